//! The messages of an MCAP file in file order, streamed by the `mcap` crate's sans-io
//! [`LinearReader`] (which checks record lengths against a limit and decompresses chunks) with
//! only the records messages need parsed: schemas, channels and messages.
//!
//! The crate's record parser reserves the length a string claims before reading it, so a 30-byte
//! channel record claiming a 4 GiB topic name reserved 4 GiB. Every string of a schema or channel
//! record is therefore checked against the bytes left in its record before the record is parsed,
//! and the records a reader of messages does not use (header, attachments, metadata, indexes,
//! statistics, the summary after the data end) are passed over unparsed.

use std::fs::File;
use std::io::{BufReader, ErrorKind, Read};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use mcap::read::ChannelAccumulator;
use mcap::records::{Record, op};
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};

use crate::error::AdapterError;

/// One message with its channel.
pub(crate) struct McapMessage {
    pub channel: Arc<mcap::Channel<'static>>,
    /// When it was recorded (nanoseconds).
    pub log_time: u64,
    pub data: Vec<u8>,
}

/// The messages of an MCAP file, read one record at a time (memory: the largest record or
/// decompressed chunk, at most `record_length_limit`).
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
fn string_end(record: &[u8], at: usize) -> Result<usize, (u64, usize)> {
    let left = record.len().saturating_sub(at);
    let Some(len) = record.get(at..at + 4) else {
        return Err((4, left));
    };
    let len = u64::from(u32::from_le_bytes([len[0], len[1], len[2], len[3]]));
    if len > (left - 4) as u64 {
        return Err((len, left - 4));
    }
    Ok(at + 4 + len as usize)
}

/// Check that every string of a schema or channel record lies inside it; `Err((claimed,
/// left))` for the first that does not.
fn check_strings(opcode: u8, record: &[u8]) -> Result<(), (u64, usize)> {
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
                return Err((4, record.len().saturating_sub(end)));
            };
            let map_len = u32::from_le_bytes([len[0], len[1], len[2], len[3]]) as usize;
            let map_end = end + 4 + map_len;
            if map_end > record.len() {
                return Err((map_len as u64, record.len() - end - 4));
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

impl McapMessages {
    /// The messages of the MCAP file at `path`, no record or chunk longer than
    /// `record_length_limit` bytes.
    pub(crate) fn open(path: &Path, record_length_limit: usize) -> Result<Self, AdapterError> {
        let file = File::open(path).map_err(|e| AdapterError::io(path, e))?;
        Ok(Self {
            path: path.to_path_buf(),
            file: BufReader::with_capacity(1 << 20, file),
            reader: LinearReader::new_with_options(
                LinearReaderOptions::default()
                    .with_record_length_limit(record_length_limit)
                    .with_emit_chunks(false),
            ),
            channels: ChannelAccumulator::default(),
            past_data_end: false,
            done: false,
        })
    }

    fn next_message(&mut self) -> Option<Result<McapMessage, AdapterError>> {
        let mcap = |path: &Path, source| AdapterError::Mcap {
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
                        match self.file.read(self.reader.insert(need)) {
                            Ok(n) => break n,
                            Err(e) if e.kind() == ErrorKind::Interrupted => {}
                            Err(e) => return Some(Err(AdapterError::io(&self.path, e))),
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
                return Some(Err(AdapterError::McapString {
                    path: self.path.clone(),
                    opcode,
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
    type Item = Result<McapMessage, AdapterError>;

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
            Err((u64::from(u32::MAX), channel.len() - 8))
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
