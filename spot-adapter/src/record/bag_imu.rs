//! Which `sensor_msgs/Imu` topic of a bag gives its samples a gyro orientation
//! ([`GyroIntegrator`]), and the IMU's mounting in the body frame from `/tf_static`.
//!
//! By default ([`ImuSource::Auto`]) the only IMU topic is used when its frame is joined to the
//! body frame by fixed transforms; several IMU topics, or one in a frame not joined to the body,
//! give no gyro, and the summary's notes say why. A topic asked for by name that is absent, of
//! another type or in a frame not joined to the body is an error.

use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;

use nalgebra::UnitQuaternion;

use crate::record::RecordError;
use crate::record::bag_frames::BagFrames;
use crate::record::bag_topics::{TopicSummary, check_topic_type};
use crate::record::frame_tree::FrameTree;
use crate::record::imu::{GyroCounts, GyroIntegrator, MAX_GYRO_GAP};
use crate::record::ros_messages::RosMessageType;

/// Where the samples' gyro orientation comes from. In a settings file (feature `serde`), tagged
/// by `kind`: `{ kind = "Topic", topic = "/imu" }`, `{ kind = "Auto" }`, `{ kind = "None" }`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(
        from = "crate::record::source_forms::ImuSourceForm",
        into = "crate::record::source_forms::ImuSourceForm"
    )
)]
pub enum ImuSource {
    /// The only `sensor_msgs/Imu` topic, when its frame is joined to the body frame by fixed
    /// transforms; else none, and the summary's notes say why.
    #[default]
    Auto,
    /// This `sensor_msgs/Imu` topic.
    Topic(String),
    /// None: every sample's `gyro_orientation` is `None`.
    None,
}

/// The IMU a bag's samples get their gyro orientation from, as decided and surveyed.
#[derive(Clone, Debug, PartialEq)]
pub struct ImuSummary {
    /// The topic.
    pub topic: String,
    /// The frame of its readings (the first reading's `frame_id`).
    pub frame: String,
    /// The IMU frame's rotation in the body frame.
    pub body_r_imu: UnitQuaternion<f64>,
    /// What became of its readings ([`GyroIntegrator`] rules).
    pub counts: GyroCounts,
    /// The first and last stamps of the readings used (seconds); `None` when none was used.
    pub span: Option<(f64, f64)>,
    /// Clouds delivered that are stamped outside that span (their gyro orientation is `None`).
    pub clouds_outside: usize,
}

impl fmt::Display for ImuSummary {
    /// `/imu in "imu_link" (800 readings, 200.0 Hz): gyro integrated into the body's orientation`,
    /// then the readings dropped, the gaps and the clouds outside its readings, when any.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let c = &self.counts;
        write!(f, "{} in {:?} ({} readings", self.topic, self.frame, c.used)?;
        if let Some((first, last)) = self.span.filter(|(a, b)| b > a) {
            write!(
                f,
                ", {:.1} Hz",
                c.used.saturating_sub(1) as f64 / (last - first)
            )?;
        }
        write!(f, "): gyro integrated into the body's orientation")?;
        let dropped: Vec<String> = [
            (c.out_of_order, "out of order"),
            (c.non_finite, "with a non-finite rate"),
            (c.other_frame, "in another frame"),
        ]
        .iter()
        .filter(|(n, _)| *n > 0)
        .map(|(n, why)| format!("{n} {why}"))
        .collect();
        if !dropped.is_empty() {
            write!(f, "; readings dropped: {}", dropped.join(", "))?;
        }
        if c.gaps > 0 {
            write!(
                f,
                "; gaps over {MAX_GYRO_GAP} s: {} (not integrated across: no orientation for a cloud inside one, nor for the first cloud after it if the cloud before it had one)",
                c.gaps
            )?;
        }
        if self.clouds_outside > 0 {
            write!(
                f,
                "; clouds outside its readings, without orientation: {}",
                self.clouds_outside
            )?;
        }
        Ok(())
    }
}

/// The IMU topics a bag has, surveyed, and what the samples need to decide on one.
pub(super) struct ImuChoice<'a> {
    pub path: &'a Path,
    pub topics: &'a BTreeMap<String, TopicSummary>,
    /// Per IMU topic, its readings integrated (identity mounting) to count and span them.
    pub gyros: &'a BTreeMap<String, GyroIntegrator>,
    pub fixed: &'a FrameTree,
    pub base_frame: &'a str,
    /// The stamps of the clouds that will be delivered.
    pub clouds: &'a [f64],
    pub frames: &'a BagFrames,
}

impl ImuChoice<'_> {
    /// The IMU used, or none with the reason as a note when there is one to say.
    ///
    /// # Errors
    /// [`RecordError::NoTopic`] for an IMU topic asked for that the bag does not have,
    /// [`RecordError::Message`] for one of another type, [`RecordError::UnlinkedImu`] for one
    /// whose frame is not joined to the body frame by fixed transforms.
    pub(super) fn resolve(
        &self,
        source: &ImuSource,
    ) -> Result<(Option<ImuSummary>, Option<String>), RecordError> {
        let topic = match source {
            ImuSource::None => return Ok((None, None)),
            ImuSource::Topic(t) => {
                check_topic_type(self.path, self.topics, t, RosMessageType::Imu)?;
                t.clone()
            }
            ImuSource::Auto => {
                let imus: Vec<&str> = self
                    .topics
                    .values()
                    .filter(|t| t.info.message_type == Some(RosMessageType::Imu))
                    .map(|t| t.info.name.as_str())
                    .collect();
                match imus.as_slice() {
                    [] => return Ok((None, None)),
                    [one] => (*one).to_owned(),
                    many => {
                        return Ok((
                            None,
                            Some(format!(
                                "several sensor_msgs/Imu topics ({}): no gyro orientation (pass --imu-topic T to use one)",
                                many.join(", ")
                            )),
                        ));
                    }
                }
            }
        };
        let Some(gyro) = self.gyros.get(&topic) else {
            // A topic without a single message.
            return Ok((None, Some(format!("IMU topic {topic} has no reading"))));
        };
        let frame = gyro.frame();
        let Some(body_r_imu) = self.mounting(frame) else {
            if matches!(source, ImuSource::Topic(_)) {
                return Err(RecordError::UnlinkedImu {
                    path: self.path.to_path_buf(),
                    topic,
                    imu_frame: frame.to_owned(),
                    body_frame: self.base_frame.to_owned(),
                    frames: Box::new(self.frames.clone()),
                });
            }
            return Ok((
                None,
                Some(format!(
                    "IMU topic {topic} ignored: its frame {frame:?} is not joined to the body frame {:?} by /tf_static; no gyro orientation (pass --imu-topic {topic} --base-frame F with a body frame joined to it to use it)",
                    self.base_frame
                )),
            ));
        };
        let span = gyro.first_stamp().zip(gyro.last_stamp());
        let clouds_outside = self
            .clouds
            .iter()
            .filter(|&&t| span.is_none_or(|(first, last)| t < first || t > last))
            .count();
        Ok((
            Some(ImuSummary {
                topic,
                frame: frame.to_owned(),
                body_r_imu,
                counts: gyro.counts(),
                span,
                clouds_outside,
            }),
            None,
        ))
    }

    /// `body_R_imu` when fixed transforms join the two frames (an empty frame never is).
    fn mounting(&self, frame: &str) -> Option<UnitQuaternion<f64>> {
        if frame.is_empty() {
            return None;
        }
        if frame == self.base_frame {
            return Some(UnitQuaternion::identity());
        }
        self.fixed
            .lookup(self.base_frame, frame, 0.0)
            .filter(|_| self.fixed.is_fixed_between(self.base_frame, frame))
            .map(|pose| pose.rotation)
    }
}
