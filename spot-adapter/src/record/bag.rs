//! A ROS 1 or ROS 2 (MCAP) bag as a source of [`Sample`](crate::robot::Sample)s: the clouds of one
//! `sensor_msgs/PointCloud2` topic, each with `odom_T_body` at its stamp (from a
//! `nav_msgs/Odometry` topic, or from the `/tf` tree between an odometry frame and the body
//! frame) and `body_T_lidar` from `/tf_static`.
//!
//! [`Bag::open`] reads the bag once, streaming, to find its topics, counts, duration, frames,
//! the first cloud's layout and the fixed transforms, and checks every message it will need, so
//! that a bad bag fails before any output is written. [`Bag::samples`] then reads it again, a
//! message at a time: memory holds the few clouds that wait for the odometry after them.

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

use slam_core::Pose3;

use crate::error::{AdapterError, MessageError};
use crate::record::bag_file::{BagFormat, BagMessages, RawMessage, TopicInfo};
use crate::record::bag_samples::BagSamples;
use crate::record::frame_tree::FrameTree;
use crate::record::point_cloud2::{CloudLayout, PointCloud2Config, PointCloud2Decoder, TimeUnit};
use crate::record::ros_messages::{
    Header, ImuReading, Odometry, PointCloud2, RosMessageType, decode_tf_message,
};
use crate::record::wire::WireReader;

/// Where the odometry of a bag comes from.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum OdometrySource {
    /// The only `nav_msgs/Odometry` topic, else the `/tf` transform from `odom` to its moving
    /// child, else none.
    #[default]
    Auto,
    /// This `nav_msgs/Odometry` topic.
    Topic(String),
    /// The `/tf` tree from this odometry frame to the body frame.
    Tf {
        /// The odometry frame (`odom`, Spot's `odom` or `vision`).
        odom_frame: String,
    },
    /// No odometry: every `odom_T_body` is the identity (LiDAR-only runs).
    None,
}

/// How to read a bag.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BagConfig {
    /// The cloud topic; `None` takes the only `sensor_msgs/PointCloud2` topic.
    pub cloud_topic: Option<String>,
    /// Where `odom_T_body` comes from.
    pub odometry: OdometrySource,
    /// The body frame; `None` takes the odometry's `child_frame_id` (or the moving child of the
    /// odometry frame in `/tf`); without odometry, the LiDAR frame.
    pub base_frame: Option<String>,
    /// The LiDAR frame; `None` takes the clouds' `frame_id`.
    pub lidar_frame: Option<String>,
    /// How clouds are decoded.
    pub cloud: PointCloud2Config,
}

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

/// One topic's count and log-time span.
#[derive(Clone, Debug, PartialEq)]
pub struct TopicSummary {
    /// The topic.
    pub info: TopicInfo,
    /// Messages.
    pub count: usize,
    /// First log time (seconds).
    pub first: f64,
    /// Last log time (seconds).
    pub last: f64,
}

/// What [`Bag::open`] found.
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

/// A bag opened and checked.
#[derive(Clone, Debug)]
pub struct Bag {
    pub(super) summary: BagSummary,
    /// The fixed transforms.
    pub(super) fixed: FrameTree,
    /// The stamps between which odometry is known.
    pub(super) span: (f64, f64),
    /// The decoder with the time unit decided on the first cloud.
    pub(super) decoder: PointCloud2Decoder,
}

/// The error for message `index` of `topic`.
pub(super) fn message_error(
    path: &Path,
    topic: &str,
    index: usize,
    source: MessageError,
) -> AdapterError {
    AdapterError::Message {
        path: path.to_path_buf(),
        topic: topic.to_owned(),
        index,
        source: Box::new(source),
    }
}

fn bad(path: &Path, message: String) -> AdapterError {
    AdapterError::Recording {
        path: path.to_path_buf(),
        message,
    }
}

/// Whether `topic` is a tf topic, and whether the static one.
pub(super) fn tf_kind(topic: &str) -> Option<bool> {
    match topic.trim_start_matches('/') {
        "tf" => Some(false),
        "tf_static" => Some(true),
        _ => None,
    }
}

/// A decoded message the samples need.
pub(super) enum Decoded<'a> {
    Cloud(PointCloud2<'a>),
    Odometry(Odometry),
    Tf(Vec<crate::record::ros_messages::TransformStamped>, bool),
    Imu(ImuReading),
}

/// Decode `msg` as what its topic carries; `None` for topics not used.
pub(super) fn decode(msg: &RawMessage) -> Result<Option<Decoded<'_>>, MessageError> {
    let Some(kind) = msg.topic.message_type else {
        return Ok(None);
    };
    let mut r = WireReader::new(&msg.data, msg.topic.wire)?;
    Ok(Some(match kind {
        RosMessageType::PointCloud2 => Decoded::Cloud(PointCloud2::decode(&mut r)?),
        RosMessageType::Odometry => Decoded::Odometry(Odometry::decode(&mut r)?),
        RosMessageType::TfMessage => match tf_kind(&msg.topic.name) {
            Some(is_static) => Decoded::Tf(decode_tf_message(&mut r)?, is_static),
            None => return Ok(None),
        },
        RosMessageType::Imu => Decoded::Imu(ImuReading::decode(&mut r)?),
    }))
}

/// The header of a cloud payload only.
pub(super) fn cloud_header(msg: &RawMessage) -> Result<Header, MessageError> {
    let mut r = WireReader::new(&msg.data, msg.topic.wire)?;
    Header::decode(&mut r)
}

/// What the first pass gathers.
#[derive(Default)]
struct Survey {
    topics: BTreeMap<String, TopicSummary>,
    fixed: FrameTree,
    moving: FrameTree,
    /// Per odometry topic: first stamp, last stamp, frame, child frame.
    odometry: BTreeMap<String, (f64, f64, String, String)>,
    /// Per cloud topic: stamps, and the first cloud's frame.
    clouds: BTreeMap<String, (Vec<f64>, String)>,
}

impl Bag {
    /// Open the bag at `path` (`.mcap` or `.bag`) and check it in one streaming pass.
    ///
    /// # Errors
    /// [`AdapterError::Io`], [`AdapterError::Mcap`], [`AdapterError::McapLength`],
    /// [`AdapterError::Ros1Bag`] or [`AdapterError::Recording`] for a file that cannot be read
    /// (truncated, not a bag); [`AdapterError::Message`] for a message that cannot be decoded, a cloud topic of another
    /// type, a missing transform; [`AdapterError::Recording`] when the topics asked for are
    /// absent or the choice is ambiguous.
    pub fn open(path: impl AsRef<Path>, config: &BagConfig) -> Result<Self, AdapterError> {
        let path = path.as_ref();
        let format = BagFormat::from_path(path)
            .ok_or_else(|| bad(path, "a bag must end in .mcap or .bag".into()))?;
        let survey = Self::survey(path, format)?;
        Self::resolve(path, format, survey, config)
    }

    fn survey(path: &Path, format: BagFormat) -> Result<Survey, AdapterError> {
        let mut s = Survey::default();
        for msg in BagMessages::open(path, format)? {
            let msg = msg?;
            let name = &msg.topic.name;
            let time = msg.log_time as f64 * 1e-9;
            let entry = s
                .topics
                .entry(name.clone())
                .or_insert_with(|| TopicSummary {
                    info: (*msg.topic).clone(),
                    count: 0,
                    first: time,
                    last: time,
                });
            let index = entry.count;
            entry.count += 1;
            entry.first = entry.first.min(time);
            entry.last = entry.last.max(time);
            let at = |e| message_error(path, name, index, e);
            if msg.topic.message_type == Some(RosMessageType::PointCloud2) {
                let header = cloud_header(&msg).map_err(at)?;
                s.clouds
                    .entry(name.clone())
                    .or_insert_with(|| (Vec::new(), header.frame_id.clone()))
                    .0
                    .push(header.stamp);
                continue;
            }
            match decode(&msg).map_err(at)? {
                Some(Decoded::Tf(transforms, is_static)) => {
                    for t in transforms {
                        if is_static {
                            s.fixed
                                .set_fixed(&t.header.frame_id, &t.child_frame_id, t.transform);
                        } else {
                            s.moving.push_moving(
                                &t.header.frame_id,
                                &t.child_frame_id,
                                t.header.stamp,
                                t.transform,
                            );
                            // Only the span is needed here.
                            s.moving.prune_before(t.header.stamp);
                        }
                    }
                }
                Some(Decoded::Odometry(o)) => {
                    let e = s.odometry.entry(name.clone()).or_insert_with(|| {
                        (
                            o.header.stamp,
                            o.header.stamp,
                            o.header.frame_id.clone(),
                            o.child_frame_id.clone(),
                        )
                    });
                    e.0 = e.0.min(o.header.stamp);
                    e.1 = e.1.max(o.header.stamp);
                }
                _ => {}
            }
        }
        Ok(s)
    }

    #[allow(clippy::too_many_lines)]
    fn resolve(
        path: &Path,
        format: BagFormat,
        mut s: Survey,
        config: &BagConfig,
    ) -> Result<Self, AdapterError> {
        let of_type = |t: RosMessageType| -> Vec<&str> {
            s.topics
                .values()
                .filter(|x| x.info.message_type == Some(t))
                .map(|x| x.info.name.as_str())
                .collect()
        };
        let listing = || {
            s.topics
                .values()
                .map(|t| format!("{} ({})", t.info.name, t.info.type_name))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let cloud_topic = match &config.cloud_topic {
            Some(t) => {
                let Some(topic) = s.topics.get(t) else {
                    return Err(bad(
                        path,
                        format!("no topic {t}; the bag has {}", listing()),
                    ));
                };
                if topic.info.message_type != Some(RosMessageType::PointCloud2) {
                    return Err(message_error(
                        path,
                        t,
                        0,
                        MessageError::UnknownType {
                            found: topic.info.type_name.clone(),
                            expected: RosMessageType::PointCloud2.name(),
                        },
                    ));
                }
                t.clone()
            }
            None => match of_type(RosMessageType::PointCloud2).as_slice() {
                [one] => (*one).to_owned(),
                [] => {
                    return Err(bad(
                        path,
                        format!(
                            "no sensor_msgs/PointCloud2 topic; the bag has {}",
                            listing()
                        ),
                    ));
                }
                many => {
                    return Err(bad(
                        path,
                        format!("several cloud topics ({}): choose one", many.join(", ")),
                    ));
                }
            },
        };
        let odometry = match &config.odometry {
            OdometrySource::Topic(t) => {
                let Some(topic) = s.topics.get(t) else {
                    return Err(bad(
                        path,
                        format!("no topic {t}; the bag has {}", listing()),
                    ));
                };
                if topic.info.message_type != Some(RosMessageType::Odometry) {
                    return Err(message_error(
                        path,
                        t,
                        0,
                        MessageError::UnknownType {
                            found: topic.info.type_name.clone(),
                            expected: RosMessageType::Odometry.name(),
                        },
                    ));
                }
                ResolvedOdometry::Topic(t.clone())
            }
            OdometrySource::Tf { odom_frame } => ResolvedOdometry::Tf {
                odom_frame: odom_frame.clone(),
            },
            OdometrySource::None => ResolvedOdometry::None,
            OdometrySource::Auto => match of_type(RosMessageType::Odometry).as_slice() {
                [one] => ResolvedOdometry::Topic((*one).to_owned()),
                _ if !s.moving.moving_children("odom").is_empty() => ResolvedOdometry::Tf {
                    odom_frame: "odom".into(),
                },
                _ => ResolvedOdometry::None,
            },
        };
        let (stamps, cloud_frame) = s.clouds.remove(&cloud_topic).unwrap_or_default();
        let lidar_frame = config.lidar_frame.clone().unwrap_or(cloud_frame);
        let (base_frame, span) = match &odometry {
            ResolvedOdometry::Topic(t) => {
                let (first, last, _, child) = s.odometry.get(t).cloned().unwrap_or_default();
                (config.base_frame.clone().unwrap_or(child), (first, last))
            }
            ResolvedOdometry::Tf { odom_frame } => {
                let base = match &config.base_frame {
                    Some(b) => b.clone(),
                    None => match s.moving.moving_children(odom_frame).as_slice() {
                        [one] => (*one).to_owned(),
                        other => {
                            return Err(bad(
                                path,
                                format!(
                                    "/tf has {} moving children of {odom_frame:?} ({}): give the body frame",
                                    other.len(),
                                    other.join(", ")
                                ),
                            ));
                        }
                    },
                };
                // Moving and fixed edges together make the odometry chain.
                let mut tree = s.moving.clone();
                for (parent, child, pose) in s.fixed.fixed_edges() {
                    tree.set_fixed(parent, child, pose);
                }
                let span = tree.known_span(odom_frame, &base).ok_or_else(|| {
                    message_error(
                        path,
                        "/tf",
                        0,
                        MessageError::MissingTransform {
                            parent: odom_frame.clone(),
                            child: base.clone(),
                            stamp: stamps.first().copied().unwrap_or(0.0),
                        },
                    )
                })?;
                (base, span)
            }
            ResolvedOdometry::None => (
                config
                    .base_frame
                    .clone()
                    .unwrap_or_else(|| lidar_frame.clone()),
                (f64::NEG_INFINITY, f64::INFINITY),
            ),
        };
        let body_t_lidar = if base_frame == lidar_frame {
            Pose3::identity()
        } else {
            s.fixed
                .lookup(&base_frame, &lidar_frame, 0.0)
                .filter(|_| s.fixed.is_fixed_between(&base_frame, &lidar_frame))
                .ok_or_else(|| {
                    message_error(
                        path,
                        "/tf_static",
                        0,
                        MessageError::MissingTransform {
                            parent: base_frame.clone(),
                            child: lidar_frame.clone(),
                            stamp: stamps.first().copied().unwrap_or(0.0),
                        },
                    )
                })?
        };
        let clouds = stamps
            .iter()
            .filter(|&&t| t >= span.0 && t <= span.1)
            .count();
        // The first cloud decides the layout and the time unit.
        let mut decoder = PointCloud2Decoder::new(config.cloud);
        let layout = Self::first_layout(path, format, &cloud_topic, &mut decoder)?;
        let (first, last) = s
            .topics
            .values()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| {
                (a.min(t.first), b.max(t.last))
            });
        let summary = BagSummary {
            path: path.to_path_buf(),
            format,
            topics: s.topics.into_values().collect(),
            duration: if last >= first { last - first } else { 0.0 },
            cloud_topic,
            layout,
            odometry,
            base_frame,
            lidar_frame,
            body_t_lidar,
            clouds,
            clouds_outside_odometry: stamps.len() - clouds,
        };
        Ok(Self {
            summary,
            fixed: s.fixed,
            span,
            decoder,
        })
    }

    /// Decode the first cloud of `topic` (stopping there), deciding the time unit when it can.
    fn first_layout(
        path: &Path,
        format: BagFormat,
        topic: &str,
        decoder: &mut PointCloud2Decoder,
    ) -> Result<CloudLayout, AdapterError> {
        for msg in BagMessages::open(path, format)? {
            let msg = msg?;
            if msg.topic.name != topic {
                continue;
            }
            let at = |e| message_error(path, topic, 0, e);
            let Some(Decoded::Cloud(cloud)) = decode(&msg).map_err(at)? else {
                break;
            };
            return Ok(decoder.decode(&cloud).map_err(at)?.layout);
        }
        Err(bad(path, format!("topic {topic} has no message")))
    }

    /// What the bag holds and how it will be read.
    #[must_use]
    pub fn summary(&self) -> &BagSummary {
        &self.summary
    }

    /// The LiDAR mounting.
    #[must_use]
    pub fn body_t_lidar(&self) -> Pose3 {
        self.summary.body_t_lidar
    }

    /// Whether the samples carry odometry (else `odom_T_body` is the identity).
    #[must_use]
    pub fn has_odometry(&self) -> bool {
        self.summary.odometry != ResolvedOdometry::None
    }

    /// The per-point time unit, as given or decided on the first cloud (`None` for clouds
    /// without times, or whose first cloud's times are all equal).
    #[must_use]
    pub fn time_unit(&self) -> Option<TimeUnit> {
        self.decoder.time_unit()
    }

    /// Clouds the samples will deliver.
    #[must_use]
    pub fn len(&self) -> usize {
        self.summary.clouds
    }

    /// Whether no cloud will be delivered.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.summary.clouds == 0
    }

    /// The samples, read from the file again one message at a time.
    ///
    /// # Errors
    /// As [`Bag::open`], when the file cannot be opened again.
    pub fn samples(&self) -> Result<BagSamples, AdapterError> {
        let messages = BagMessages::open(&self.summary.path, self.summary.format)?;
        Ok(BagSamples::new(self.clone(), messages))
    }
}
