//! LOAM registration (Zhang & Singh 2014; thesis section 4.1.1.2): source edge points matched to
//! lines through the nearest target edge points, planar points to planes fitted to the nearest
//! target planar points, Tukey-weighted Gauss-Newton on SE(3).

use slam_core::{
    Alignment, Degeneracy, InvalidSetting, MapRegistrator, PointCloud, Pose3, Reach,
    RegistrationError, Registrator, se3_exp,
};

use crate::alignment_inputs::check_alignment_inputs;
use crate::alignment_report::alignment_report;
use crate::config::{NON_NEGATIVE, POSITIVE, check, check_f32};
use crate::loam_features::{LoamFeatureConfig, LoamFeatures, voxel_thin};
use crate::loam_matching::{Matcher, normal_equations};
use crate::voxel_hash_map::VoxelHashMap;

/// Settings of [`LoamRegistrator`]. Lengths in metres, angles in radians.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct LoamConfig {
    /// Feature extraction.
    pub features: LoamFeatureConfig,
    /// Voxel of a local map's edge points (thesis: 5 cm): a map of many scans
    /// ([`MapRegistrator::target_from_sources`], [`MapRegistrator::empty_map`]) keeps one point
    /// per voxel, the newest.
    pub local_map_edge_voxel: f32,
    /// Voxel of a local map's planar points (thesis: 10 cm).
    pub local_map_plane_voxel: f32,
    /// Voxel the source's edge picks are thinned to before aligning (0: keep all).
    pub source_edge_voxel: f32,
    /// Voxel the source's planar picks are thinned to before aligning (0: keep all).
    pub source_plane_voxel: f32,
    /// Side of the cells the target's points are hashed into for neighbour search (0.4 m;
    /// rounded to a whole number of local-map voxels). Answers do not depend on it, only speed.
    pub search_cell: f64,
    /// Target points looked up per source feature (5, as LeGO-LOAM).
    pub neighbours: usize,
    /// The farthest of those neighbours must lie within this distance (1 m).
    pub max_neighbour_distance: f64,
    /// A patch is a line when its largest covariance eigenvalue exceeds the middle one this many
    /// times (10).
    pub line_eigenvalue_ratio: f64,
    /// A patch is a plane when each of its points lies within this distance of the fitted plane
    /// (0.1 m).
    pub plane_fit_tolerance: f64,
    /// Tukey threshold `k` (thesis eq. 4.7) once converged: 5 cm for odometry, as the thesis.
    pub tukey_threshold: f64,
    /// Tukey threshold of the first iterations, halved every time a step is small until it
    /// reaches `tukey_threshold`: lets an alignment start away from the answer. 0.25 m suits
    /// odometry from a motion guess; use 1 m to start a metre or 10° off.
    pub initial_tukey_threshold: f64,
    /// Lines and planes are refitted when the pose has moved by more than this since they were
    /// found (metres, rotation counted at 10 m): 1 cm. Later iterations reuse them.
    pub rematch_motion: f64,
    /// Iteration cap.
    pub max_iterations: usize,
    /// Converged when an update moves less than this (metres) ...
    pub translation_tolerance: f64,
    /// ... and turns less than this (radians).
    pub rotation_tolerance: f64,
    /// Fewer weighted correspondences than this is an error.
    pub min_correspondences: usize,
}

impl Default for LoamConfig {
    fn default() -> Self {
        Self {
            features: LoamFeatureConfig::default(),
            local_map_edge_voxel: 0.05,
            local_map_plane_voxel: 0.1,
            source_edge_voxel: 0.0,
            source_plane_voxel: 0.0,
            search_cell: 0.4,
            neighbours: 5,
            max_neighbour_distance: 1.0,
            line_eigenvalue_ratio: 10.0,
            plane_fit_tolerance: 0.1,
            tukey_threshold: 0.05,
            initial_tukey_threshold: 0.25,
            rematch_motion: 0.01,
            max_iterations: 50,
            translation_tolerance: 5e-4,
            rotation_tolerance: 5e-5,
            min_correspondences: 20,
        }
    }
}

impl LoamConfig {
    /// Settings for odometry against a local map of many keyframes (what the SLAM engine does):
    /// the defaults, with the source's picks thinned to one edge point per 0.2 m and one planar
    /// point per 0.4 m, as LeGO-LOAM thins a scan before matching it to its map. The step takes
    /// about half the time of keeping every pick; on the simulated Spot's loops segment drift
    /// rises from 0.075-0.093 % to 0.091-0.127 % (the target is 0.2 %). Scan-to-scan pairs keep
    /// every pick (the default): against a single scan, thinning the source costs accuracy.
    #[must_use]
    pub fn local_map_odometry() -> Self {
        Self {
            source_edge_voxel: 0.2,
            source_plane_voxel: 0.4,
            ..Self::default()
        }
    }
}

/// LOAM registration behind [`Registrator`]: sources are [`LoamFeatures`], targets their edge
/// and planar points hashed into voxels for neighbour search.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LoamRegistrator {
    /// Settings.
    pub config: LoamConfig,
}

/// A target prepared for LOAM: edge and planar points, each in its own [`VoxelHashMap`]. A local
/// map ([`MapRegistrator::empty_map`]) is updated in place as keyframes enter and leave it.
#[derive(Clone, Debug)]
pub struct LoamTarget {
    edges: VoxelHashMap,
    planes: VoxelHashMap,
}

impl LoamTarget {
    /// Edge points of the target.
    #[must_use]
    pub fn edges(&self) -> &VoxelHashMap {
        &self.edges
    }

    /// Planar points of the target.
    #[must_use]
    pub fn planes(&self) -> &VoxelHashMap {
        &self.planes
    }
}

impl LoamConfig {
    fn validate(&self) -> Result<(), RegistrationError> {
        check(
            self.rematch_motion.is_finite() && self.rematch_motion >= 0.0,
            "LoamConfig::rematch_motion",
            self.rematch_motion,
            NON_NEGATIVE,
        )?;
        for (setting, v) in [
            (
                "LoamConfig::max_neighbour_distance",
                self.max_neighbour_distance,
            ),
            (
                "LoamConfig::line_eigenvalue_ratio",
                self.line_eigenvalue_ratio,
            ),
            ("LoamConfig::plane_fit_tolerance", self.plane_fit_tolerance),
            ("LoamConfig::tukey_threshold", self.tukey_threshold),
            (
                "LoamConfig::initial_tukey_threshold",
                self.initial_tukey_threshold,
            ),
            ("LoamConfig::search_cell", self.search_cell),
        ] {
            check(v.is_finite() && v > 0.0, setting, v, POSITIVE)?;
        }
        check(
            self.neighbours >= 3,
            "LoamConfig::neighbours",
            self.neighbours as f64,
            "at least 3",
        )?;
        for (setting, v) in [
            (
                "LoamConfig::local_map_edge_voxel",
                self.local_map_edge_voxel,
            ),
            (
                "LoamConfig::local_map_plane_voxel",
                self.local_map_plane_voxel,
            ),
        ] {
            check_f32(v >= 0.0, setting, v, "not negative")?;
        }
        Ok(())
    }

    /// An empty target whose maps thin to `edge_voxel` and `plane_voxel` (0: keep all).
    fn empty_target(
        &self,
        edge_voxel: f32,
        plane_voxel: f32,
    ) -> Result<LoamTarget, RegistrationError> {
        self.validate()?;
        Ok(LoamTarget {
            edges: VoxelHashMap::new(self.search_cell, f64::from(edge_voxel))?,
            planes: VoxelHashMap::new(self.search_cell, f64::from(plane_voxel))?,
        })
    }

    /// `target` unless it holds fewer points than a registration needs.
    fn enough(&self, target: LoamTarget) -> Result<LoamTarget, RegistrationError> {
        let points = target.edges.len() + target.planes.len();
        if points < self.min_correspondences {
            return Err(RegistrationError::TooFewPoints {
                what: "target",
                points,
                required: self.min_correspondences,
            });
        }
        Ok(target)
    }
}

/// Adds the map points of `features`, moved by `pose`, to `target` under `owner`.
fn add_features(target: &mut LoamTarget, owner: u32, features: &LoamFeatures, pose: &Pose3) {
    for p in &features.edge_map {
        target.edges.insert(owner, &(pose * p));
    }
    for p in &features.plane_map {
        target.planes.insert(owner, &(pose * p));
    }
}

impl Registrator for LoamRegistrator {
    type Source = LoamFeatures;
    type Target = LoamTarget;

    fn prepare_source(&self, cloud: &PointCloud) -> Result<Self::Source, RegistrationError> {
        let mut features = LoamFeatures::extract(cloud, &self.config.features)?;
        let c = &self.config;
        features.edges = voxel_thin(std::mem::take(&mut features.edges), c.source_edge_voxel);
        features.planes = voxel_thin(std::mem::take(&mut features.planes), c.source_plane_voxel);
        if features.len() < self.config.min_correspondences {
            return Err(RegistrationError::TooFewPoints {
                what: "source",
                points: features.len(),
                required: self.config.min_correspondences,
            });
        }
        Ok(features)
    }

    /// A single scan's target keeps every reliable feature point: thinning one scan biases
    /// every frame of an odometry the same way, through per-laser range offsets.
    fn prepare_target(&self, cloud: &PointCloud) -> Result<Self::Target, RegistrationError> {
        let features = LoamFeatures::extract(cloud, &self.config.features)?;
        let mut target = self.config.empty_target(0.0, 0.0)?;
        add_features(&mut target, 0, &features, &Pose3::identity());
        self.config.enough(target)
    }

    fn align(
        &self,
        source: &Self::Source,
        target: &Self::Target,
        initial: &Pose3,
    ) -> Result<Alignment, RegistrationError> {
        align_loam(&self.config, source, target, initial)
    }

    /// The reach widens the neighbour search (its farthest neighbour within `reach.distance`
    /// instead of [`LoamConfig::max_neighbour_distance`], if larger) and starts the Tukey
    /// threshold at `reach.kernel`; the final threshold stays [`LoamConfig::tukey_threshold`].
    fn align_within(
        &self,
        source: &Self::Source,
        target: &Self::Target,
        initial: &Pose3,
        reach: &Reach,
    ) -> Result<Alignment, RegistrationError> {
        if !reach.is_valid() {
            return Err(InvalidSetting {
                setting: "Reach::distance",
                value: reach.distance.min(reach.kernel),
                expected: "finite and positive, with a finite and positive kernel",
            }
            .into());
        }
        let config = LoamConfig {
            max_neighbour_distance: self.config.max_neighbour_distance.max(reach.distance),
            initial_tukey_threshold: reach.kernel,
            ..self.config
        };
        align_loam(&config, source, target, initial)
    }
}

/// LOAM's alignment with `config`.
fn align_loam(
    config: &LoamConfig,
    source: &LoamFeatures,
    target: &LoamTarget,
    initial: &Pose3,
) -> Result<Alignment, RegistrationError> {
    check_alignment_inputs(config.validate(), initial)?;
    let mut matcher = Matcher::new(config, target, source);
    let mut pose = *initial;
    let mut k = config.initial_tukey_threshold.max(config.tukey_threshold);
    let (mut converged, mut iterations) = (false, 0);
    let mut pairs = Vec::new();
    // The pose the correspondences were found at: lines and planes are refitted only when
    // the pose has moved since by more than `rematch_motion`.
    let mut matched_at: Option<Pose3> = None;
    let too_few = |found| RegistrationError::TooFewCorrespondences {
        found,
        required: config.min_correspondences,
    };
    while iterations < config.max_iterations {
        iterations += 1;
        if matched_at.is_none_or(|m| motion(&m, &pose) > config.rematch_motion) {
            matcher.all(source, &pose, &mut pairs);
            matched_at = Some(pose);
        }
        let (h, b, used, _) = normal_equations(&pairs, &pose, k);
        if used < config.min_correspondences {
            return Err(too_few(used));
        }
        let Some(delta) = h.cholesky().map(|c| -c.solve(&b)) else {
            return Err(RegistrationError::Degenerate {
                cause: Degeneracy::SingularNormalEquations,
            });
        };
        if !delta.iter().all(|v| v.is_finite()) {
            return Err(RegistrationError::Degenerate {
                cause: Degeneracy::NonFiniteUpdate,
            });
        }
        pose = se3_exp(&delta) * pose;
        let (dt, dr) = (
            delta.fixed_rows::<3>(0).norm(),
            delta.fixed_rows::<3>(3).norm(),
        );
        // Coarse to fine: a wide threshold pulls the pose in, then it shrinks to the final
        // one, which alone decides convergence.
        if k > config.tukey_threshold {
            if dt < 100.0 * config.translation_tolerance && dr < 100.0 * config.rotation_tolerance {
                k = (k * 0.5).max(config.tukey_threshold);
            }
        } else if dt < config.translation_tolerance && dr < config.rotation_tolerance {
            // The correspondences were found within `rematch_motion` of this pose.
            converged = true;
            break;
        }
    }
    // Composed step after step from the caller's guess: keep the quaternion unit.
    pose.rotation.renormalize();
    // Report at the final pose, on correspondences found near it.
    if matched_at.is_none_or(|m| motion(&m, &pose) > config.rematch_motion) {
        matcher.all(source, &pose, &mut pairs);
    }
    let (information, _, inliers, sq) = normal_equations(&pairs, &pose, k);
    if inliers < config.min_correspondences {
        return Err(too_few(inliers));
    }
    Ok(alignment_report(
        pose,
        converged,
        iterations,
        inliers,
        source.len(),
        (sq / inliers as f64).sqrt(),
        &information,
    ))
}

/// How far `b` is from `a`: translation plus rotation seen at 10 m (metres).
fn motion(a: &Pose3, b: &Pose3) -> f64 {
    let d = a.inverse() * b;
    d.translation.vector.norm() + 10.0 * d.rotation.angle()
}

impl MapRegistrator for LoamRegistrator {
    /// Parts added in order: where two parts share a voxel, the later one's point stays.
    fn target_from_sources(
        &self,
        parts: &[(&Self::Source, Pose3)],
    ) -> Result<Self::Target, RegistrationError> {
        let c = &self.config;
        let mut target = c.empty_target(c.local_map_edge_voxel, c.local_map_plane_voxel)?;
        // Keyframes of a local map overlap: of the simulated Spot's 40-keyframe map, 57 % of the
        // edge and 23 % of the planar points land in voxels of their own. Room for half of them
        // saves the rehashes.
        let (edges, planes) = parts.iter().fold((0, 0), |(e, p), (f, _)| {
            (e + f.edge_map.len(), p + f.plane_map.len())
        });
        target.edges.reserve(edges / 2);
        target.planes.reserve(planes / 2);
        for (owner, (features, pose)) in (0u32..).zip(parts) {
            add_features(&mut target, owner, features, pose);
        }
        c.enough(target)
    }

    /// Thins the map points to the local-map voxels in the sensor frame (the picks to align stay
    /// whole): a 40-keyframe map then merges a few thousand points per keyframe, not every
    /// reliable point of every scan.
    /// `None`: LOAM's features stay in memory.
    fn stored_source(&self, _source: &Self::Source) -> Option<Vec<u8>> {
        None
    }

    fn restored_source(&self, _bytes: &[u8]) -> Option<Self::Source> {
        None
    }

    /// Nothing to set: LOAM's feature maps keep their own voxels whatever the sensor.
    fn fit_to_scan(&mut self, _points: usize) {}

    /// `None`: two feature maps, each with its own voxel.
    fn map_voxel(&self) -> Option<f32> {
        None
    }

    fn keyframe_source(&self, mut source: Self::Source) -> Self::Source {
        let c = &self.config;
        source.edge_map = voxel_thin(source.edge_map, c.local_map_edge_voxel);
        source.plane_map = voxel_thin(source.plane_map, c.local_map_plane_voxel);
        source
    }

    /// `None`: the features run along each ring in firing order, so a scan must come as the
    /// sensor gave it.
    fn source_voxel(&self) -> Option<f32> {
        None
    }

    /// A local map with the local-map voxels, updated in place as keyframes enter and leave.
    fn empty_map(&self) -> Option<Self::Target> {
        let c = &self.config;
        c.empty_target(c.local_map_edge_voxel, c.local_map_plane_voxel)
            .ok()
    }

    fn add_to_map(&self, map: &mut Self::Target, key: u32, source: &Self::Source, pose: &Pose3) {
        add_features(map, key, source, pose);
    }

    fn remove_from_map(&self, map: &mut Self::Target, key: u32) {
        map.edges.remove_owner(key);
        map.planes.remove_owner(key);
    }

    /// The feature maps are voxel hashes searched as they are: nothing to rebuild.
    fn ready_map_beside(&self, _map: &mut Self::Target, beside: &mut (dyn FnMut() + Send)) {
        beside();
    }

    /// Nothing to rebuild (see [`MapRegistrator::ready_map_beside`]).
    fn ready_map_ahead(&self, _map: &mut Self::Target) {}
}
