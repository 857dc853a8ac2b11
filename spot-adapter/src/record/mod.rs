//! Recordings in ([`open_recording`] opens any of them from its path), each a source of [`Sample`](crate::robot::Sample)s read one scan at a time,
//! interchangeable with a simulated run for the engine:
//!
//! - the spot-nav recording format ([`Recording`], written by [`RecordingWriter`]);
//! - KITTI odometry sequences ([`KittiSequence`]);
//! - folders of PCD or PLY scans with an optional TUM odometry file ([`CloudFolder`]);
//! - ROS 1 bags and ROS 2 bags in MCAP ([`Bag`]): `sensor_msgs/PointCloud2` in any field
//!   layout ([`PointCloud2Decoder`]), `nav_msgs/Odometry`, `tf2_msgs/TFMessage`,
//!   `sensor_msgs/Imu`.
//!
//! Every reader removes no-return points (exact zeros, points inside a minimum range) and
//! non-finite ones, and counts them ([`ReturnFilter`], [`DroppedPoints`]). A source without
//! odometry gets it from its scans with [`ScanToScanOdometry`].
//!
//! Uses `robot` (the sample type) and `slam-core`'s file formats only.

mod bag;
mod bag_file;
mod bag_samples;
mod cloud_folder;
mod frame_tree;
mod kitti;
mod lidar_only;
mod no_return;
mod point_cloud2;
mod recording;
mod ros_messages;
mod source;
mod wire;

pub use bag::{Bag, BagConfig, BagSummary, OdometrySource, ResolvedOdometry, TopicSummary};
pub use bag_file::{BagFormat, TopicInfo};
pub use bag_samples::BagSamples;
pub use cloud_folder::{CloudFolder, CloudFolderConfig, CloudFolderSamples, is_cloud_folder};
pub use frame_tree::{FrameTree, PoseSeries};
pub use kitti::{KittiOdometry, KittiSamples, KittiSequence};
pub use lidar_only::{ScanToScanConfig, ScanToScanOdometry};
pub use no_return::{DroppedPoints, PointKind, ReturnFilter};
pub use point_cloud2::{
    CloudLayout, DecodedCloud, FieldSlot, PointCloud2Config, PointCloud2Decoder, TimeFields,
    TimeUnit,
};
pub use recording::{Recording, RecordingSamples, RecordingWriter};
pub use ros_messages::{
    Header, ImuReading, Odometry, PointCloud2, PointField, RosMessageType, TransformStamped,
};
pub use source::{
    OpenedSource, RecordingKind, ReturnFiltered, SampleSource, SourceConfig, detect, open_recording,
};
pub use wire::Wire;
