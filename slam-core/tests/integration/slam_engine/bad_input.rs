//! Bad settings refused by name, and a keyframe pose that overflows reported as such.

use super::{brute_engine, feed, hall, loop_poses, no_loop_config};
use nalgebra::Point3;
use slam_core::tracking::{ReachConfig, TrackerConfig};
use slam_core::{EdgeInformation, GraphSlamConfig, PointCloud, Pose3, ScanInput, ScanOutcome};

/// Sets one scalar setting of a configuration.
type Set = fn(&mut GraphSlamConfig, f64);

#[test]
fn bad_settings_are_refused_by_name() {
    let build = |config: GraphSlamConfig| brute_engine(config).err().map(|e| (e.setting, e.value));
    assert_eq!(build(GraphSlamConfig::default()), None);
    let zero_sigma = GraphSlamConfig {
        loop_information: EdgeInformation::Fixed {
            translation_sigma: 0.0,
            rotation_sigma: 0.01,
        },
        ..GraphSlamConfig::default()
    };
    assert_eq!(
        build(zero_sigma),
        Some(("GraphSlamConfig::loop_information::translation_sigma", 0.0))
    );
    let tiny_sigma = GraphSlamConfig {
        odometry_information: EdgeInformation::Fixed {
            translation_sigma: 0.01,
            rotation_sigma: 1e-200,
        },
        ..GraphSlamConfig::default()
    };
    assert_eq!(
        build(tiny_sigma),
        Some((
            "GraphSlamConfig::odometry_information::rotation_sigma",
            1e-200
        ))
    );
    let nan_scale = GraphSlamConfig {
        odometry_information: EdgeInformation::FixedAndRegistration {
            translation_sigma: 0.01,
            rotation_sigma: 0.01,
            scale: f64::NAN,
        },
        ..GraphSlamConfig::default()
    };
    assert_eq!(
        build(nan_scale).map(|(setting, _)| setting),
        Some("GraphSlamConfig::odometry_information::scale")
    );
    // Scalar settings, each with the bad values it must refuse by name.
    let scalars: [(&str, Set, &[f64]); 9] = [
        (
            "GraphSlamConfig::gravity_tilt_sigma",
            |c, v| c.gravity_tilt_sigma = v,
            &[f64::NAN, 0.0, -1e-4],
        ),
        (
            "GraphSlamConfig::sweep_min_gain",
            |c, v| c.sweep_min_gain = v,
            &[f64::NAN, -0.1, 1.0],
        ),
        (
            "GraphSlamConfig::sweep_min_inlier_gain",
            |c, v| c.sweep_min_inlier_gain = v,
            &[f64::NAN, 0.0, -0.1, 1.5],
        ),
        (
            "GraphSlamConfig::loop_max_drift_rate",
            |c, v| c.loop_max_drift_rate = v,
            &[f64::NAN, -0.01],
        ),
        (
            "GraphSlamConfig::loop_max_height_drift_rate",
            |c, v| c.loop_max_height_drift_rate = v,
            &[f64::NAN, -0.01],
        ),
        (
            "GraphSlamConfig::keyframe_distance",
            |c, v| c.keyframe_distance = v,
            &[f64::NAN],
        ),
        (
            "GraphSlamConfig::map_voxel_size",
            |c, v| c.map_voxel_size = v as f32,
            &[-0.05],
        ),
        (
            "GraphSlamConfig::keyframe_scan_spacing",
            |c, v| c.keyframe_scan_spacing = v,
            &[f64::NAN, -1.0, f64::INFINITY],
        ),
        (
            "TrackerConfig::recheck_basin",
            |c, v| c.tracker.recheck_basin = v,
            &[f64::NAN, -0.01, f64::INFINITY],
        ),
    ];
    for (setting, set, bad) in scalars {
        for &v in bad {
            let mut config = GraphSlamConfig::default();
            set(&mut config, v);
            assert_eq!(
                build(config).map(|(s, _)| s),
                Some(setting),
                "{setting} = {v}"
            );
        }
    }
    let cases: [(GraphSlamConfig, &str); 5] = [
        (
            GraphSlamConfig {
                local_map_keyframes: 0,
                ..GraphSlamConfig::default()
            },
            "GraphSlamConfig::local_map_keyframes",
        ),
        (
            GraphSlamConfig {
                tracker: TrackerConfig {
                    arbitration_distance: 0.0,
                    ..TrackerConfig::default()
                },
                ..GraphSlamConfig::default()
            },
            "TrackerConfig::arbitration_distance",
        ),
        (
            GraphSlamConfig {
                tracker: TrackerConfig {
                    reach: ReachConfig {
                        max: f64::NAN,
                        ..ReachConfig::default()
                    },
                    ..TrackerConfig::default()
                },
                ..GraphSlamConfig::default()
            },
            "ReachConfig::max",
        ),
        (
            GraphSlamConfig {
                loop_kernel: Some(slam_core::RobustKernel::Cauchy { c: -1.0 }),
                ..GraphSlamConfig::default()
            },
            "GraphSlamConfig::loop_kernel",
        ),
        (
            GraphSlamConfig {
                loop_information: EdgeInformation::FromRegistration { scale: 0.0 },
                ..GraphSlamConfig::default()
            },
            "GraphSlamConfig::loop_information::scale",
        ),
    ];
    for (config, setting) in cases {
        assert_eq!(build(config).map(|(s, _)| s), Some(setting));
    }
}

#[test]
fn an_overflowing_keyframe_pose_is_reported_as_such() {
    let world = hall();
    let truth = loop_poses();
    let config = no_loop_config();
    let mut slam = brute_engine(config).unwrap();
    for (k, gt) in truth.iter().take(6).enumerate() {
        feed(&mut slam, &world, k, gt, *gt);
    }
    // Points 500 m away match nothing, so no registration can stand in for the odometry.
    let far: PointCloud = PointCloud::from_points(
        (0..100)
            .map(|i| Point3::new(500.0 + 0.1 * i as f32, 0.0, 0.0))
            .collect(),
    );
    let input = |k: usize, odom: Pose3| ScanInput {
        stamp: k as f64 * 0.2,
        odom_t_body: Some(odom),
        body_t_lidar: Pose3::identity(),
        cloud: &far,
        gyro_orientation: None,
    };
    // Finite odometry: a keyframe at about 1.8e308 m (kept, unregistered)...
    assert!(matches!(
        slam.process(&input(6, Pose3::translation(f64::MAX, 0.0, 0.0))),
        ScanOutcome::Keyframe {
            registered: false,
            ..
        }
    ));
    // ... then a step from it that overflows to infinity.
    assert_eq!(
        slam.process(&input(7, Pose3::translation(-f64::MAX, 0.0, 0.0))),
        ScanOutcome::Skipped(slam_core::SkipReason::NonFinitePose)
    );
    let report = slam.report();
    assert_eq!(report.skipped_non_finite_pose, 1, "{report:?}");
    assert_eq!(report.skipped_non_finite_odometry, 0, "{report:?}");
    // The graph is untouched by the refusal: one node per keyframe, a chain of edges.
    assert_eq!(slam.graph().node_count(), slam.keyframe_count());
    assert_eq!(slam.graph().edge_count(), slam.keyframe_count() - 1);
}
