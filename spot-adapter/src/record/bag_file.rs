//! The messages of a bag file in file order, one at a time, whichever format it is in: ROS 2
//! MCAP ([`McapMessages`], over the `mcap` crate's streaming reader: memory is that of the
//! largest chunk) or ROS 1 (the `rosbag` crate over a memory map, one chunk decompressed at a time).
//! Payloads come out undecoded, with their topic, type and serialisation.

use std::collections::{HashMap, VecDeque};
use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use rosbag::{ChunkRecord, IndexRecord, MessageRecord, RosBag};

use crate::record::RecordError;
use crate::record::mcap_file::McapMessages;
use crate::record::ros_messages::RosMessageType;
use crate::record::wire::Wire;

/// The largest MCAP record or chunk read (1 GiB): a corrupt length is refused rather than
/// allocated. A 128-beam cloud is about 10 MB; recorders' chunks are 1 to 100 MB.
const MAX_RECORD_BYTES: usize = 1 << 30;

/// The bag formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BagFormat {
    /// ROS 2 (or any) MCAP file.
    Mcap,
    /// ROS 1 bag (format 2.0).
    Ros1,
}

impl BagFormat {
    /// The format a file's extension names (`.mcap`, `.bag`), `None` for another.
    #[must_use]
    pub fn from_path(path: &Path) -> Option<Self> {
        match path.extension()?.to_str()? {
            "mcap" => Some(Self::Mcap),
            "bag" => Some(Self::Ros1),
            _ => None,
        }
    }
}

/// A topic as the bag declares it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TopicInfo {
    /// Its name.
    pub name: String,
    /// Its message type as the bag spells it.
    pub type_name: String,
    /// The serialisation of its payloads.
    pub wire: Wire,
    /// The type, when it is one this reader decodes.
    pub message_type: Option<RosMessageType>,
}

/// One undecoded message.
#[derive(Clone, Debug)]
pub(crate) struct RawMessage {
    pub topic: Arc<TopicInfo>,
    /// When it was recorded (nanoseconds).
    pub log_time: u64,
    pub data: Vec<u8>,
}

/// The messages of a bag in file order.
pub(crate) enum BagMessages {
    Mcap {
        path: PathBuf,
        reader: Box<McapMessages>,
        topics: HashMap<u16, Arc<TopicInfo>>,
    },
    Ros1(Box<Ros1Messages>),
}

impl std::fmt::Debug for BagMessages {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Mcap { path, .. } => write!(f, "BagMessages::Mcap({})", path.display()),
            Self::Ros1(r) => write!(f, "BagMessages::Ros1({})", r.path.display()),
        }
    }
}

impl BagMessages {
    /// The messages of the bag at `path`, in `format`.
    pub(crate) fn open(path: &Path, format: BagFormat) -> Result<Self, RecordError> {
        match format {
            BagFormat::Mcap => Ok(Self::Mcap {
                path: path.to_path_buf(),
                reader: Box::new(McapMessages::open(path, MAX_RECORD_BYTES)?),
                topics: HashMap::new(),
            }),
            BagFormat::Ros1 => Ok(Self::Ros1(Box::new(Ros1Messages::open(path)?))),
        }
    }
}

impl Iterator for BagMessages {
    type Item = Result<RawMessage, RecordError>;

    fn next(&mut self) -> Option<Self::Item> {
        match self {
            Self::Mcap { reader, topics, .. } => {
                let message = match reader.next()? {
                    Ok(m) => m,
                    Err(e) => return Some(Err(e)),
                };
                let channel = &message.channel;
                let topic = topics.entry(channel.id).or_insert_with(|| {
                    let type_name = channel
                        .schema
                        .as_ref()
                        .map_or_else(String::new, |s| s.name.clone());
                    // Only ROS payloads are decoded; a protobuf or JSON channel keeps its type
                    // name (with the encoding) for the listing but is not read.
                    let wire = match channel.message_encoding.as_str() {
                        "ros1" => Some(Wire::Ros1),
                        "cdr" => Some(Wire::Cdr),
                        _ => None,
                    };
                    Arc::new(TopicInfo {
                        name: channel.topic.clone(),
                        message_type: wire.and_then(|_| RosMessageType::from_name(&type_name)),
                        type_name: match wire {
                            Some(_) => type_name,
                            None => format!("{type_name} ({})", channel.message_encoding),
                        },
                        wire: wire.unwrap_or(Wire::Cdr),
                    })
                });
                Some(Ok(RawMessage {
                    topic: Arc::clone(topic),
                    log_time: message.log_time,
                    data: message.data,
                }))
            }
            Self::Ros1(r) => r.next(),
        }
    }
}

/// Reads the `index_pos` field of a ROS 1 bag's header record and where that record ends, so
/// that a truncated or unindexed bag is refused before the `rosbag` crate slices its memory map
/// between the two.
fn ros1_index_pos(path: &Path) -> Result<(u64, u64), RecordError> {
    let bad = |problem: &'static str| RecordError::Ros1Header {
        path: path.to_path_buf(),
        problem,
    };
    let mut head = Vec::new();
    File::open(path)
        .map_err(|e| RecordError::io(path, e))?
        .take(4096)
        .read_to_end(&mut head)
        .map_err(|e| RecordError::io(path, e))?;
    let rest = head
        .strip_prefix(b"#ROSBAG V2.0\n")
        .ok_or_else(|| RecordError::NotRos1Bag {
            path: path.to_path_buf(),
        })?;
    let u32_at = |b: &[u8], at: usize| -> Option<usize> {
        Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?) as usize)
    };
    let header_len = u32_at(rest, 0).ok_or_else(|| bad("truncated header"))?;
    let data_len = u32_at(rest, 4 + header_len).ok_or_else(|| bad("truncated header"))?;
    let header_end = (13 + 4 + header_len + 4 + data_len) as u64;
    let mut fields = rest
        .get(4..4 + header_len)
        .ok_or_else(|| bad("truncated header"))?;
    while let Some(len) = u32_at(fields, 0) {
        let field = fields
            .get(4..4 + len)
            .ok_or_else(|| bad("malformed header field"))?;
        if let Some(v) = field.strip_prefix(b"index_pos=") {
            let v: [u8; 8] = v.try_into().map_err(|_| bad("malformed index_pos"))?;
            return Ok((u64::from_le_bytes(v), header_end));
        }
        fields = &fields[4 + len..];
    }
    Err(bad("header has no index_pos"))
}

/// A ROS 1 bag's messages, chunk by chunk through its index.
pub(crate) struct Ros1Messages {
    path: PathBuf,
    bag: RosBag,
    topics: HashMap<u32, Arc<TopicInfo>>,
    chunks: VecDeque<u64>,
    pending: VecDeque<RawMessage>,
}

impl Ros1Messages {
    fn open(path: &Path) -> Result<Self, RecordError> {
        let len = std::fs::metadata(path)
            .map_err(|e| RecordError::io(path, e))?
            .len();
        let (index_pos, header_end) = ros1_index_pos(path)?;
        if index_pos < header_end || index_pos > len {
            return Err(RecordError::Unindexed {
                path: path.to_path_buf(),
                index_pos,
                len,
            });
        }
        let bag = RosBag::new(path).map_err(|e| RecordError::io(path, e))?;
        let ros1 = |source| RecordError::Ros1Bag {
            path: path.to_path_buf(),
            source,
        };
        let mut topics = HashMap::new();
        let mut chunks = Vec::new();
        for record in bag.index_records() {
            match record.map_err(ros1)? {
                IndexRecord::Connection(c) => {
                    topics.insert(
                        c.id,
                        Arc::new(TopicInfo {
                            name: c.topic.to_owned(),
                            type_name: c.tp.to_owned(),
                            wire: Wire::Ros1,
                            message_type: RosMessageType::from_name(c.tp),
                        }),
                    );
                }
                IndexRecord::ChunkInfo(info) => chunks.push(info.chunk_pos),
                IndexRecord::IndexData(_) => {}
            }
        }
        chunks.sort_unstable();
        Ok(Self {
            path: path.to_path_buf(),
            bag,
            topics,
            chunks: chunks.into(),
            pending: VecDeque::new(),
        })
    }

    /// Decompress the next chunk into `pending`.
    fn load_chunk(&mut self, pos: u64) -> Result<(), RecordError> {
        let ros1 = |source| RecordError::Ros1Bag {
            path: self.path.clone(),
            source,
        };
        let mut records = self.bag.chunk_records();
        records.seek(pos).map_err(ros1)?;
        let Some(record) = records.next() else {
            return Err(ros1(rosbag::Error::OutOfBounds));
        };
        let ChunkRecord::Chunk(chunk) = record.map_err(ros1)? else {
            return Err(ros1(rosbag::Error::InvalidRecord));
        };
        for message in chunk.messages() {
            match message.map_err(ros1)? {
                MessageRecord::MessageData(m) => {
                    let topic = self.topics.get(&m.conn_id).ok_or_else(|| {
                        RecordError::UnknownConnection {
                            path: self.path.clone(),
                            connection: m.conn_id,
                        }
                    })?;
                    self.pending.push_back(RawMessage {
                        topic: Arc::clone(topic),
                        log_time: m.time,
                        data: m.data.to_vec(),
                    });
                }
                MessageRecord::Connection(_) => {}
            }
        }
        Ok(())
    }
}

impl Iterator for Ros1Messages {
    type Item = Result<RawMessage, RecordError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(m) = self.pending.pop_front() {
                return Some(Ok(m));
            }
            let pos = self.chunks.pop_front()?;
            if let Err(e) = self.load_chunk(pos) {
                self.chunks.clear();
                return Some(Err(e));
            }
        }
    }
}
