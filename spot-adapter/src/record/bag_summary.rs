//! What [`Bag::open`](crate::record::Bag::open) found in a bag and decided ([`BagSummary`]):
//! its topics, the cloud topic and its layout, where the odometry comes from, the frames and
//! the LiDAR mounting.

use std::fmt;
use std::path::PathBuf;

use slam_core::Pose3;

use crate::record::bag_file::BagFormat;
use crate::record::bag_imu::ImuSummary;
use crate::record::bag_topics::TopicSummary;
use crate::record::point_cloud2::CloudLayout;
use crate::record::ros_messages::RosMessageType;

/// The odometry a bag's samples get, as decided.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ResolvedOdometry {
    /// A `nav_msgs/Odometry` topic.
    Topic(String),
    /// The `/tf` transform from `odom_frame` to the body frame.
    Tf {
        /// The odometry frame.
        odom_frame: String,
    },
    /// None: identity.
    None,
}

/// What [`Bag::open`](crate::record::Bag::open) found.
#[derive(Clone, Debug, PartialEq)]
pub struct BagSummary {
    /// The file.
    pub path: PathBuf,
    /// Its format.
    pub format: BagFormat,
    /// Every topic, by name.
    pub topics: Vec<TopicSummary>,
    /// Seconds from the first message to the last.
    pub duration: f64,
    /// The cloud topic used.
    pub cloud_topic: String,
    /// The first cloud's layout.
    pub layout: CloudLayout,
    /// Where the odometry comes from.
    pub odometry: ResolvedOdometry,
    /// The body frame.
    pub base_frame: String,
    /// The LiDAR frame.
    pub lidar_frame: String,
    /// The LiDAR mounting.
    pub body_t_lidar: Pose3,
    /// Clouds that will be delivered (stamped within the odometry's span).
    pub clouds: usize,
    /// Clouds stamped before the first or after the last odometry (left out).
    pub clouds_outside_odometry: usize,
    /// The IMU whose gyro gives the samples' orientation, when one does.
    pub imu: Option<ImuSummary>,
    /// What the bag has that is not used, and why, one line each (an odometry or IMU topic whose
    /// frame is not joined to the clouds' or the body's).
    pub notes: Vec<String>,
}

impl fmt::Display for BagSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "bag         {} ({:?}, {:.1} s)",
            self.path.display(),
            self.format,
            self.duration
        )?;
        for t in &self.topics {
            writeln!(
                f,
                "topic       {:<28} {:<30} {:>7} messages",
                t.info.name, t.info.type_name, t.count
            )?;
        }
        writeln!(f, "clouds      {} ({})", self.cloud_topic, self.layout)?;
        let odometry = match &self.odometry {
            ResolvedOdometry::Topic(t) => format!("topic {t}"),
            ResolvedOdometry::Tf { odom_frame } => {
                format!("/tf {odom_frame} -> {}", self.base_frame)
            }
            ResolvedOdometry::None => "none (LiDAR-only)".into(),
        };
        writeln!(f, "odometry    {odometry}")?;
        match &self.imu {
            Some(imu) => writeln!(f, "imu         {imu}")?,
            None if self
                .topics
                .iter()
                .any(|t| t.info.message_type == Some(RosMessageType::Imu)) =>
            {
                writeln!(f, "imu         none")?;
            }
            None => {}
        }
        for note in &self.notes {
            writeln!(f, "note        {note}")?;
        }
        let t = self.body_t_lidar.translation.vector;
        write!(
            f,
            "frames      body {}, lidar {} at ({:.3}, {:.3}, {:.3}) m, {:.2} deg; {} clouds used, {} outside the odometry",
            self.base_frame,
            self.lidar_frame,
            t.x,
            t.y,
            t.z,
            self.body_t_lidar.rotation.angle().to_degrees(),
            self.clouds,
            self.clouds_outside_odometry
        )
    }
}
