//! The Graph-SLAM engine with the real backends (point-to-plane ICP odometry, point-to-point
//! loop check, point-to-plane refinement, Levenberg-Marquardt) on a simulated lap of a generated
//! building, against the simulator's ground truth.
#![allow(clippy::unwrap_used)]

use posegraph::LevenbergMarquardt;
use registration::{IcpConfig, IcpKernel, PointToPlaneIcp, PointToPointIcp};
use slam_core::io::StampedPose;
use slam_core::{GraphSlam, GraphSlamConfig};
use spot_adapter::{
    DEFAULT_MAX_STAMP_DIFFERENCE, INDOOR_SEGMENT_LENGTHS, SimulatedSpot, SimulationConfig,
    TrajectoryEvaluation,
};

#[test]
fn simulated_loop_meets_the_accuracy_targets() {
    let seed = 3;
    let mut config = SimulationConfig::default();
    config.seed = seed;
    let sim = SimulatedSpot::corridor_loop(seed, &config).unwrap();
    let body_t_lidar = sim.body_t_lidar();
    let truth = sim.ground_truth();
    let odometry = PointToPlaneIcp {
        config: IcpConfig {
            kernel: IcpKernel::Tukey { k: 0.1 },
            max_correspondence_distance: 0.5,
            ..IcpConfig::default()
        },
    };
    let coarse = PointToPointIcp {
        config: IcpConfig {
            max_correspondence_distance: 1.0,
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
    let slam_config = GraphSlamConfig {
        loop_max_mean_squared_error: 0.04,
        ..GraphSlamConfig::default()
    };
    let mut slam = GraphSlam::new(
        slam_config,
        odometry,
        coarse,
        refine,
        LevenbergMarquardt::default(),
    );
    let mut odom = Vec::new();
    for sample in sim {
        odom.push(StampedPose {
            stamp: sample.stamp,
            pose: sample.odom_t_body,
        });
        slam.process(&sample.scan_input());
    }
    let report = slam.report();
    assert!(report.loops_closed >= 1, "{report:?}");
    let lidar_t_body = body_t_lidar.inverse();
    let estimate: Vec<StampedPose> = slam
        .scan_trajectory()
        .into_iter()
        .map(|(stamp, p)| StampedPose {
            stamp,
            pose: p * lidar_t_body,
        })
        .collect();
    let e = TrajectoryEvaluation::compute(
        &estimate,
        &truth,
        DEFAULT_MAX_STAMP_DIFFERENCE,
        &INDOOR_SEGMENT_LENGTHS,
    )
    .unwrap();
    let o = TrajectoryEvaluation::compute(
        &odom,
        &truth,
        DEFAULT_MAX_STAMP_DIFFERENCE,
        &INDOOR_SEGMENT_LENGTHS,
    )
    .unwrap();
    assert!(e.end_point.path_length > 100.0, "a loop of at least 100 m");
    assert!(e.ate.rmse <= 0.05, "ATE {} m", e.ate.rmse);
    assert!(
        e.loop_end_point_error <= 0.05,
        "loop end-point error {} m",
        e.loop_end_point_error
    );
    let segments = e.segments.unwrap();
    assert!(
        segments.translation <= 0.002,
        "segment drift {} %",
        100.0 * segments.translation
    );
    // Spot's own odometry drifts about 1.9 %: SLAM must be far better.
    assert!(o.loop_end_point_error > 10.0 * e.loop_end_point_error.max(0.01));
}
