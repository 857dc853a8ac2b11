//! The Graph-SLAM engine put together with this workspace's backends, configured as the
//! simulated and recorded runs use it: one place for the settings that the example, the tests
//! and the benches share.
//!
//! Mapping the first 10 s of a simulated Spot's lap, LiDAR-only, and reading the body's pose
//! back from the engine's LiDAR poses (frames as in the workspace README: `a_T_b` maps points
//! in `b` into `a`):
//!
//! ```
//! use spot_adapter::pipelines::{point_to_plane_slam, slam_config};
//! use spot_adapter::sim::{SimulatedSpot, SimulationConfig};
//!
//! let sim = SimulatedSpot::corridor_loop(&SimulationConfig::with_seed(3))?;
//! let truth = sim.ground_truth(); // world_T_body per scan
//! let mut slam = point_to_plane_slam(slam_config())?;
//! let mut body_t_lidar = None;
//! for sample in sim.take(50) {
//!     // Points in the LiDAR frame; without odometry each scan is registered against the
//!     // local map from a constant-velocity prediction.
//!     slam.process(&sample.lidar_only_input());
//!     body_t_lidar = Some(sample.body_t_lidar);
//! }
//! let lidar_t_body = body_t_lidar.expect("scans").inverse();
//! // The engine keeps map_T_lidar per scan; the map frame is the first scan's LiDAR frame.
//! let scans = slam.scan_trajectory();
//! let map_t_body = |k: usize| scans[k].pose * lidar_t_body;
//! // The walk from the first scan to the last, as the engine saw it and as it was.
//! let seen = map_t_body(0).inverse() * map_t_body(49);
//! let walked = truth[0].pose.inverse() * truth[49].pose;
//! let error = (seen.translation.vector - walked.translation.vector).norm();
//! assert!(walked.translation.vector.norm() > 4.0, "Spot walked some metres");
//! assert!(error < 0.05, "{error} m off after {:.1} m", walked.translation.vector.norm());
//! assert!(slam.keyframe_count() > 10 && slam.report().fallbacks() == 0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use posegraph::{GncConfig, GraduatedNonConvexity, KnownInliers};
use registration::{
    IcpConfig, IcpKernel, LoamConfig, LoamRegistrator, PointToPlaneIcp, PointToPointIcp,
    ScanContextConfig, ScanContextIndexConfig, ScanContextRecognizer,
};
use slam_core::{
    GraphSlam, GraphSlamConfig, InvalidSetting, MapRegistrator, Optimizer, PlaceRecognizer, Pose3,
};

/// Graph-SLAM with point-to-plane ICP odometry and loop refinement.
pub type PointToPlaneSlam = GraphSlam<PointToPlaneIcp, PointToPointIcp, GraduatedNonConvexity>;

/// Graph-SLAM with LOAM odometry and loop refinement.
pub type LoamSlam = GraphSlam<LoamRegistrator, PointToPointIcp, GraduatedNonConvexity>;

/// The engine settings that go with [`point_to_plane_slam`] and [`loam_slam`]: the defaults,
/// except that the point-to-point loop check accepts an RMS distance up to 0.2 m (voxel
/// centroids of two different scans sit a few centimetres apart), and that keyframes of scans
/// of more than 60,000 points (an OS1-128's 131,072; not a VLP-16's 29,000) keep their whole
/// scan for the map one a metre ([`GraphSlamConfig::keyframe_scan_spacing`]), not at every
/// keyframe.
#[must_use]
pub fn slam_config() -> GraphSlamConfig {
    GraphSlamConfig {
        loop_max_mean_squared_error: 0.04,
        keyframe_scan_spacing: 1.0,
        dense_scan_points: SPARSE_SCAN_POINTS,
        ..GraphSlamConfig::default()
    }
}

/// The engine with `odometry` and `refine`, the thesis' loop check (point-to-point ICP on
/// voxelised keyframes) and graduated non-convexity over Levenberg-Marquardt with its defaults
/// (truncated least squares on loop edges, odometry edges known inliers: the edges without a
/// kernel, so keep [`GraphSlamConfig::loop_kernel`] set): a loop that passes
/// the geometric check yet disagrees with the rest of the graph (a look-alike place) is
/// weighted out instead of bending the map.
fn assemble<R: MapRegistrator>(
    config: GraphSlamConfig,
    odometry: R,
    refine: R,
) -> Result<GraphSlam<R, PointToPointIcp, GraduatedNonConvexity>, InvalidSetting> {
    // Odometry edges carry no kernel and loops carry the engine's loop kernel: the ones without
    // are the known inliers (an odometry edge from an old keyframe the walk rode on joins ids
    // that are not consecutive).
    let gnc = GraduatedNonConvexity::try_new(GncConfig {
        known_inliers: KnownInliers::WithoutKernel,
        ..GncConfig::default()
    })?;
    assemble_with(config, odometry, refine, gnc)
}

/// [`assemble`] with `optimizer` as the back end.
fn assemble_with<R: MapRegistrator, O: Optimizer<Pose3>>(
    config: GraphSlamConfig,
    odometry: R,
    refine: R,
    optimizer: O,
) -> Result<GraphSlam<R, PointToPointIcp, O>, InvalidSetting> {
    let loop_check = PointToPointIcp {
        config: IcpConfig {
            max_correspondence_distance: 1.0,
            // The thesis' check: textbook nearest-point pairs, whose mean squared error the
            // acceptance threshold was set on.
            pair_target_points: 1,
            ..IcpConfig::default()
        },
    };
    GraphSlam::try_new(config, odometry, loop_check, refine, optimizer)
}

/// Point-to-plane ICP for tracking a scan against a map (the SLAM odometry's fine stage after the
/// tracker's coarse ones, and the navigator's localisation): Tukey 10 cm, pairs within 0.5 m,
/// every target normal, no coarse stage of its own, at most 2,500 source points an alignment,
/// the scan thinned to 0.25 m voxels and the map to 0.2 m, or to 0.15 m for a sensor whose scans
/// have at most 60,000 points (a VLP-16's; [`IcpConfig::sparse_scan_points`]).
///
/// The finer map for sparse scans is for stairs. At 0.2 m a voxel averages a step's tread and
/// riser into a ramp, along which motion and height are coupled: on the simulated Spot's
/// two-floor walks (`slam --floors 2`, VLP-16, the robot's odometry, building seeds 1-12) the
/// upper floor ended 0.3-5.9 cm low on the mean (seed 3: 5.9 cm, 6.7 cm at most), at 0.15 m
/// 0.2-2.0 cm (seed 3: 1.5 cm; 3.1 cm at most on any seed); the flat laps end as before (ATE
/// 0.5-1.4 cm with or without odometry) at 0-25 % more time a scan (2.6-4.1 ms). A dense scan
/// keeps 0.2 m: on the hand-held OS1-128 walk 0.15 m costs 10-14 % more a scan and its
/// LiDAR-only tracking turns chaotic (the constant-velocity prediction fails seed 1's first 80
/// scans by 5.8°, and moving every point by 10 µm moves that walk's ATE from 2.4 to 9.5 cm).
/// LiDAR-only over stairs the finer map costs one rise: where the body levels off at the top,
/// one scan registers a step low on the repeating treads (the upper floor 12.6-19.4 cm low on
/// seeds 1, 2, 3 and 5, against 9.3 cm low to 12.6 cm high at 0.2 m), which the robot's
/// odometry prevents; `IcpConfig::sparse_scan_points` 0 keeps 0.2 m for every sensor.
///
/// The map's voxel differs from the scan's on purpose. Thinned to the same voxel, the scan's
/// centroids and the map's form the same lattice, and along a corridor, where little fixes the
/// motion, the alignment locks onto a lattice step: on the hand-held OS1-128 walk (3 seeds, each
/// also with every point moved by 1 or 10 micrometres) the fine stage, started 2 cm from the
/// same place, ended 0.2 m apart, and the ATE ranged over 2.5-14 cm (both voxels 0.25 m) or
/// 2.5-23 cm (both 0.2 m). With a 0.2 m map under 0.25 m scans each seed's ATE stays within
/// 0.4 cm of itself (2.5-6.9 cm), and the VLP-16 lap ends 0.7-1.4 cm.
///
/// Every normal: pairing only plane-like target neighbourhoods (`IcpConfig::min_planarity`
/// 0.2) kept the scan-to-scan odometry this crate had before from sliding along a blank
/// corridor, but with every scan registered against the local map it drops what fixes the
/// motion along a corridor (door frames, corners): LiDAR-only, the seed-3 lap slid 9 cm in one
/// scan and ended 6-9 cm ATE (0.9 cm with every normal), the hand-held OS1-128 walk 9.2 cm
/// (2.6 cm); the blank corridor holds either way.
#[must_use]
pub fn point_to_plane_tracker() -> PointToPlaneIcp {
    PointToPlaneIcp {
        config: IcpConfig {
            kernel: IcpKernel::Tukey { k: 0.1 },
            max_correspondence_distance: 0.5,
            coarse_stride: 1,
            // A dense scan's 4,000 or more voxels register as well from 2,500 (the hand-held
            // OS1-128 walk: the same ATE, 2.7 cm, and 0.69 of the time); a VLP-16's 2,000 are
            // all kept.
            max_source_points: 2500,
            target_voxel: 0.2,
            sparse_scan_points: SPARSE_SCAN_POINTS,
            sparse_target_voxel: 0.15,
            ..IcpConfig::default()
        },
    }
}

/// Scans of at most this many points are sparse ([`point_to_plane_tracker`]): a VLP-16's (28,800
/// at 10 Hz, 57,600 at 5 Hz), not an OS1-64's (65,536) or denser (an OS1-128's 131,072). An
/// HDL-32E's (up to 69,000; 42,000 in the static garage sequence, where either map voxel ends
/// within 0.3 cm and 0.07° of the start) may fall either side.
const SPARSE_SCAN_POINTS: usize = 60_000;

/// Point-to-plane ICP for localising a scan against a building's map (the [`Navigator`]'s):
/// [`point_to_plane_tracker`] with the map thinned to 0.1 m instead of 0.25 m, and every
/// normal kept. A voxel wider than a wall is thick mixes the wall's two faces into one centroid
/// inside the wall: a room the map saw mostly through one such wall was localised onto that
/// virtual surface, 0.11 m and 0.6° off with 57 % of the scan matched (building 5, 20 random
/// goals, leg 3), where a 0.1 m map
/// registers the same scan within 2 cm and 0.1°. The map is fixed and every cycle aligns a scan
/// against it, so its normals are computed when it is prepared. It stops once a step moves less
/// than 1 mm (not 0.1 mm): a navigator needs centimetres.
///
/// [`Navigator`]: crate::nav::Navigator
#[must_use]
pub fn point_to_plane_localiser() -> PointToPlaneIcp {
    let mut icp = point_to_plane_tracker();
    icp.config.target_voxel = 0.1;
    // A building's map is the same whatever the sensor.
    icp.config.sparse_scan_points = 0;
    // A walk into a part of the map not seen yet would compute its normals in that cycle.
    icp.config.normals_up_front = true;
    // A navigator needs centimetres: steps of a tenth of a millimetre chase pairs that swap
    // back and forth (in building 3's farthest room, 50 iterations of a cycle of 0.1-0.7 mm
    // steps, where 1 mm stops after 1-2).
    icp.config.translation_tolerance = 1e-3;
    icp
}

/// Point-to-plane odometry ([`point_to_plane_tracker`]) against the local map, and
/// point-to-plane loop refinement (Tukey 10 cm, pairs within 1 m), with `config` (usually
/// [`slam_config`]).
///
/// # Errors
/// [`InvalidSetting`] naming the first bad setting of `config`.
pub fn point_to_plane_slam(config: GraphSlamConfig) -> Result<PointToPlaneSlam, InvalidSetting> {
    point_to_plane_slam_with(config, point_to_plane_tracker())
}

/// [`point_to_plane_slam`] with `odometry` in place of [`point_to_plane_tracker`] (to try other
/// tracking settings on a recording, say).
///
/// # Errors
/// [`InvalidSetting`] naming the first bad setting of `config` or of `odometry`'s
/// (`IcpConfig::...`).
pub fn point_to_plane_slam_with(
    config: GraphSlamConfig,
    odometry: PointToPlaneIcp,
) -> Result<PointToPlaneSlam, InvalidSetting> {
    odometry.config.validate()?;
    assemble(config, odometry, point_to_plane_refine())
}

/// [`point_to_plane_slam`] with `optimizer` in place of graduated non-convexity (to compare
/// back ends, say an incremental smoother that does not re-solve the whole graph per loop but
/// has no defence against a wrong loop).
///
/// # Errors
/// [`InvalidSetting`] naming the first bad setting of `config`.
pub fn point_to_plane_slam_optimized_by<O: Optimizer<Pose3>>(
    config: GraphSlamConfig,
    optimizer: O,
) -> Result<GraphSlam<PointToPlaneIcp, PointToPointIcp, O>, InvalidSetting> {
    assemble_with(
        config,
        point_to_plane_tracker(),
        point_to_plane_refine(),
        optimizer,
    )
}

/// Point-to-plane loop refinement: Tukey 10 cm, pairs within 1 m.
fn point_to_plane_refine() -> PointToPlaneIcp {
    PointToPlaneIcp {
        config: IcpConfig {
            kernel: IcpKernel::Tukey { k: 0.10 },
            max_correspondence_distance: 1.0,
            ..IcpConfig::default()
        },
    }
}

/// LOAM odometry against a local map of edge and planar features (5 cm and 10 cm voxels,
/// Tukey 5 cm, as the thesis), and LOAM loop refinement with Tukey 10 cm, with `config` (usually
/// [`slam_config`]).
///
/// # Errors
/// [`InvalidSetting`] naming the first bad setting of `config`.
pub fn loam_slam(config: GraphSlamConfig) -> Result<LoamSlam, InvalidSetting> {
    let odometry = LoamRegistrator {
        config: LoamConfig::local_map_odometry(),
    };
    let refine = LoamRegistrator {
        config: LoamConfig {
            tukey_threshold: 0.10,
            initial_tukey_threshold: 1.0,
            ..LoamConfig::default()
        },
    };
    assemble(config, odometry, refine)
}

/// Scan Context place recognition with its defaults, for
/// [`GraphSlam::with_place_recognizer`]: the engine then seeks loops by appearance as well as
/// by position.
///
/// # Panics
/// Never: the default settings are valid (a test checks it).
#[must_use]
pub fn scan_context_places() -> Box<dyn PlaceRecognizer + Send> {
    // The defaults are valid; `new` only refuses invalid settings.
    #[allow(clippy::expect_used)]
    let places = ScanContextRecognizer::new(
        ScanContextConfig::default(),
        ScanContextIndexConfig::default(),
        ScanContextRecognizer::default_offset(),
    )
    .expect("default Scan Context settings are valid");
    Box::new(places)
}
