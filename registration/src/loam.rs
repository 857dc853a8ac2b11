//! LOAM registration (Zhang & Singh 2014; thesis section 4.1.1.2): source edge points matched to
//! lines through the nearest target edge points, planar points to planes fitted to the nearest
//! target planar points, Tukey-weighted Gauss-Newton on SE(3).

use std::cell::OnceCell;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use nalgebra::{Matrix3, Matrix6, Point3, Vector3, Vector6};
use slam_core::{
    Alignment, MapRegistrator, PointCloud, Pose3, RegistrationError, Registrator, pose3_is_finite,
    se3_exp,
};

use crate::icp::min_eigenvalue_ratio;
use crate::kernel::IcpKernel;
use crate::loam_features::{LoamFeatureConfig, LoamFeatures, voxel_thin};
use crate::sym3::{Eigen3, symmetric_eigen3};

/// Settings of [`LoamRegistrator`]. Lengths in metres, angles in radians.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoamConfig {
    /// Feature extraction.
    pub features: LoamFeatureConfig,
    /// Voxel of a local map's edge points (thesis: 5 cm): the map of many scans built by
    /// [`MapRegistrator::target_from_sources`] keeps one point per voxel.
    pub local_map_edge_voxel: f32,
    /// Voxel of a local map's planar points (thesis: 10 cm).
    pub local_map_plane_voxel: f32,
    /// Which patch a source feature's line or plane is fitted to.
    pub patch: LoamPatch,
    /// Target points looked up per source feature (5, as LeGO-LOAM).
    pub neighbours: usize,
    /// The farthest of those neighbours must lie within this distance (1 m).
    pub max_neighbour_distance: f64,
    /// A patch is a line when its largest covariance eigenvalue exceeds the middle one this many
    /// times (3, as LOAM).
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
            patch: LoamPatch::AroundQuery,
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

/// Where the patch a source feature is matched to comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoamPatch {
    /// The `neighbours` target points nearest the moved source point, refitted at every
    /// matching (LOAM's own rule). The default.
    AroundQuery,
    /// The nearest target point and its `neighbours` nearest points, fitted once per target
    /// point and kept: one nearest-point query per match, and a local map shared by several
    /// scans fits each patch once. Less accurate: a patch centred off the query point bends
    /// with the surface (0.49° and 4 cm from the HDL-32E pair's reference, against 0.20° and
    /// 2.1 cm).
    AroundNearest,
}

/// LOAM registration behind [`Registrator`]: sources are [`LoamFeatures`], targets their edge
/// and planar points in two k-d trees.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LoamRegistrator {
    /// Settings.
    pub config: LoamConfig,
}

/// A target prepared for LOAM: edge and planar points, each in its own k-d tree.
pub struct LoamTarget {
    edges: FeatureTree,
    planes: FeatureTree,
}

impl std::fmt::Debug for LoamTarget {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LoamTarget")
            .field("edges", &self.edges.points.len())
            .field("planes", &self.planes.points.len())
            .finish()
    }
}

impl LoamTarget {
    /// Edge points of the target.
    #[must_use]
    pub fn edges(&self) -> &[Point3<f64>] {
        &self.edges.points
    }

    /// Planar points of the target.
    #[must_use]
    pub fn planes(&self) -> &[Point3<f64>] {
        &self.planes.points
    }
}

struct FeatureTree {
    points: Vec<Point3<f64>>,
    /// In f32: half the memory traffic of f64 per query, and a local map spans far less than
    /// the kilometres where f32 would lose millimetres.
    tree: Option<ImmutableKdTree<f32, 3>>,
    /// The line or plane around each point, fitted on first use ([`LoamPatch::AroundNearest`]).
    fits: Vec<OnceCell<Option<Fit>>>,
}

impl FeatureTree {
    fn new(points: Vec<Point3<f64>>) -> Result<Self, RegistrationError> {
        let tree = if points.is_empty() {
            None
        } else {
            #[allow(clippy::cast_possible_truncation)]
            let coords: Vec<[f32; 3]> = points
                .iter()
                .map(|p| [p.x as f32, p.y as f32, p.z as f32])
                .collect();
            Some(
                ImmutableKdTree::new_from_slice(&coords)
                    .map_err(|e| RegistrationError::Degenerate(format!("k-d tree: {e:?}")))?,
            )
        };
        let fits = (0..points.len()).map(|_| OnceCell::new()).collect();
        Ok(Self { points, tree, fits })
    }

    /// The `k` nearest points to `q` when the farthest of them lies within `max_d2`.
    #[allow(clippy::cast_possible_truncation)]
    fn patch(
        &self,
        q: &Point3<f64>,
        k: std::num::NonZero<usize>,
        max_d2: f64,
        out: &mut Vec<Point3<f64>>,
    ) -> bool {
        out.clear();
        let Some(tree) = &self.tree else {
            return false;
        };
        let nn = tree
            .query(&[q.x as f32, q.y as f32, q.z as f32])
            .nearest_n::<SquaredEuclidean<f32>>(k)
            .within::<SquaredEuclidean<f32>>(max_d2 as f32)
            .unsorted()
            .execute();
        if nn.len() < k.get() {
            return false;
        }
        out.extend(nn.iter().map(|r| self.points[r.item as usize]));
        true
    }

    /// The nearest point to `q` when it lies within `max_d2`.
    #[allow(clippy::cast_possible_truncation)]
    fn nearest(&self, q: &Point3<f64>, max_d2: f64) -> Option<usize> {
        let r = self
            .tree
            .as_ref()?
            .query(&[q.x as f32, q.y as f32, q.z as f32])
            .nearest_one::<SquaredEuclidean<f32>>()
            .execute();
        (f64::from(r.distance) <= max_d2).then_some(r.item as usize)
    }
}

/// Mean and eigen-decomposition of a patch's covariance (eigenvalues ascending).
fn patch_pca(patch: &[Point3<f64>]) -> (Vector3<f64>, Eigen3) {
    #[allow(clippy::cast_precision_loss)]
    let n = patch.len() as f64;
    let mean = patch.iter().map(|p| p.coords).sum::<Vector3<f64>>() / n;
    let cov = patch.iter().fold(Matrix3::zeros(), |m, p| {
        let d = p.coords - mean;
        m + d * d.transpose()
    }) / n;
    (mean, symmetric_eigen3(&cov))
}

/// A line (two residual directions across it) or a plane (one: its normal) through `c`. The
/// residual of direction `n` at a point `x` is `n . (x - c)`.
#[derive(Clone, Copy)]
struct Fit {
    normals: [Vector3<f64>; 2],
    len: usize,
    c: Vector3<f64>,
}

impl Fit {
    /// The line through a patch whose largest covariance eigenvalue exceeds the middle one
    /// `ratio` times.
    fn line(patch: &[Point3<f64>], ratio: f64) -> Option<Self> {
        let (c, eig) = patch_pca(patch);
        (eig.values[2] > ratio * eig.values[1]).then(|| Self {
            normals: [
                eig.vectors.column(0).into_owned(),
                eig.vectors.column(1).into_owned(),
            ],
            len: 2,
            c,
        })
    }

    /// The plane through a patch that spans two dimensions and whose points all lie within
    /// `tolerance` of it.
    fn plane(patch: &[Point3<f64>], tolerance: f64) -> Option<Self> {
        let (c, eig) = patch_pca(patch);
        // A patch spread along a line (one scan line) fixes no plane.
        if eig.values[1] < 0.01 * eig.values[2] {
            return None;
        }
        let n = eig.vectors.column(0).into_owned();
        if patch
            .iter()
            .any(|q| n.dot(&(q.coords - c)).abs() > tolerance)
        {
            return None;
        }
        Some(Self {
            normals: [n, Vector3::zeros()],
            len: 1,
            c,
        })
    }
}

/// A source point and the line or plane it is matched to.
struct Correspondence {
    source: Point3<f64>,
    fit: Fit,
}

impl Correspondence {
    /// The moved point, its residuals and its distance to the line or plane.
    fn at(&self, pose: &Pose3) -> (Point3<f64>, [f64; 2], f64) {
        let p = pose * self.source;
        let f = &self.fit;
        let d = p.coords - f.c;
        let r = [f.normals[0].dot(&d), f.normals[1].dot(&d)];
        let distance = if f.len == 2 {
            r[0].hypot(r[1])
        } else {
            r[0].abs()
        };
        (p, r, distance)
    }
}

struct Matcher<'a> {
    config: &'a LoamConfig,
    target: &'a LoamTarget,
    k: std::num::NonZero<usize>,
    max_d2: f64,
    patch: Vec<Point3<f64>>,
}

impl Matcher<'_> {
    /// The line or plane matched to the moved source point `p` in `tree`.
    fn fit(&mut self, tree: &FeatureTree, p: &Point3<f64>, edge: bool) -> Option<Fit> {
        let (ratio, tol) = (
            self.config.line_eigenvalue_ratio,
            self.config.plane_fit_tolerance,
        );
        let fit = |patch: &[Point3<f64>]| {
            if edge {
                Fit::line(patch, ratio)
            } else {
                Fit::plane(patch, tol)
            }
        };
        match self.config.patch {
            LoamPatch::AroundQuery => {
                if !tree.patch(p, self.k, self.max_d2, &mut self.patch) {
                    return None;
                }
                fit(&self.patch)
            }
            LoamPatch::AroundNearest => {
                let i = tree.nearest(p, self.max_d2)?;
                *tree.fits[i].get_or_init(|| {
                    let mut patch = Vec::with_capacity(self.k.get());
                    tree.patch(&tree.points[i], self.k, self.max_d2, &mut patch)
                        .then(|| fit(&patch))
                        .flatten()
                })
            }
        }
    }

    fn edge(&mut self, source: Point3<f64>, p: &Point3<f64>) -> Option<Correspondence> {
        let fit = self.fit(&self.target.edges, p, true)?;
        Some(Correspondence { source, fit })
    }

    fn plane(&mut self, source: Point3<f64>, p: &Point3<f64>) -> Option<Correspondence> {
        let fit = self.fit(&self.target.planes, p, false)?;
        Some(Correspondence { source, fit })
    }

    fn all(&mut self, source: &LoamFeatures, pose: &Pose3, out: &mut Vec<Correspondence>) {
        out.clear();
        for &e in &source.edges {
            if let Some(c) = self.edge(e, &(pose * e)) {
                out.push(c);
            }
        }
        for &q in &source.planes {
            if let Some(c) = self.plane(q, &(pose * q)) {
                out.push(c);
            }
        }
    }
}

/// `J^T W J` and `J^T W e` of the correspondences at `pose` under Tukey threshold `k`, with the
/// number of correspondences of non-zero weight and their summed squared distances.
fn normal_equations(
    pairs: &[Correspondence],
    pose: &Pose3,
    k: f64,
) -> (Matrix6<f64>, Vector6<f64>, usize, f64) {
    let kernel = IcpKernel::Tukey { k };
    let mut h = Matrix6::zeros();
    let mut b = Vector6::zeros();
    let (mut used, mut sq) = (0, 0.0);
    for c in pairs {
        let (p, r, distance) = c.at(pose);
        let w = kernel.weight(distance);
        if w == 0.0 {
            continue;
        }
        used += 1;
        sq += distance * distance;
        for (n, r) in c.fit.normals[..c.fit.len].iter().zip(r) {
            // `[n; p x n]`: the row's Jacobian for a left perturbation.
            let x = p.coords.cross(n);
            let j = Vector6::new(n.x, n.y, n.z, x.x, x.y, x.z);
            h += j * j.transpose() * w;
            b += j * (r * w);
        }
    }
    (h, b, used, sq)
}

impl LoamConfig {
    fn validate(&self) -> Result<(), RegistrationError> {
        let positive = [
            self.max_neighbour_distance,
            self.line_eigenvalue_ratio,
            self.plane_fit_tolerance,
            self.tukey_threshold,
            self.initial_tukey_threshold,
        ];
        if !(self.rematch_motion.is_finite() && self.rematch_motion >= 0.0) {
            return Err(RegistrationError::InvalidConfig(
                "LOAM rematch_motion must be finite and non-negative".into(),
            ));
        }
        if positive.iter().any(|v| !(v.is_finite() && *v > 0.0))
            || self.neighbours < 3
            || !(self.local_map_edge_voxel >= 0.0 && self.local_map_plane_voxel >= 0.0)
        {
            return Err(RegistrationError::InvalidConfig(
                "LOAM distances, ratios and thresholds must be positive, neighbours at least 3"
                    .into(),
            ));
        }
        Ok(())
    }

    /// A target from the map points of `features`.
    fn target(&self, features: LoamFeatures) -> Result<LoamTarget, RegistrationError> {
        self.validate()?;
        let edges = FeatureTree::new(features.edge_map)?;
        let planes = FeatureTree::new(features.plane_map)?;
        let points = edges.points.len() + planes.points.len();
        if points < self.min_correspondences {
            return Err(RegistrationError::TooFewPoints {
                what: "target",
                points,
                required: self.min_correspondences,
            });
        }
        Ok(LoamTarget { edges, planes })
    }
}

impl Registrator for LoamRegistrator {
    type Source = LoamFeatures;
    type Target = LoamTarget;

    fn prepare_source(&self, cloud: &PointCloud) -> Result<Self::Source, RegistrationError> {
        let features = LoamFeatures::extract(cloud, &self.config.features)?;
        if features.len() < self.config.min_correspondences {
            return Err(RegistrationError::TooFewPoints {
                what: "source",
                points: features.len(),
                required: self.config.min_correspondences,
            });
        }
        Ok(features)
    }

    fn prepare_target(&self, cloud: &PointCloud) -> Result<Self::Target, RegistrationError> {
        self.config
            .target(LoamFeatures::extract(cloud, &self.config.features)?)
    }

    fn align(
        &self,
        source: &Self::Source,
        target: &Self::Target,
        initial: &Pose3,
    ) -> Result<Alignment, RegistrationError> {
        let config = &self.config;
        config.validate()?;
        if !pose3_is_finite(initial) {
            return Err(RegistrationError::NonFiniteInitialGuess);
        }
        let mut matcher = Matcher {
            config,
            target,
            k: std::num::NonZero::new(config.neighbours).unwrap_or(std::num::NonZero::<usize>::MIN),
            max_d2: config.max_neighbour_distance.powi(2),
            patch: Vec::with_capacity(config.neighbours),
        };
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
                return Err(RegistrationError::Degenerate(
                    "singular normal equations".into(),
                ));
            };
            if !delta.iter().all(|v| v.is_finite()) {
                return Err(RegistrationError::Degenerate("non-finite update".into()));
            }
            pose = se3_exp(&delta) * pose;
            let (dt, dr) = (
                delta.fixed_rows::<3>(0).norm(),
                delta.fixed_rows::<3>(3).norm(),
            );
            // Coarse to fine: a wide threshold pulls the pose in, then it shrinks to the final
            // one, which alone decides convergence.
            if k > config.tukey_threshold {
                if dt < 100.0 * config.translation_tolerance
                    && dr < 100.0 * config.rotation_tolerance
                {
                    k = (k * 0.5).max(config.tukey_threshold);
                }
            } else if dt < config.translation_tolerance && dr < config.rotation_tolerance {
                // The correspondences were found within `rematch_motion` of this pose.
                converged = true;
                break;
            }
        }
        // Report at the final pose, on correspondences found near it.
        if matched_at.is_none_or(|m| motion(&m, &pose) > config.rematch_motion) {
            matcher.all(source, &pose, &mut pairs);
        }
        let (information, _, inliers, sq) = normal_equations(&pairs, &pose, k);
        if inliers < config.min_correspondences {
            return Err(too_few(inliers));
        }
        #[allow(clippy::cast_precision_loss)]
        Ok(Alignment {
            pose,
            converged,
            iterations,
            inliers,
            inlier_ratio: inliers as f64 / source.len().max(1) as f64,
            rmse: (sq / inliers as f64).sqrt(),
            min_eigenvalue_ratio: min_eigenvalue_ratio(&information),
            information,
        })
    }
}

/// How far `b` is from `a`: translation plus rotation seen at 10 m (metres).
fn motion(a: &Pose3, b: &Pose3) -> f64 {
    let d = a.inverse() * b;
    d.translation.vector.norm() + 10.0 * d.rotation.angle()
}

impl MapRegistrator for LoamRegistrator {
    fn target_from_sources(
        &self,
        parts: &[(&Self::Source, Pose3)],
    ) -> Result<Self::Target, RegistrationError> {
        let mut merged = LoamFeatures::default();
        for (features, pose) in parts {
            merged
                .edge_map
                .extend(features.edge_map.iter().map(|p| pose * p));
            merged
                .plane_map
                .extend(features.plane_map.iter().map(|p| pose * p));
        }
        let c = &self.config;
        merged.edge_map = voxel_thin(merged.edge_map, c.local_map_edge_voxel);
        merged.plane_map = voxel_thin(merged.plane_map, c.local_map_plane_voxel);
        self.config.target(merged)
    }

    /// Thins the map points to the local-map voxels in the sensor frame (the picks to align stay
    /// whole): a 40-keyframe map then merges a few thousand points per keyframe, not every
    /// reliable point of every scan.
    fn keyframe_source(&self, mut source: Self::Source) -> Self::Source {
        let c = &self.config;
        source.edge_map = voxel_thin(source.edge_map, c.local_map_edge_voxel);
        source.plane_map = voxel_thin(source.plane_map, c.local_map_plane_voxel);
        source
    }
}
