//! A ROS 1 or ROS 2 (MCAP) bag as a source of [`Sample`](crate::robot::Sample)s: the clouds of one
//! `sensor_msgs/PointCloud2` topic, each with `odom_T_body` at its stamp (from a
//! `nav_msgs/Odometry` topic, or from the `/tf` tree between an odometry frame and the body
//! frame), `body_T_lidar` from `/tf_static`, and the body's orientation integrated from a
//! `sensor_msgs/Imu` topic's gyro when there is one ([`ImuSource`]).
//!
//! An odometry is only taken by default when it reaches the clouds: an odometry topic whose child
//! frame is empty or not joined to the LiDAR frame by any transform (a simulator's ground truth
//! recorded beside real scans) is left out, and the summary's notes say so; asked for by name, a
//! body frame not joined to the LiDAR frame by fixed transforms is an error that lists the
//! frames the bag has ([`BagFrames`]).
//!
//! [`Bag::open`] reads the bag once, streaming, to find its topics, counts, duration, frames,
//! the first cloud's layout and the fixed transforms, and checks every message it will need, so
//! that a bad bag fails before any output is written. [`Bag::samples`] then reads it again, a
//! message at a time: memory holds the few clouds that wait for the odometry after them.

use std::collections::BTreeMap;
use std::path::Path;

use nalgebra::UnitQuaternion;
use slam_core::Pose3;

use crate::record::bag_decoding::{Decoded, cloud_header, decode, message_error, tf_kind};
use crate::record::bag_file::{BagFormat, BagMessages};
use crate::record::bag_frames::BagFrames;
use crate::record::bag_imu::{ImuChoice, ImuSource};
use crate::record::bag_samples::BagSamples;
use crate::record::bag_summary::{BagSummary, ResolvedOdometry};
use crate::record::bag_topics::{TopicSummary, check_topic_type, listing};
use crate::record::frame_tree::FrameTree;
use crate::record::imu::GyroIntegrator;
use crate::record::point_cloud2::{CloudLayout, PointCloud2Config, PointCloud2Decoder, TimeUnit};
use crate::record::ros_messages::RosMessageType;
use crate::record::{BodyFrameSource, MessageError, RecordError};

/// Where the odometry of a bag comes from. In a settings file (feature `serde`), tagged by
/// `kind`: `{ kind = "Topic", topic = "/odom" }`, `{ kind = "Tf", odom_frame = "odom" }`,
/// `{ kind = "Auto" }`, `{ kind = "None" }`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(
        from = "crate::record::source_forms::OdometrySourceForm",
        into = "crate::record::source_forms::OdometrySourceForm"
    )
)]
pub enum OdometrySource {
    /// The only `nav_msgs/Odometry` topic, else the `/tf` transform from `odom` to its moving
    /// child, else none. An odometry whose body frame (the topic's child frame, the moving
    /// child) is empty or joined to the clouds' frame by no transform is left out, and the
    /// summary's notes say why (unless a LiDAR frame is given: then a body frame not joined to
    /// it is an error).
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
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
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
    /// Where the samples' gyro orientation comes from.
    pub imu: ImuSource,
    /// How clouds are decoded.
    pub cloud: PointCloud2Config,
}

/// A bag opened and checked.
#[derive(Clone, Debug)]
pub struct Bag {
    summary: BagSummary,
    /// The fixed transforms.
    fixed: FrameTree,
    /// The stamps between which odometry is known.
    span: (f64, f64),
    /// The decoder with the time unit decided on the first cloud.
    decoder: PointCloud2Decoder,
}

/// The topics of type `kind`.
fn of_type(s: &Survey, kind: RosMessageType) -> Vec<&str> {
    s.topics
        .values()
        .filter(|x| x.info.message_type == Some(kind))
        .map(|x| x.info.name.as_str())
        .collect()
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
    /// Per IMU topic: its readings integrated with an identity mounting (to count and span
    /// them; only the last reading is kept).
    imu: BTreeMap<String, GyroIntegrator>,
}

impl Survey {
    /// The frames the bag names.
    fn frames(&self) -> BagFrames {
        let has = |kind| self.topics.keys().any(|t| tf_kind(t) == Some(kind));
        let pairs = |edges: Vec<(&str, &str)>| {
            let mut out: Vec<(String, String)> = edges
                .into_iter()
                .map(|(p, c)| (p.to_owned(), c.to_owned()))
                .collect();
            out.sort();
            out
        };
        BagFrames {
            has_tf: has(false),
            tf: pairs(self.moving.moving_edges().collect()),
            has_tf_static: has(true),
            tf_static: pairs(self.fixed.fixed_edges().map(|(p, c, _)| (p, c)).collect()),
            odometry: self
                .odometry
                .iter()
                .map(|(topic, (_, _, frame, child))| (topic.clone(), frame.clone(), child.clone()))
                .collect(),
            imu: self
                .imu
                .iter()
                .map(|(topic, gyro)| (topic.clone(), gyro.frame().to_owned()))
                .collect(),
        }
    }
}

/// The odometry decided on, and a note for each one left out.
struct OdometryChoice {
    odometry: ResolvedOdometry,
    notes: Vec<String>,
}

impl Bag {
    /// Open the bag at `path` (`.mcap` or `.bag`) and check it in one streaming pass.
    ///
    /// # Errors
    /// [`RecordError::Io`], [`RecordError::Mcap`], [`RecordError::McapLength`],
    /// [`RecordError::Ros1Bag`], [`RecordError::NotABag`], [`RecordError::NotRos1Bag`],
    /// [`RecordError::Ros1Header`], [`RecordError::Unindexed`] or
    /// [`RecordError::UnknownConnection`] for a file that cannot be read (truncated, not a
    /// bag); [`RecordError::Message`] for a message that cannot be decoded, a cloud topic of
    /// another type, a missing transform; [`RecordError::NoTopic`],
    /// [`RecordError::NoCloudTopic`], [`RecordError::EmptyTopic`],
    /// [`RecordError::SeveralCloudTopics`] or [`RecordError::AmbiguousBodyFrame`] when the
    /// topics asked for are absent or the choice is ambiguous.
    pub fn open(path: impl AsRef<Path>, config: &BagConfig) -> Result<Self, RecordError> {
        let path = path.as_ref();
        let format = BagFormat::from_path(path).ok_or_else(|| RecordError::NotABag {
            path: path.to_path_buf(),
        })?;
        let survey = Self::survey(path, format)?;
        Self::resolve(path, format, survey, config)
    }

    fn survey(path: &Path, format: BagFormat) -> Result<Survey, RecordError> {
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
                Some(Decoded::Imu(reading)) => {
                    let gyro = s.imu.entry(name.clone()).or_insert_with(|| {
                        GyroIntegrator::new(&reading.frame_id, UnitQuaternion::identity())
                    });
                    gyro.push(&reading);
                    if let Some(last) = gyro.last_stamp() {
                        gyro.prune_before(last);
                    }
                }
                _ => {}
            }
        }
        Ok(s)
    }

    fn resolve(
        path: &Path,
        format: BagFormat,
        mut s: Survey,
        config: &BagConfig,
    ) -> Result<Self, RecordError> {
        let cloud_topic = Self::cloud_topic(path, &s, config)?;
        let (stamps, cloud_frame) = s.clouds.remove(&cloud_topic).unwrap_or_default();
        let lidar_frame = config.lidar_frame.clone().unwrap_or(cloud_frame);
        // Moving and fixed edges together: what joins two frames at all.
        let mut tree = s.moving.clone();
        for (parent, child, pose) in s.fixed.fixed_edges() {
            tree.set_fixed(parent, child, pose);
        }
        let frames = s.frames();
        let choice = Self::odometry(path, &s, config, &tree, &lidar_frame)?;
        let odometry = choice.odometry;
        let (base_frame, span) =
            Self::body_frame(path, &s, config, &tree, &odometry, &stamps, &lidar_frame)?;
        let body_t_lidar =
            Self::mounting(&s.fixed, &base_frame, &lidar_frame).ok_or_else(|| {
                RecordError::UnlinkedLidar {
                    path: path.to_path_buf(),
                    body_from: match (&config.base_frame, &odometry) {
                        (Some(_), _) => BodyFrameSource::Given,
                        (None, ResolvedOdometry::Topic(t)) => {
                            BodyFrameSource::OdometryTopic(t.clone())
                        }
                        (None, ResolvedOdometry::Tf { odom_frame }) => {
                            BodyFrameSource::TfChild(odom_frame.clone())
                        }
                        (None, ResolvedOdometry::None) => BodyFrameSource::Lidar,
                    },
                    body_frame: base_frame.clone(),
                    lidar_frame: lidar_frame.clone(),
                    frames: Box::new(frames.clone()),
                }
            })?;
        let delivered: Vec<f64> = stamps
            .iter()
            .copied()
            .filter(|&t| t >= span.0 && t <= span.1)
            .collect();
        let (imu, imu_note) = ImuChoice {
            path,
            topics: &s.topics,
            gyros: &s.imu,
            fixed: &s.fixed,
            base_frame: &base_frame,
            clouds: &delivered,
            frames: &frames,
        }
        .resolve(&config.imu)?;
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
            clouds: delivered.len(),
            clouds_outside_odometry: stamps.len() - delivered.len(),
            imu,
            notes: choice.notes.into_iter().chain(imu_note).collect(),
        };
        Ok(Self {
            summary,
            fixed: s.fixed,
            span,
            decoder,
        })
    }

    /// The body frame (the one given, else the odometry's child, else the LiDAR frame) and the
    /// stamps between which its odometry is known.
    fn body_frame(
        path: &Path,
        s: &Survey,
        config: &BagConfig,
        tree: &FrameTree,
        odometry: &ResolvedOdometry,
        stamps: &[f64],
        lidar_frame: &str,
    ) -> Result<(String, (f64, f64)), RecordError> {
        Ok(match odometry {
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
                            return Err(RecordError::AmbiguousBodyFrame {
                                path: path.to_path_buf(),
                                odom_frame: odom_frame.clone(),
                                children: other.iter().map(|c| (*c).to_owned()).collect(),
                            });
                        }
                    },
                };
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
                    .unwrap_or_else(|| lidar_frame.to_owned()),
                (f64::NEG_INFINITY, f64::INFINITY),
            ),
        })
    }

    /// `body_T_lidar` from the fixed transforms; `None` when they do not join the two frames.
    fn mounting(fixed: &FrameTree, base_frame: &str, lidar_frame: &str) -> Option<Pose3> {
        if base_frame == lidar_frame {
            return Some(Pose3::identity());
        }
        fixed
            .lookup(base_frame, lidar_frame, 0.0)
            .filter(|_| fixed.is_fixed_between(base_frame, lidar_frame))
    }

    /// The cloud topic: the one asked for, else the only one.
    fn cloud_topic(path: &Path, s: &Survey, config: &BagConfig) -> Result<String, RecordError> {
        if let Some(t) = &config.cloud_topic {
            check_topic_type(path, &s.topics, t, RosMessageType::PointCloud2)?;
            return Ok(t.clone());
        }
        match of_type(s, RosMessageType::PointCloud2).as_slice() {
            [one] => Ok((*one).to_owned()),
            [] => Err(RecordError::NoCloudTopic {
                path: path.to_path_buf(),
                available: listing(&s.topics),
            }),
            many => Err(RecordError::SeveralCloudTopics {
                path: path.to_path_buf(),
                topics: many.iter().map(|t| (*t).to_owned()).collect(),
            }),
        }
    }

    /// The odometry: the one asked for, else (`Auto`) the only odometry topic when its child
    /// frame reaches the LiDAR frame in `tree`, else `/tf` from `odom` unless its only moving
    /// child does not reach it, else none; what is left out gets a note.
    fn odometry(
        path: &Path,
        s: &Survey,
        config: &BagConfig,
        tree: &FrameTree,
        lidar_frame: &str,
    ) -> Result<OdometryChoice, RecordError> {
        let chosen = |odometry| OdometryChoice {
            odometry,
            notes: Vec::new(),
        };
        match &config.odometry {
            OdometrySource::Topic(t) => {
                check_topic_type(path, &s.topics, t, RosMessageType::Odometry)?;
                return Ok(chosen(ResolvedOdometry::Topic(t.clone())));
            }
            OdometrySource::Tf { odom_frame } => {
                return Ok(chosen(ResolvedOdometry::Tf {
                    odom_frame: odom_frame.clone(),
                }));
            }
            OdometrySource::None => return Ok(chosen(ResolvedOdometry::None)),
            OdometrySource::Auto => {}
        }
        // Whether a body frame reaches the clouds' through any transform. A LiDAR frame given is
        // the user's word: the odometry is then taken as found, and a body frame that does not
        // reach it is an error, not a reason to drop the odometry.
        let reaches = |frame: &str| {
            config.lidar_frame.is_some()
                || (!frame.is_empty() && tree.is_joined(frame, lidar_frame))
        };
        let unlinked = |what: String, frame: &str| {
            format!(
                "{what} ignored: child frame {frame:?} is not linked to the cloud frame {lidar_frame:?}"
            )
        };
        // What was left out, and what to pass to use it.
        let mut left_out = Vec::new();
        match of_type(s, RosMessageType::Odometry).as_slice() {
            [one] => {
                let child = s.odometry.get(*one).map_or("", |o| o.3.as_str());
                if reaches(child) {
                    return Ok(chosen(ResolvedOdometry::Topic((*one).to_owned())));
                }
                left_out.push((
                    unlinked(format!("odometry topic {one}"), child),
                    format!("--odom-topic {one} --base-frame F to use it"),
                ));
            }
            [] => {}
            many => left_out.push((
                format!(
                    "several nav_msgs/Odometry topics ({}), none taken",
                    many.join(", ")
                ),
                "--odom-topic T to use one".to_owned(),
            )),
        }
        let odometry = match s.moving.moving_children("odom").as_slice() {
            [] => ResolvedOdometry::None,
            [one] if !reaches(one) => {
                left_out.push((
                    unlinked("/tf from \"odom\"".to_owned(), one),
                    "--odom-frame odom --base-frame F to use it".to_owned(),
                ));
                ResolvedOdometry::None
            }
            _ => ResolvedOdometry::Tf {
                odom_frame: "odom".into(),
            },
        };
        let instead = match &odometry {
            ResolvedOdometry::None => "running LiDAR-only",
            _ => "using /tf from \"odom\" instead",
        };
        let notes = left_out
            .into_iter()
            .map(|(what, hint)| format!("{what}; {instead} (pass {hint})"))
            .collect();
        Ok(OdometryChoice { odometry, notes })
    }

    /// Decode the first cloud of `topic` (stopping there), deciding the time unit when it can.
    fn first_layout(
        path: &Path,
        format: BagFormat,
        topic: &str,
        decoder: &mut PointCloud2Decoder,
    ) -> Result<CloudLayout, RecordError> {
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
        Err(RecordError::EmptyTopic {
            path: path.to_path_buf(),
            topic: topic.to_owned(),
        })
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
    pub fn samples(&self) -> Result<BagSamples, RecordError> {
        let messages = BagMessages::open(&self.summary.path, self.summary.format)?;
        Ok(BagSamples::new(
            self.summary.clone(),
            self.fixed.clone(),
            self.span,
            self.decoder.clone(),
            messages,
        ))
    }
}
