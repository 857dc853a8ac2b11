//! The Graph-SLAM engine put together with this workspace's backends, configured as the
//! simulated and recorded runs use it: one place for the settings that the example, the tests
//! and the benches share.

use posegraph::LevenbergMarquardt;
use registration::{
    IcpConfig, IcpKernel, LoamConfig, LoamRegistrator, PointToPlaneIcp, PointToPointIcp,
};
use slam_core::{GraphSlam, GraphSlamConfig};

/// Graph-SLAM with point-to-plane ICP odometry and loop refinement.
pub type PointToPlaneSlam = GraphSlam<PointToPlaneIcp, PointToPointIcp, LevenbergMarquardt>;

/// Graph-SLAM with LOAM odometry and loop refinement.
pub type LoamSlam = GraphSlam<LoamRegistrator, PointToPointIcp, LevenbergMarquardt>;

/// The thesis' loop check: point-to-point ICP on voxelised keyframes, and the engine settings
/// that go with it. Voxel centroids of two different scans sit a few centimetres apart, so the
/// check accepts an RMS distance up to 0.2 m.
fn loop_check() -> (PointToPointIcp, GraphSlamConfig) {
    let coarse = PointToPointIcp {
        config: IcpConfig {
            max_correspondence_distance: 1.0,
            ..IcpConfig::default()
        },
    };
    let config = GraphSlamConfig {
        loop_max_mean_squared_error: 0.04,
        ..GraphSlamConfig::default()
    };
    (coarse, config)
}

/// Point-to-plane odometry (Tukey 10 cm, pairs within 0.5 m) against the local map, and
/// point-to-plane loop refinement (Tukey 10 cm, pairs within 1 m).
#[must_use]
pub fn point_to_plane_slam() -> PointToPlaneSlam {
    let odometry = PointToPlaneIcp {
        config: IcpConfig {
            kernel: IcpKernel::Tukey { k: 0.1 },
            max_correspondence_distance: 0.5,
            ..IcpConfig::default()
        },
    };
    let refine = PointToPlaneIcp {
        config: IcpConfig {
            kernel: IcpKernel::Tukey { k: 0.10 },
            max_correspondence_distance: 1.0,
            ..IcpConfig::default()
        },
    };
    let (coarse, config) = loop_check();
    GraphSlam::new(
        config,
        odometry,
        coarse,
        refine,
        LevenbergMarquardt::default(),
    )
}

/// LOAM odometry against a local map of edge and planar features (5 cm and 10 cm voxels,
/// Tukey 5 cm, as the thesis), and LOAM loop refinement with Tukey 10 cm.
#[must_use]
pub fn loam_slam() -> LoamSlam {
    let odometry = LoamRegistrator {
        config: LoamConfig::default(),
    };
    let refine = LoamRegistrator {
        config: LoamConfig {
            tukey_threshold: 0.10,
            initial_tukey_threshold: 1.0,
            ..LoamConfig::default()
        },
    };
    let (coarse, config) = loop_check();
    GraphSlam::new(
        config,
        odometry,
        coarse,
        refine,
        LevenbergMarquardt::default(),
    )
}
