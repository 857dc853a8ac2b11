//! The readers we have no writer for (we do not write bags or ROS messages): parse the bytes and,
//! when they parse, panic unless the result keeps the invariants a user relies on. Every point
//! is finite, counts agree (points kept plus points dropped is the message's `width * height`;
//! a bag delivers as many samples as it announced), poses are finite with unit rotations, and
//! decoding the same cloud again with the time unit decided gives the same cloud (NaN
//! intensities matching NaN).
//!
//! The bag readers take a path (the `rosbag` crate memory-maps its file, and [`Bag`] reads a bag
//! twice), so each input is written to a file of this process first.

use std::path::PathBuf;

use crate::same::assert_same_cloud;
use slam_core::{PointCloud, Pose3};
use spot_adapter::record::{
    Bag, BagConfig, DecodedCloud, ImuReading, Odometry, PointCloud2, PointCloud2Config,
    PointCloud2Decoder, TimeUnit, TransformStamped, Wire,
};

/// Panic unless every point, and every time, of `cloud` is finite and its channels have one
/// value per point (`what` names the cloud).
fn assert_finite_cloud(cloud: &PointCloud, what: &str) {
    let n = cloud.len();
    for (i, p) in cloud.points().iter().enumerate() {
        assert!(
            p.x.is_finite() && p.y.is_finite() && p.z.is_finite(),
            "{what}: point {i} is {p:?}"
        );
    }
    if let Some(t) = cloud.time() {
        assert_eq!(t.len(), n, "{what}: times");
        assert!(
            t.iter().all(|v| v.is_finite()),
            "{what}: a time is not finite"
        );
    }
    if let Some(r) = cloud.ring() {
        assert_eq!(r.len(), n, "{what}: rings");
    }
    if let Some(v) = cloud.intensity() {
        assert_eq!(v.len(), n, "{what}: intensities");
    }
}

/// Panic unless `pose` is finite with a unit quaternion.
fn assert_valid_pose(pose: &Pose3, what: &str) {
    let t = pose.translation.vector;
    assert!(t.iter().all(|v| v.is_finite()), "{what}: translation {t:?}");
    let q = pose.rotation.coords;
    assert!(
        q.iter().all(|v| v.is_finite()) && (q.norm() - 1.0).abs() < 1e-9,
        "{what}: rotation {q:?}"
    );
}

/// A file of this process to hold one input (`extension` tells the bag reader its format), in
/// `/dev/shm` when there is one so that writing it costs no disk.
fn scratch_file(extension: &str) -> PathBuf {
    let shm = std::path::Path::new("/dev/shm");
    let dir = if shm.is_dir() {
        shm.to_path_buf()
    } else {
        std::env::temp_dir()
    };
    dir.join(format!(
        "spot-nav-fuzz-{}-{:?}.{extension}",
        std::process::id(),
        std::thread::current().id()
    ))
    .clone()
}

/// A bag (`extension` `bag` or `mcap`): when it opens, every sample it then gives has a finite
/// cloud and poses, it gives at most the clouds it announced, and exactly those when it ends
/// without an error; its summary's cloud counts agree with its topic's count. True when the bag
/// opened and every sample was read.
fn bag(data: &[u8], extension: &str) -> bool {
    let path = scratch_file(extension);
    std::fs::write(&path, data).expect("writing the input to a scratch file");
    let checked = check_bag(&path);
    let _ = std::fs::remove_file(&path);
    checked
}

fn check_bag(path: &std::path::Path) -> bool {
    let Ok(bag) = Bag::open(path, &BagConfig::default()) else {
        return false;
    };
    let summary = bag.summary();
    let topic = summary
        .topics
        .iter()
        .find(|t| t.info.name == summary.cloud_topic)
        .expect("the cloud topic is among the topics");
    assert!(
        summary.clouds + summary.clouds_outside_odometry <= topic.count,
        "{} + {} clouds of {} messages",
        summary.clouds,
        summary.clouds_outside_odometry,
        topic.count
    );
    assert_valid_pose(&summary.body_t_lidar, "body_T_lidar");
    assert!(summary.duration.is_finite() && summary.duration >= 0.0);
    let Ok(samples) = bag.samples() else {
        return false;
    };
    let announced = samples.len();
    assert_eq!(announced, bag.len());
    let mut delivered = 0;
    for sample in samples {
        let Ok(sample) = sample else {
            return false;
        };
        delivered += 1;
        assert!(
            delivered <= announced,
            "more samples than the {announced} announced"
        );
        assert!(sample.stamp.is_finite());
        assert_valid_pose(&sample.odom_t_body, "odom_T_body");
        assert_valid_pose(&sample.body_t_lidar, "sample body_T_lidar");
        assert_finite_cloud(&sample.cloud, "bag cloud");
    }
    assert_eq!(delivered, announced, "samples delivered");
    true
}

/// A ROS 1 bag (format 2.0) through [`Bag::open`] and [`Bag::samples`].
#[must_use]
pub fn ros1_bag(data: &[u8]) -> bool {
    bag(data, "bag")
}

/// An MCAP file (ROS 2 bag) through [`Bag::open`] and [`Bag::samples`].
#[must_use]
pub fn mcap_bag(data: &[u8]) -> bool {
    bag(data, "mcap")
}

/// The wire a selector byte names (bit 0: 0 ROS 1, 1 CDR).
fn wire_of(selector: u8) -> Wire {
    if selector & 1 == 0 {
        Wire::Ros1
    } else {
        Wire::Cdr
    }
}

/// Panic unless `decoded` keeps every point of `msg` accounted for and finite.
fn assert_decoded(msg: &PointCloud2<'_>, decoded: &DecodedCloud) {
    let total = u64::from(msg.width) * u64::from(msg.height);
    let kept = decoded.cloud.len() as u64;
    let dropped = (decoded.dropped.non_finite + decoded.dropped.no_return) as u64;
    assert_eq!(kept + dropped, total, "kept {kept} + dropped {dropped}");
    assert_finite_cloud(&decoded.cloud, "PointCloud2");
}

/// A `sensor_msgs/PointCloud2` payload. Input: one selector byte (bit 0 the wire; bits 1 to 3:
/// 0 decides the time unit from the cloud, 1 to 4 gives one), then the payload. When it decodes,
/// every point is accounted for and finite, per-point times lie within the scan period of the
/// stamp, and decoding it again with the unit decided gives the same cloud.
#[must_use]
pub fn point_cloud2(data: &[u8]) -> bool {
    let Some((&selector, payload)) = data.split_first() else {
        return false;
    };
    let Ok(msg) = PointCloud2::parse(payload, wire_of(selector)) else {
        return false;
    };
    let time_unit = match (selector >> 1) & 7 {
        1 => Some(TimeUnit::SecondsRelative),
        2 => Some(TimeUnit::NanosecondsRelative),
        3 => Some(TimeUnit::SecondsAbsolute),
        4 => Some(TimeUnit::NanosecondsAbsolute),
        _ => None,
    };
    let config = PointCloud2Config {
        time_unit,
        ..PointCloud2Config::default()
    };
    let mut decoder = PointCloud2Decoder::new(config);
    let Ok(decoded) = decoder.decode(&msg) else {
        return false;
    };
    assert_decoded(&msg, &decoded);
    if let Some(t) = decoded.cloud.time() {
        // Within the period, to f32 rounding of the offsets.
        let limit = config.max_scan_period as f32 * (1.0 + 1e-6);
        assert!(
            t.iter().all(|v| v.abs() <= limit),
            "a time outside one scan period of the stamp"
        );
    }
    let unit = decoder.time_unit();
    let again = decoder
        .decode(&msg)
        .expect("a cloud decodes again with the unit it decided");
    assert_eq!(decoder.time_unit(), unit, "the unit changed");
    assert_same_cloud(&decoded.cloud, &again.cloud, "a second decoding");
    assert_eq!(
        again.dropped, decoded.dropped,
        "a second decoding's dropped points"
    );
    assert_eq!(again.layout, decoded.layout, "a second decoding's layout");
    true
}

/// `nav_msgs/Odometry`, `tf2_msgs/TFMessage` or `sensor_msgs/Imu`. Input: one selector byte
/// (bit 0 the wire, bits 1 and 2: 0 odometry, 1 tf, 2 IMU, 3 odometry), then the payload. When
/// it decodes, stamps are finite and every pose finite with a unit rotation.
#[must_use]
pub fn ros_message(data: &[u8]) -> bool {
    let Some((&selector, payload)) = data.split_first() else {
        return false;
    };
    let wire = wire_of(selector);
    match (selector >> 1) & 3 {
        1 => {
            let Ok(transforms) = TransformStamped::parse_tf_message(payload, wire) else {
                return false;
            };
            for t in &transforms {
                assert!(t.header.stamp.is_finite());
                assert_valid_pose(&t.transform, "tf transform");
            }
        }
        2 => {
            let Ok(imu) = ImuReading::parse(payload, wire) else {
                return false;
            };
            assert!(imu.stamp.is_finite());
        }
        _ => {
            let Ok(odometry) = Odometry::parse(payload, wire) else {
                return false;
            };
            assert!(odometry.header.stamp.is_finite());
            assert_valid_pose(&odometry.pose, "odometry pose");
        }
    }
    true
}
