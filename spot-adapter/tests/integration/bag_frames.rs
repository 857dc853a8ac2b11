//! Bags whose odometry does not reach the clouds: a public ROS 1 bag of Luminar scans beside a
//! 2D simulator's ground truth (`nav_msgs/Odometry` with an empty child frame, no `/tf_static`)
//! once made `slam` take that ground truth as the body's odometry and fail on a transform from
//! `""`. Written by rosbags (`unlinked_messages` in `tests/bags/write_bags.py`), in both formats:
//! by default such a topic is left out, said in the description, and the run is LiDAR-only; asked
//! for by name, it is an error naming both frames, the frames the bag has and what to pass.

#![allow(clippy::unwrap_used, clippy::panic, clippy::expect_used)]

use std::path::PathBuf;

use slam_core::Pose3;
use spot_adapter::record::RecordError;
use spot_adapter::record::{
    Bag, BagConfig, OdometrySource, ResolvedOdometry, SourceConfig, open_recording,
};

use super::bags::bags;

/// Clouds in the bags.
const SCANS: usize = 5;

fn unlinked() -> [PathBuf; 2] {
    let dir = bags().join("bags");
    [dir.join("unlinked/unlinked.mcap"), dir.join("unlinked.bag")]
}

#[test]
fn odometry_not_linked_to_the_clouds_is_left_out_and_said() {
    let paths = unlinked();
    for path in paths {
        let source = open_recording(&path, &SourceConfig::default()).unwrap();
        assert!(!source.has_odometry, "{}", path.display());
        let said = "odometry topic /sim/ground_truth ignored: child frame \"\" is not linked to the \
                    cloud frame \"lidar\"; running LiDAR-only (pass --odom-topic /sim/ground_truth \
                    --base-frame F to use it)";
        assert!(
            source.description.contains(said),
            "{}:\n{}",
            path.display(),
            source.description
        );
        let bag = Bag::open(&path, &BagConfig::default()).unwrap();
        assert_eq!(bag.summary().odometry, ResolvedOdometry::None);
        assert_eq!(bag.summary().base_frame, "lidar");
        assert_eq!(bag.len(), SCANS);
        let mut n = 0;
        for sample in bag.samples().unwrap() {
            let sample = sample.unwrap();
            assert_eq!(sample.odom_t_body, Pose3::identity());
            assert_eq!(sample.body_t_lidar, Pose3::identity());
            n += 1;
        }
        assert_eq!(n, SCANS);
    }
}

#[test]
fn odometry_asked_for_that_does_not_reach_the_clouds_names_the_frames() {
    let paths = unlinked();
    for path in paths {
        let config = BagConfig {
            odometry: OdometrySource::Topic("/sim/ground_truth".into()),
            ..BagConfig::default()
        };
        let err = Bag::open(&path, &config).unwrap_err();
        assert!(
            matches!(&err, RecordError::UnlinkedLidar { body_frame, lidar_frame, .. } if body_frame.is_empty() && lidar_frame == "lidar"),
            "{err}"
        );
        let text = err.to_string();
        for needle in [
            // Both frames.
            "body frame \"\"",
            "LiDAR frame \"lidar\"",
            // The frames the bag has, and the topics looked at.
            "/tf: \"world\" -> \"robot2d\"",
            "/tf_static: not in the bag",
            "/sim/ground_truth: \"map\" -> \"\"",
            "IMU /imu: \"imu_link\"",
            // What to pass.
            "--no-odometry",
            "--base-frame",
            "--odom-topic",
            "--odom-frame",
        ] {
            assert!(text.contains(needle), "{needle:?} not in: {text}");
        }
        // Its advice works: the topic taken as the LiDAR's own odometry.
        let bag = Bag::open(
            &path,
            &BagConfig {
                base_frame: Some("lidar".into()),
                ..config
            },
        )
        .unwrap();
        assert_eq!(
            bag.summary().odometry,
            ResolvedOdometry::Topic("/sim/ground_truth".into())
        );
        assert_eq!(bag.body_t_lidar(), Pose3::identity());
        assert_eq!(bag.samples().unwrap().count(), SCANS);
    }
}
