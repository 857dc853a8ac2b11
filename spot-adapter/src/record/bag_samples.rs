//! A bag's samples read one message at a time: clouds decoded when their message comes, held
//! until the odometry (and, with an IMU, the gyro reading) after their stamp has been read, then
//! given with `odom_T_body` interpolated at the stamp, the fixed `body_T_lidar` and the gyro's
//! orientation there. Moving transforms, odometry and gyro readings older than the oldest
//! waiting cloud are forgotten, so memory does not grow with the bag.

use std::collections::{HashMap, VecDeque};

use slam_core::{PointCloud, Pose3};

use crate::record::bag_decoding::{Decoded, cloud_header, decode, message_error, tf_kind};
use crate::record::bag_file::{BagMessages, RawMessage};
use crate::record::bag_summary::{BagSummary, ResolvedOdometry};
use crate::record::frame_tree::{FrameTree, PoseSeries};
use crate::record::imu::GyroIntegrator;
use crate::record::no_return::DroppedPoints;
use crate::record::point_cloud2::PointCloud2Decoder;
use crate::record::ros_messages::{ImuReading, RosMessageType};
use crate::record::{MessageError, RecordError};
use crate::robot::Sample;

/// A bag's samples, read one message at a time (from [`Bag::samples`](crate::record::Bag::samples)).
#[derive(Debug)]
pub struct BagSamples {
    messages: BagMessages,
    /// What the bag holds and how it is read.
    summary: BagSummary,
    /// The stamps between which odometry is known.
    span: (f64, f64),
    /// The decoder with the time unit decided on the first cloud.
    decoder: PointCloud2Decoder,
    /// The fixed transforms and the moving ones read so far.
    tree: FrameTree,
    odometry: PoseSeries,
    /// Clouds waiting for the odometry after their stamp.
    pending: VecDeque<(usize, f64, PointCloud)>,
    counters: HashMap<String, usize>,
    dropped: DroppedPoints,
    imu: Vec<ImuReading>,
    imu_before_last: Vec<ImuReading>,
    /// The IMU topic's gyro integrated, when the summary names one.
    gyro: Option<GyroIntegrator>,
    /// Every message has been read.
    exhausted: bool,
    left: usize,
    done: bool,
}

/// Whether the odometry at a stamp is known yet.
enum OdometryAt {
    Known(Pose3),
    NotYet,
}

impl BagSamples {
    /// The samples of a bag `summary` describes, read from `messages`, with its fixed
    /// transforms, the `span` of its odometry and its cloud `decoder`.
    pub(super) fn new(
        summary: BagSummary,
        fixed: FrameTree,
        span: (f64, f64),
        decoder: PointCloud2Decoder,
        messages: BagMessages,
    ) -> Self {
        let gyro = summary
            .imu
            .as_ref()
            .map(|imu| GyroIntegrator::new(&imu.frame, imu.body_r_imu));
        Self {
            gyro,
            messages,
            tree: fixed,
            left: summary.clouds,
            summary,
            span,
            decoder,
            odometry: PoseSeries::default(),
            pending: VecDeque::new(),
            counters: HashMap::new(),
            dropped: DroppedPoints::default(),
            imu: Vec::new(),
            imu_before_last: Vec::new(),
            exhausted: false,
            done: false,
        }
    }

    /// Whether the gyro orientation at `stamp` is known, or will never be: no IMU, a stamp
    /// outside its readings, a reading at or after it read, or the bag read to its end.
    fn gyro_ready(&self, stamp: f64) -> bool {
        let (Some(gyro), Some(imu)) = (&self.gyro, &self.summary.imu) else {
            return true;
        };
        self.exhausted
            || imu
                .span
                .is_none_or(|(first, last)| stamp < first || stamp > last)
            || gyro.last_stamp().is_some_and(|t| t >= stamp)
    }

    /// Points removed from the clouds delivered so far.
    #[must_use]
    pub fn dropped_points(&self) -> DroppedPoints {
        self.dropped
    }

    /// The IMU readings read between the previous sample and the last one delivered.
    #[must_use]
    pub fn imu_before_last_sample(&self) -> &[ImuReading] {
        &self.imu_before_last
    }

    fn odometry_at(&self, stamp: f64) -> Result<OdometryAt, MessageError> {
        let summary = &self.summary;
        match &summary.odometry {
            ResolvedOdometry::None => Ok(OdometryAt::Known(Pose3::identity())),
            ResolvedOdometry::Topic(_) => match self.odometry.last_stamp() {
                Some(last) if last >= stamp => {
                    self.odometry.at(stamp).map(OdometryAt::Known).ok_or(
                        MessageError::MissingTransform {
                            parent: "odometry".into(),
                            child: summary.base_frame.clone(),
                            stamp,
                        },
                    )
                }
                _ => Ok(OdometryAt::NotYet),
            },
            ResolvedOdometry::Tf { odom_frame } => {
                match self.tree.known_span(odom_frame, &summary.base_frame) {
                    Some((_, until)) if until >= stamp => self
                        .tree
                        .lookup(odom_frame, &summary.base_frame, stamp)
                        .map(OdometryAt::Known)
                        .ok_or_else(|| MessageError::MissingTransform {
                            parent: odom_frame.clone(),
                            child: summary.base_frame.clone(),
                            stamp,
                        }),
                    _ => Ok(OdometryAt::NotYet),
                }
            }
        }
    }

    /// Take in one message.
    fn take(&mut self, msg: &RawMessage) -> Result<(), RecordError> {
        let path = self.summary.path.clone();
        let name = &msg.topic.name;
        let counter = self.counters.entry(name.clone()).or_default();
        let index = *counter;
        *counter += 1;
        let at = |e| message_error(&path, name, index, e);
        let summary = &self.summary;
        if *name == summary.cloud_topic {
            let stamp = cloud_header(msg).map_err(at)?.stamp;
            let (from, until) = self.span;
            if stamp < from || stamp > until {
                return Ok(());
            }
            let Some(Decoded::Cloud(cloud)) = decode(msg).map_err(at)? else {
                return Ok(());
            };
            let decoded = self.decoder.decode(&cloud).map_err(at)?;
            self.dropped.add(decoded.dropped);
            self.pending.push_back((index, stamp, decoded.cloud));
            return Ok(());
        }
        let odometry_topic = matches!(&summary.odometry, ResolvedOdometry::Topic(t) if t == name);
        let imu_topic = summary.imu.as_ref().is_some_and(|imu| imu.topic == *name);
        let tf = tf_kind(name).is_some();
        if !(odometry_topic || tf || msg.topic.message_type == Some(RosMessageType::Imu)) {
            return Ok(());
        }
        match decode(msg).map_err(at)? {
            Some(Decoded::Odometry(o)) if odometry_topic => {
                self.odometry.push(o.header.stamp, o.pose);
            }
            Some(Decoded::Tf(transforms, false)) => {
                for t in transforms {
                    self.tree.push_moving(
                        &t.header.frame_id,
                        &t.child_frame_id,
                        t.header.stamp,
                        t.transform,
                    );
                }
            }
            Some(Decoded::Imu(reading)) => {
                if let Some(gyro) = self.gyro.as_mut().filter(|_| imu_topic) {
                    gyro.push(&reading);
                }
                self.imu.push(reading);
            }
            _ => {}
        }
        Ok(())
    }

    /// The first waiting cloud as a sample, with `odom_T_body` at its stamp.
    fn deliver(&mut self, odom_t_body: Pose3) -> Option<Sample> {
        let (_, stamp, cloud) = self.pending.pop_front()?;
        let gyro_orientation = self.gyro.as_mut().and_then(|g| g.sample_orientation(stamp));
        // The next cloud's stamp (or this one's) bounds what is still needed.
        let keep_from = self.pending.front().map_or(stamp, |p| p.1.min(stamp));
        self.odometry.prune_before(keep_from);
        self.tree.prune_before(keep_from);
        if let Some(gyro) = self.gyro.as_mut() {
            gyro.prune_before(keep_from);
        }
        self.imu_before_last = std::mem::take(&mut self.imu);
        Some(Sample {
            stamp,
            odom_t_body,
            body_t_lidar: self.summary.body_t_lidar,
            cloud,
            ground_truth: None,
            gyro_orientation,
        })
    }

    fn next_sample(&mut self) -> Result<Option<Sample>, RecordError> {
        loop {
            if let Some(&(index, stamp, _)) = self.pending.front() {
                let known = self.odometry_at(stamp).map_err(|e| {
                    message_error(&self.summary.path, &self.summary.cloud_topic, index, e)
                })?;
                match known {
                    OdometryAt::Known(odom_t_body) if self.gyro_ready(stamp) => {
                        return Ok(self.deliver(odom_t_body));
                    }
                    OdometryAt::NotYet if self.exhausted => {
                        let summary = &self.summary;
                        return Err(message_error(
                            &summary.path,
                            &summary.cloud_topic,
                            index,
                            MessageError::MissingTransform {
                                parent: "odometry".into(),
                                child: summary.base_frame.clone(),
                                stamp,
                            },
                        ));
                    }
                    _ => {}
                }
            }
            if self.exhausted {
                return Ok(None);
            }
            let Some(msg) = self.messages.next() else {
                self.exhausted = true;
                continue;
            };
            self.take(&msg?)?;
        }
    }
}

impl Iterator for BagSamples {
    type Item = Result<Sample, RecordError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done || self.left == 0 {
            return None;
        }
        match self.next_sample() {
            Ok(Some(sample)) => {
                self.left -= 1;
                Some(Ok(sample))
            }
            Ok(None) => {
                self.done = true;
                None
            }
            Err(e) => {
                self.done = true;
                Some(Err(e))
            }
        }
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.len();
        (n, Some(n))
    }
}

impl ExactSizeIterator for BagSamples {
    fn len(&self) -> usize {
        if self.done { 0 } else { self.left }
    }
}
