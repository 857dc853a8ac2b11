//! A bag's raw messages decoded into what its readers need (clouds, odometry, transforms, IMU
//! readings), and the error that names the message. Used by the first pass ([`Bag::open`]) and
//! by the samples ([`BagSamples`]).
//!
//! [`Bag::open`]: crate::record::Bag::open
//! [`BagSamples`]: crate::record::BagSamples

use std::path::Path;

use crate::record::bag_file::RawMessage;
use crate::record::ros_messages::{
    Header, ImuReading, Odometry, PointCloud2, RosMessageType, TransformStamped, decode_tf_message,
};
use crate::record::wire::WireReader;
use crate::record::{MessageError, RecordError};

/// The error for message `index` of `topic`.
pub(super) fn message_error(
    path: &Path,
    topic: &str,
    index: usize,
    source: MessageError,
) -> RecordError {
    RecordError::Message {
        path: path.to_path_buf(),
        topic: topic.to_owned(),
        index,
        source: Box::new(source),
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
    Tf(Vec<TransformStamped>, bool),
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
