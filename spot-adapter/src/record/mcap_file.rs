//! The messages of an MCAP file in file order, streamed by the `mcap` crate's sans-io
//! [`LinearReader`] (which checks record lengths against a limit and decompresses chunks) with
//! only the records messages need parsed: schemas, channels and messages.
//!
//! The crate's record parser reserves the length a string claims before reading it, so a 30-byte
//! channel record claiming a 4 GiB topic name reserved 4 GiB. Every string of a schema or channel
//! record is therefore checked against the bytes left in its record before the record is parsed,
//! and the records a reader of messages does not use (header, attachments, metadata, indexes,
//! statistics, the summary after the data end) are passed over unparsed.
//!
//! The crate also takes a record inside an uncompressed chunk at the length it claims, past the
//! chunk's end (an integer overflow: a panic in debug builds, a misread file in release), so the
//! records of every uncompressed chunk are checked to lie inside it ([`check_chunks`]) before the
//! file is read.

use std::fs::File;
use std::io::{BufReader, ErrorKind, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use mcap::read::ChannelAccumulator;
use mcap::records::{Record, op};
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};

use crate::record::RecordError;

/// One message with its channel.
pub(crate) struct McapMessage {
    pub channel: Arc<mcap::Channel<'static>>,
    /// When it was recorded (nanoseconds).
    pub log_time: u64,
    pub data: Vec<u8>,
}

/// The messages of an MCAP file, read one record at a time (memory: the largest record or
/// decompressed chunk, at most the record length limit).
pub(crate) struct McapMessages {
    path: PathBuf,
    file: BufReader<File>,
    reader: LinearReader,
    channels: ChannelAccumulator<'static>,
    /// Past the data end record: the rest (the summary) repeats schemas and channels.
    past_data_end: bool,
    done: bool,
}

/// The length of the string at `at` in `record` when the record holds it, and where it ends.
fn string_end(record: &[u8], at: usize) -> Result<usize, (u64, u64)> {
    let left = record.len().saturating_sub(at) as u64;
    let Some(len) = record.get(at..at + 4) else {
        return Err((4, left));
    };
    let len = u64::from(u32::from_le_bytes([len[0], len[1], len[2], len[3]]));
    if len > left - 4 {
        return Err((len, left - 4));
    }
    Ok(at + 4 + len as usize)
}

/// Check that every string of a schema or channel record lies inside it; `Err((claimed,
/// left))` for the first that does not.
fn check_strings(opcode: u8, record: &[u8]) -> Result<(), (u64, u64)> {
    match opcode {
        // id u16, name, encoding, then the schema's bytes (length-checked by the crate).
        op::SCHEMA => {
            let end = string_end(record, 2)?;
            string_end(record, end)?;
        }
        // id u16, schema id u16, topic, message encoding, then a map of strings given by its
        // length in bytes.
        op::CHANNEL => {
            let end = string_end(record, 4)?;
            let end = string_end(record, end)?;
            let Some(len) = record.get(end..end + 4) else {
                return Err((4, record.len().saturating_sub(end) as u64));
            };
            let map_len = u32::from_le_bytes([len[0], len[1], len[2], len[3]]) as usize;
            let map_end = end + 4 + map_len;
            if map_end > record.len() {
                return Err((map_len as u64, (record.len() - end - 4) as u64));
            }
            let mut at = end + 4;
            while at < map_end {
                at = string_end(&record[..map_end], at)?;
                at = string_end(&record[..map_end], at)?;
            }
        }
        _ => {}
    }
    Ok(())
}

/// Most bytes asked of the file at once: the reader's buffer grows with the data read, not with
/// the length a record claims.
const READ_STEP: usize = 1 << 20;
/// Most bytes a chunk may decompress to per byte of the file (point clouds compress 2 to 5
/// times; lz4 cannot exceed 255): a chunk claiming more is refused before its buffer is made.
const MAX_EXPANSION: u64 = 1024;

/// Bytes of a record's opcode and length.
const RECORD_HEAD: u64 = 9;
/// Bytes of a chunk record before its compression string: start and end times, uncompressed
/// size, CRC, the string's length.
const CHUNK_HEAD: u64 = 8 + 8 + 8 + 4 + 4;

fn read_array<const N: usize>(file: &mut impl Read) -> Option<[u8; N]> {
    let mut out = [0u8; N];
    file.read_exact(&mut out).ok()?;
    Some(out)
}

/// Check that the records of every uncompressed chunk (up to the footer) lie inside their
/// chunk, reading only record heads. Anything else wrong (a truncated file, a chunk longer than
/// its record) is left for the reader to report, so the walk just stops there.
fn check_chunks(file: &mut (impl Read + Seek)) -> Result<(), (u64, u64)> {
    let mut at = 8; // the magic
    loop {
        if file.seek(SeekFrom::Start(at)).is_err() {
            return Ok(());
        }
        let Some(head) = read_array::<9>(file) else {
            return Ok(());
        };
        let len = u64::from_le_bytes([
            head[1], head[2], head[3], head[4], head[5], head[6], head[7], head[8],
        ]);
        let body = at + RECORD_HEAD;
        let Some(next) = body.checked_add(len) else {
            return Ok(());
        };
        match head[0] {
            op::FOOTER => return Ok(()),
            op::CHUNK => {
                let Some(fixed) = read_array::<32>(file) else {
                    return Ok(());
                };
                let compression = u64::from(u32::from_le_bytes([
                    fixed[28], fixed[29], fixed[30], fixed[31],
                ]));
                let header = CHUNK_HEAD + compression + 8;
                if compression == 0 && header <= len {
                    let Some(size) = read_array::<8>(file) else {
                        return Ok(());
                    };
                    let size = u64::from_le_bytes(size);
                    if size <= len - header {
                        check_chunk_records(file, body + header, size)?;
                    }
                }
            }
            _ => {}
        }
        at = next;
    }
}

/// The records of the uncompressed chunk data of `size` bytes at `start`.
fn check_chunk_records(
    file: &mut (impl Read + Seek),
    start: u64,
    size: u64,
) -> Result<(), (u64, u64)> {
    let mut done = 0;
    while done < size {
        let left = size - done;
        if left < RECORD_HEAD {
            return Err((RECORD_HEAD, left));
        }
        if file.seek(SeekFrom::Start(start + done)).is_err() {
            return Ok(());
        }
        let Some(head) = read_array::<9>(file) else {
            return Ok(());
        };
        let len = u64::from_le_bytes([
            head[1], head[2], head[3], head[4], head[5], head[6], head[7], head[8],
        ]);
        if len > left - RECORD_HEAD {
            return Err((len, left - RECORD_HEAD));
        }
        done += RECORD_HEAD + len;
    }
    Ok(())
}

impl McapMessages {
    /// The messages of the MCAP file at `path`, no record or decompressed chunk longer than
    /// `record_length_limit` bytes or [`MAX_EXPANSION`] times the file's length.
    pub(crate) fn open(path: &Path, record_length_limit: usize) -> Result<Self, RecordError> {
        let mut file = File::open(path).map_err(|e| RecordError::io(path, e))?;
        let file_len = file.metadata().map_err(|e| RecordError::io(path, e))?.len();
        let limit = usize::try_from(file_len.saturating_mul(MAX_EXPANSION))
            .map_or(record_length_limit, |l| l.min(record_length_limit));
        let mut heads = BufReader::with_capacity(1 << 12, &mut file);
        if let Err((claimed, left)) = check_chunks(&mut heads) {
            return Err(RecordError::McapLength {
                path: path.to_path_buf(),
                what: "uncompressed chunk: a record",
                claimed,
                left,
            });
        }
        drop(heads);
        file.rewind().map_err(|e| RecordError::io(path, e))?;
        Ok(Self {
            path: path.to_path_buf(),
            file: BufReader::with_capacity(1 << 20, file),
            reader: LinearReader::new_with_options(
                LinearReaderOptions::default()
                    .with_record_length_limit(limit)
                    .with_emit_chunks(false),
            ),
            channels: ChannelAccumulator::default(),
            past_data_end: false,
            done: false,
        })
    }

    fn next_message(&mut self) -> Option<Result<McapMessage, RecordError>> {
        let mcap = |path: &Path, source| RecordError::Mcap {
            path: path.to_path_buf(),
            source: Box::new(source),
        };
        loop {
            let event = match self.reader.next_event()? {
                Ok(event) => event,
                Err(e) => return Some(Err(mcap(&self.path, e))),
            };
            let (opcode, data) = match event {
                LinearReadEvent::ReadRequest(need) => {
                    let read = loop {
                        match self.file.read(self.reader.insert(need.min(READ_STEP))) {
                            Ok(n) => break n,
                            Err(e) if e.kind() == ErrorKind::Interrupted => {}
                            Err(e) => return Some(Err(RecordError::io(&self.path, e))),
                        }
                    };
                    self.reader.notify_read(read);
                    continue;
                }
                LinearReadEvent::Record { opcode, data } => (opcode, data),
            };
            if opcode == op::DATA_END {
                self.past_data_end = true;
            }
            if self.past_data_end || !matches!(opcode, op::SCHEMA | op::CHANNEL | op::MESSAGE) {
                continue;
            }
            if let Err((claimed, left)) = check_strings(opcode, data) {
                return Some(Err(RecordError::McapLength {
                    path: self.path.clone(),
                    what: if opcode == op::SCHEMA {
                        "schema record: a string"
                    } else {
                        "channel record: a string"
                    },
                    claimed,
                    left,
                }));
            }
            let record = match mcap::parse_record(opcode, data) {
                Ok(record) => record,
                Err(e) => return Some(Err(mcap(&self.path, e))),
            };
            let added = match record {
                Record::Schema { header, data } => {
                    self.channels.add_schema_from_slice(header, &data)
                }
                Record::Channel(channel) => self.channels.add_channel(channel),
                Record::Message { header, data } => {
                    let Some(channel) = self.channels.get(header.channel_id) else {
                        return Some(Err(mcap(
                            &self.path,
                            mcap::McapError::UnknownChannel(header.sequence, header.channel_id),
                        )));
                    };
                    return Some(Ok(McapMessage {
                        channel,
                        log_time: header.log_time,
                        data: data.into_owned(),
                    }));
                }
                _ => Ok(()),
            };
            if let Err(e) = added {
                return Some(Err(mcap(&self.path, e)));
            }
        }
    }
}

impl Iterator for McapMessages {
    type Item = Result<McapMessage, RecordError>;

    /// The next message; nothing after the first error.
    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let next = self.next_message();
        if !matches!(next, Some(Ok(_))) {
            self.done = true;
        }
        next
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn string(s: &[u8]) -> Vec<u8> {
        let mut out = (s.len() as u32).to_le_bytes().to_vec();
        out.extend_from_slice(s);
        out
    }

    /// An uncompressed chunk record holding `records`.
    fn chunk(records: &[u8]) -> Vec<u8> {
        let mut body = vec![0u8; 28];
        body.extend_from_slice(&0u32.to_le_bytes()); // no compression
        body.extend_from_slice(&(records.len() as u64).to_le_bytes());
        body.extend_from_slice(records);
        let mut out = vec![op::CHUNK];
        out.extend_from_slice(&(body.len() as u64).to_le_bytes());
        out.extend(body);
        out
    }

    #[test]
    fn records_past_their_uncompressed_chunk_are_refused() {
        let message = [&[op::MESSAGE][..], &3u64.to_le_bytes(), b"abc"].concat();
        let file = |records: &[u8]| {
            let mut f = b"\x89MCAP0\r\n".to_vec();
            f.extend(chunk(records));
            f.extend_from_slice(&[op::DATA_END, 4, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]);
            std::io::Cursor::new(f)
        };
        let two = [message.clone(), message.clone()].concat();
        assert_eq!(check_chunks(&mut file(&two)), Ok(()));
        // The second message claims 4 bytes where 3 remain in the chunk.
        let mut bad = two.clone();
        bad[13] = 4;
        assert_eq!(check_chunks(&mut file(&bad)), Err((4, 3)));
        // A record head cut by the chunk's end.
        assert_eq!(check_chunks(&mut file(&two[..16])), Err((9, 4)));
        // A truncated file is left to the reader.
        let mut cut = file(&two).into_inner();
        cut.truncate(30);
        assert_eq!(check_chunks(&mut std::io::Cursor::new(cut)), Ok(()));
    }

    #[test]
    fn strings_claiming_more_than_their_record_are_refused() {
        // A channel: id, schema id, topic, encoding, a map of one pair.
        let mut channel = vec![1, 0, 0, 0];
        channel.extend(string(b"/points"));
        channel.extend(string(b"cdr"));
        let pair = [string(b"k"), string(b"v")].concat();
        channel.extend((pair.len() as u32).to_le_bytes());
        channel.extend(&pair);
        assert_eq!(check_strings(op::CHANNEL, &channel), Ok(()));
        // The topic claims 4 GiB.
        let mut bad = channel.clone();
        bad[4..8].copy_from_slice(&u32::MAX.to_le_bytes());
        assert_eq!(
            check_strings(op::CHANNEL, &bad),
            Err((u64::from(u32::MAX), channel.len() as u64 - 8))
        );
        // The map's value claims more than the map.
        let mut bad = channel.clone();
        let value = channel.len() - 5;
        bad[value..value + 4].copy_from_slice(&2u32.to_le_bytes());
        assert_eq!(check_strings(op::CHANNEL, &bad), Err((2, 1)));
        // Cut inside the encoding's length.
        assert!(check_strings(op::CHANNEL, &channel[..17]).is_err());
        // A schema: id, name, encoding.
        let mut schema = vec![1, 0];
        schema.extend(string(b"sensor_msgs/msg/PointCloud2"));
        schema.extend(string(b"ros2msg"));
        assert_eq!(check_strings(op::SCHEMA, &schema), Ok(()));
        assert!(check_strings(op::SCHEMA, &schema[..schema.len() - 1]).is_err());
    }
}
