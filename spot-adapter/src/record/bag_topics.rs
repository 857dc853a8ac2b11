//! A bag's topics as the first pass counts them ([`TopicSummary`]), and the check of a topic
//! asked for by name.

use std::collections::BTreeMap;
use std::path::Path;

use crate::record::bag_decoding::message_error;
use crate::record::bag_file::TopicInfo;
use crate::record::ros_messages::RosMessageType;
use crate::record::{MessageError, RecordError};

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

/// `(name, type)` of every topic.
pub(super) fn listing(topics: &BTreeMap<String, TopicSummary>) -> Vec<(String, String)> {
    topics
        .values()
        .map(|t| (t.info.name.clone(), t.info.type_name.clone()))
        .collect()
}

/// Check that the bag has topic `name` and that it carries `kind`.
pub(super) fn check_topic_type(
    path: &Path,
    topics: &BTreeMap<String, TopicSummary>,
    name: &str,
    kind: RosMessageType,
) -> Result<(), RecordError> {
    let Some(topic) = topics.get(name) else {
        return Err(RecordError::NoTopic {
            path: path.to_path_buf(),
            topic: name.to_owned(),
            available: listing(topics),
        });
    };
    if topic.info.message_type != Some(kind) {
        return Err(message_error(
            path,
            name,
            0,
            MessageError::UnknownType {
                found: topic.info.type_name.clone(),
                expected: kind.name(),
            },
        ));
    }
    Ok(())
}
