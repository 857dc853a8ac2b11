//! Recordings in ([`open_recording`] opens any of them from its path), each a source of [`Sample`](crate::robot::Sample)s read one scan at a time,
//! interchangeable with a simulated run for the engine:
//!
//! - the spot-nav recording format ([`Recording`], written by [`RecordingWriter`]);
//! - KITTI odometry sequences ([`KittiSequence`]);
//! - folders of PCD or PLY scans with an optional TUM odometry file ([`CloudFolder`]);
//! - ROS 1 bags and ROS 2 bags in MCAP ([`Bag`]): `sensor_msgs/PointCloud2` in any field
//!   layout ([`PointCloud2Decoder`]), `nav_msgs/Odometry`, `tf2_msgs/TFMessage`,
//!   `sensor_msgs/Imu` (its gyro integrated into the body's orientation, [`GyroIntegrator`]).
//!
//! Every reader removes no-return points (exact zeros, points inside a minimum range) and
//! non-finite ones, and counts them ([`ReturnFilter`], [`DroppedPoints`]). A source without
//! odometry says so ([`OpenedSource::has_odometry`]): feed its samples to the engine with
//! [`Sample::lidar_only_input`](crate::robot::Sample::lidar_only_input), which tracks them by
//! registration alone.
//!
//! A cloud as a driver publishes it (Ouster's convention: integer nanoseconds under `t`, a
//! no-return at the origin), decoded:
//!
//! ```
//! use spot_adapter::record::{
//!     Header, PointCloud2, PointCloud2Config, PointCloud2Decoder, PointField, TimeUnit,
//! };
//!
//! let field = |name: &str, offset, datatype| PointField { name: name.into(), offset, datatype, count: 1 };
//! let mut data = Vec::new();
//! for (x, t_ns) in [(2.0f32, 0u32), (0.0, 50_000_000), (3.0, 99_000_000)] {
//!     for v in [x, 1.0, 0.5] {
//!         data.extend_from_slice(&v.to_le_bytes()); // x y z float32
//!     }
//!     data.extend_from_slice(&t_ns.to_le_bytes()); // t uint32
//! }
//! data[16..28].fill(0); // the second point: no return
//! let msg = PointCloud2 {
//!     header: Header { stamp: 1.7e9, frame_id: "os_sensor".into() },
//!     height: 1,
//!     width: 3,
//!     fields: vec![field("x", 0, 7), field("y", 4, 7), field("z", 8, 7), field("t", 12, 6)],
//!     is_bigendian: false,
//!     point_step: 16,
//!     row_step: 48,
//!     data: &data,
//! };
//! let mut decoder = PointCloud2Decoder::new(PointCloud2Config::default());
//! let decoded = decoder.decode(&msg)?;
//! assert_eq!(decoder.time_unit(), Some(TimeUnit::NanosecondsRelative));
//! assert_eq!(decoded.cloud.len(), 2);
//! assert_eq!(decoded.dropped.no_return, 1);
//! assert_eq!(decoded.cloud.time(), Some(&[0.0, 0.099][..]));
//! # Ok::<(), spot_adapter::MessageError>(())
//! ```
//!
//! Every file is read only when it is a regular file of at most [`MAX_RECORDING_FILE_BYTES`].
//!
//! Uses `robot` (the sample type) and `slam-core`'s file formats only.

mod bag;
mod bag_decoding;
mod bag_file;
mod bag_frames;
mod bag_imu;
mod bag_samples;
mod bag_summary;
mod bag_topics;
mod bounded_file;
mod cloud_folder;
mod error;
mod folder_files;
mod frame_tree;
mod imu;
mod kitti;
mod mcap_file;
mod message_error;
mod no_return;
mod point_cloud2;
mod read_ahead;
mod recording;
mod recording_writer;
mod ros_messages;
mod source;
#[cfg(feature = "serde")]
mod source_forms;
mod time_unit;
mod wire;

pub use bag::{Bag, BagConfig, OdometrySource};
pub use bag_file::{BagFormat, TopicInfo};
pub use bag_frames::BagFrames;
pub use bag_imu::{ImuSource, ImuSummary};
pub use bag_samples::BagSamples;
pub use bag_summary::{BagSummary, ResolvedOdometry};
pub use bag_topics::TopicSummary;
pub use bounded_file::MAX_RECORDING_FILE_BYTES;
pub use cloud_folder::{CloudFolder, CloudFolderConfig, CloudFolderSamples, is_cloud_folder};
pub use error::{BodyFrameSource, CalibrationProblem, IndexLineProblem, RecordError};
pub use frame_tree::{FrameTree, PoseSeries};
pub use imu::{GyroCounts, GyroIntegrator, GyroStep, MAX_GYRO_GAP};
pub use kitti::{KittiOdometry, KittiSamples, KittiSequence};
pub use message_error::{MessageError, TimeUnitProblem};
pub use no_return::{DroppedPoints, PointKind, ReturnFilter};
pub use point_cloud2::{
    CloudLayout, DecodedCloud, FieldSlot, PointCloud2Config, PointCloud2Decoder, TimeFields,
    TimeUnit,
};
pub use read_ahead::ReadAhead;
pub use recording::{
    IndexEntry, Recording, RecordingSamples, calibration_text, parse_calibration, parse_index,
};
pub use recording_writer::RecordingWriter;
pub use ros_messages::{
    Header, ImuReading, Odometry, PointCloud2, PointField, RosMessageType, TransformStamped,
};
pub use source::{
    OpenedSource, RecordingKind, ReturnFiltered, SampleSource, SourceConfig, detect, open_recording,
};
pub use wire::Wire;
