//! PCD (Point Cloud Library) files: `ascii`, `binary` and `binary_compressed` data, fields in any
//! order, padding fields skipped. Reads x y z plus intensity, ring and time when present.
//! The `VIEWPOINT` is not applied to the points (as PCL does not); files are read as stored.

use std::io::Write;
use std::path::Path;

use super::lzf::lzf_decompress;
use super::point_record::{write_ascii_records, write_binary_records};
use super::reading::{byte_err, line_err, next_header_line, require_xyz};
use super::scalar::{
    Channel, ChannelSink, Column, Scalar, create_file, parse_f64, read_file, ring_value,
};
use crate::cloud::PointCloud;
use crate::error::FormatError;

/// How [`write_pcd`] stores the data section.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PcdEncoding {
    /// One text line per point (values printed so that f32 round-trips exactly).
    Ascii,
    /// Packed little-endian records.
    #[default]
    Binary,
}

/// One `FIELDS` entry.
#[derive(Clone, Debug)]
struct Field {
    name: String,
    scalar: Scalar,
    count: usize,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum DataKind {
    Ascii,
    Binary,
    BinaryCompressed,
}

struct Header {
    fields: Vec<Field>,
    points: usize,
    data: DataKind,
    /// Byte offset of the data section.
    data_offset: usize,
    /// Line number of the first data line (for ascii errors).
    data_line: usize,
}

fn scalar_of(ty: &str, size: usize, line: usize) -> Result<Scalar, FormatError> {
    Ok(match (ty, size) {
        ("F", 4) => Scalar::F32,
        ("F", 8) => Scalar::F64,
        ("U", 1) => Scalar::U8,
        ("U", 2) => Scalar::U16,
        ("U", 4) => Scalar::U32,
        ("U", 8) => Scalar::U64,
        ("I", 1) => Scalar::I8,
        ("I", 2) => Scalar::I16,
        ("I", 4) => Scalar::I32,
        ("I", 8) => Scalar::I64,
        _ => {
            return Err(line_err(
                line,
                format!("unsupported TYPE {ty} with SIZE {size}"),
            ));
        }
    })
}

/// Header values as read, before they are checked against each other.
#[derive(Default)]
struct RawHeader {
    names: Option<Vec<String>>,
    sizes: Option<Vec<usize>>,
    types: Option<Vec<String>>,
    counts: Option<Vec<usize>>,
    width: Option<usize>,
    height: Option<usize>,
    points: Option<usize>,
}

impl RawHeader {
    /// Check the header at its `DATA` line (`line_no`); the data starts at byte `pos`.
    fn finish(self, data: DataKind, pos: usize, line_no: usize) -> Result<Header, FormatError> {
        let names = self
            .names
            .ok_or_else(|| line_err(line_no, "no FIELDS line before DATA"))?;
        let sizes = self
            .sizes
            .ok_or_else(|| line_err(line_no, "no SIZE line before DATA"))?;
        let types = self
            .types
            .ok_or_else(|| line_err(line_no, "no TYPE line before DATA"))?;
        let counts = self.counts.unwrap_or_else(|| vec![1; names.len()]);
        if sizes.len() != names.len() || types.len() != names.len() || counts.len() != names.len() {
            return Err(line_err(
                line_no,
                format!(
                    "FIELDS has {} entries but SIZE {}, TYPE {}, COUNT {}",
                    names.len(),
                    sizes.len(),
                    types.len(),
                    counts.len()
                ),
            ));
        }
        let mut fields = Vec::with_capacity(names.len());
        for (((name, size), ty), count) in names.into_iter().zip(sizes).zip(types).zip(counts) {
            if count == 0 {
                return Err(line_err(line_no, format!("field {name} has COUNT 0")));
            }
            fields.push(Field {
                scalar: scalar_of(&ty, size, line_no)?,
                name,
                count,
            });
        }
        let wh = match (self.width, self.height) {
            (Some(w), Some(h)) => Some(
                w.checked_mul(h)
                    .ok_or_else(|| line_err(line_no, "WIDTH * HEIGHT overflows"))?,
            ),
            (Some(w), None) => Some(w),
            _ => None,
        };
        let points = match (self.points, wh) {
            (Some(p), Some(wh)) if p != wh => {
                return Err(line_err(
                    line_no,
                    format!("POINTS {p} but WIDTH * HEIGHT = {wh}"),
                ));
            }
            (Some(p), _) => p,
            (None, Some(wh)) => wh,
            (None, None) => return Err(line_err(line_no, "neither POINTS nor WIDTH given")),
        };
        Ok(Header {
            fields,
            points,
            data,
            data_offset: pos,
            data_line: line_no + 1,
        })
    }
}

fn parse_header(bytes: &[u8]) -> Result<Header, FormatError> {
    let mut raw = RawHeader::default();
    let mut pos = 0;
    let mut line_no = 0;
    while pos < bytes.len() {
        line_no += 1;
        let text = next_header_line(bytes, &mut pos, line_no)?;
        if text.is_empty() || text.starts_with('#') {
            continue;
        }
        let mut it = text.split_whitespace();
        let key = it.next().unwrap_or_default().to_ascii_uppercase();
        let rest: Vec<&str> = it.collect();
        let nums = |rest: &[&str]| -> Result<Vec<usize>, FormatError> {
            rest.iter()
                .map(|t| {
                    t.parse::<usize>()
                        .map_err(|_| line_err(line_no, format!("{key}: {t:?} is not a count")))
                })
                .collect()
        };
        match key.as_str() {
            "VERSION" | "VIEWPOINT" => {}
            "FIELDS" | "COLUMNS" => {
                raw.names = Some(rest.iter().map(|s| (*s).to_string()).collect());
            }
            "SIZE" => raw.sizes = Some(nums(&rest)?),
            "TYPE" => raw.types = Some(rest.iter().map(|s| s.to_ascii_uppercase()).collect()),
            "COUNT" => raw.counts = Some(nums(&rest)?),
            "WIDTH" => raw.width = nums(&rest)?.first().copied(),
            "HEIGHT" => raw.height = nums(&rest)?.first().copied(),
            "POINTS" => raw.points = nums(&rest)?.first().copied(),
            "DATA" => {
                let data = match rest.first().map(|s| s.to_ascii_lowercase()).as_deref() {
                    Some("ascii") => DataKind::Ascii,
                    Some("binary") => DataKind::Binary,
                    Some("binary_compressed") => DataKind::BinaryCompressed,
                    other => return Err(line_err(line_no, format!("unknown DATA kind {other:?}"))),
                };
                return raw.finish(data, pos, line_no);
            }
            other => return Err(line_err(line_no, format!("unknown header key {other}"))),
        }
    }
    Err(line_err(line_no, "no DATA line: the header is incomplete"))
}

/// Where one channel lives in the data.
#[derive(Clone, Copy, Debug)]
struct Slot {
    channel: Channel,
    /// Byte offset in a binary record.
    offset: usize,
    /// How the value is stored.
    scalar: Scalar,
    /// Index of the value among all values of an ascii line.
    value_index: usize,
    /// Index of the field in `FIELDS` (a compressed file stores each field in its own block).
    field_index: usize,
}

/// Where each channel lives in a record, and the record's size.
struct Layout {
    record_size: usize,
    /// One slot per channel found (the first field of each channel).
    slots: Vec<Slot>,
}

fn layout(fields: &[Field]) -> Result<Layout, FormatError> {
    let mut offset = 0usize;
    let mut value_index = 0usize;
    let mut slots: Vec<Slot> = Vec::new();
    for (field_index, f) in fields.iter().enumerate() {
        if let Some(ch) = Channel::from_name(&f.name)
            && !slots.iter().any(|s| s.channel == ch)
        {
            if ch == Channel::Ring && !f.scalar.is_integer() {
                return Err(FormatError::NonIntegerRing {
                    field: f.name.clone(),
                });
            }
            slots.push(Slot {
                channel: ch,
                offset,
                scalar: f.scalar,
                value_index,
                field_index,
            });
        }
        offset = f
            .scalar
            .size()
            .checked_mul(f.count)
            .and_then(|s| s.checked_add(offset))
            .ok_or(FormatError::RecordTooLarge)?;
        value_index += f.count;
    }
    require_xyz(|ch| slots.iter().any(|s| s.channel == ch))?;
    Ok(Layout {
        record_size: offset,
        slots,
    })
}

fn sink_for(layout: &Layout, n: usize) -> ChannelSink {
    let has = |c| layout.slots.iter().any(|s| s.channel == c);
    ChannelSink::new(
        n,
        has(Channel::Ring),
        has(Channel::Intensity),
        has(Channel::Time),
    )
}

/// Push one decoded point; `value(slot)` yields the slot's number.
fn push_point(
    sink: &mut ChannelSink,
    layout: &Layout,
    mut value: impl FnMut(&Slot) -> Result<f64, FormatError>,
    at: impl Fn() -> FormatError,
) -> Result<(), FormatError> {
    let mut p = [0f32; 3];
    for s in &layout.slots {
        let v = value(s)?;
        match s.channel {
            Channel::X => p[0] = v as f32,
            Channel::Y => p[1] = v as f32,
            Channel::Z => p[2] = v as f32,
            Channel::Intensity => {
                if let Some(c) = &mut sink.intensity {
                    c.push(v as f32);
                }
            }
            Channel::Time => {
                if let Some(c) = &mut sink.time {
                    c.push(v as f32);
                }
            }
            Channel::Ring => {
                let r = ring_value(v).ok_or_else(&at)?;
                if let Some(c) = &mut sink.ring {
                    c.push(r);
                }
            }
        }
    }
    sink.xyz.push(nalgebra::Point3::new(p[0], p[1], p[2]));
    Ok(())
}

/// Parse a PCD file held in memory.
///
/// # Errors
/// [`FormatError::Line`] for header and ascii errors, [`FormatError::Byte`] for binary data that
/// is truncated or malformed, [`FormatError::MissingField`] for files without x, y, z,
/// [`FormatError::NonIntegerRing`] for a floating-point ring field.
pub fn parse_pcd(bytes: &[u8]) -> Result<PointCloud, FormatError> {
    let header = parse_header(bytes)?;
    let layout = layout(&header.fields)?;
    let data = &bytes[header.data_offset..];
    match header.data {
        DataKind::Binary => parse_binary(&header, &layout, data),
        DataKind::BinaryCompressed => parse_compressed(&header, &layout, data),
        DataKind::Ascii => parse_ascii(&header, &layout, data),
    }
}

fn parse_binary(header: &Header, layout: &Layout, data: &[u8]) -> Result<PointCloud, FormatError> {
    let n = header.points;
    let need = n.saturating_mul(layout.record_size);
    if data.len() < need {
        return Err(byte_err(
            header.data_offset + data.len(),
            format!(
                "binary data holds {} bytes, {n} points need {need}",
                data.len()
            ),
        ));
    }
    let mut sink = sink_for(layout, n);
    // Every record has the same layout: each channel is read as a column at its offset.
    let columns: Vec<(Channel, Column<'_>)> = layout
        .slots
        .iter()
        .map(|s| {
            let column = Column {
                data: &data[..need],
                stride: layout.record_size,
                offset: s.offset,
                scalar: s.scalar,
            };
            (s.channel, column)
        })
        .collect();
    sink.extend_columns(n, &columns, true).map_err(|i| {
        byte_err(
            header.data_offset + i * layout.record_size,
            "ring value is not a u16",
        )
    })?;
    sink.finish()
}

fn parse_compressed(
    header: &Header,
    layout: &Layout,
    data: &[u8],
) -> Result<PointCloud, FormatError> {
    let n = header.points;
    let word = |k: usize| -> Result<usize, FormatError> {
        let b = data
            .get(4 * k..4 * k + 4)
            .ok_or_else(|| byte_err(header.data_offset, "compressed header truncated"))?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
    };
    let (csize, usize_) = (word(0)?, word(1)?);
    let need = n.saturating_mul(layout.record_size);
    if usize_ != need {
        return Err(byte_err(
            header.data_offset + 4,
            format!("uncompressed size {usize_}, {need} expected"),
        ));
    }
    let comp = data
        .get(8..8 + csize)
        .ok_or_else(|| byte_err(header.data_offset + 8, "compressed data truncated"))?;
    let raw = lzf_decompress(comp, usize_, header.data_offset + 8)?;
    // Column layout: every point's value of field 0, then field 1, ...
    let mut field_start = Vec::with_capacity(header.fields.len());
    let mut acc = 0;
    for f in &header.fields {
        field_start.push(acc);
        acc += f.scalar.size() * f.count * n;
    }
    let mut sink = sink_for(layout, n);
    // Each field's block is a column of `n` values (`count` of them a point; the first read).
    let columns: Vec<(Channel, Column<'_>)> = layout
        .slots
        .iter()
        .map(|s| {
            let f = &header.fields[s.field_index];
            let stride = f.scalar.size() * f.count;
            let start = field_start[s.field_index];
            let column = Column {
                data: &raw[start..start + stride * n],
                stride,
                offset: 0,
                scalar: s.scalar,
            };
            (s.channel, column)
        })
        .collect();
    sink.extend_columns(n, &columns, true)
        .map_err(|_| byte_err(header.data_offset, "ring value is not a u16"))?;
    sink.finish()
}

fn parse_ascii(header: &Header, layout: &Layout, data: &[u8]) -> Result<PointCloud, FormatError> {
    let n = header.points;
    let text = std::str::from_utf8(data)
        .map_err(|_| byte_err(header.data_offset, "ascii data is not UTF-8"))?;
    let values_per_point: usize = header.fields.iter().map(|f| f.count).sum();
    let mut sink = sink_for(layout, n.min(data.len() / 2 + 1));
    // Grows to the tokens a line really has: COUNT is the file's word, not memory's.
    let mut tokens: Vec<&str> = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let line_no = header.data_line + k;
        if sink.xyz.len() == n {
            if line.trim().is_empty() {
                continue;
            }
            return Err(line_err(
                line_no,
                format!("more than the {n} points the header states"),
            ));
        }
        if line.trim().is_empty() {
            continue;
        }
        tokens.clear();
        tokens.extend(line.split_whitespace());
        if tokens.len() != values_per_point {
            return Err(line_err(
                line_no,
                format!("{} values, {values_per_point} expected", tokens.len()),
            ));
        }
        let at = || line_err(line_no, "ring value is not a whole number in 0..=65535");
        push_point(
            &mut sink,
            layout,
            |s| parse_f64(tokens[s.value_index], line_no, "value"),
            at,
        )?;
    }
    if sink.xyz.len() != n {
        return Err(line_err(
            header.data_line + text.lines().count(),
            format!("{} points, the header states {n}", sink.xyz.len()),
        ));
    }
    sink.finish()
}

/// Read a PCD file.
///
/// # Errors
/// [`FormatError::Io`] when the file cannot be read, otherwise as [`parse_pcd`].
pub fn read_pcd(path: impl AsRef<Path>) -> Result<PointCloud, FormatError> {
    parse_pcd(&read_file(path.as_ref())?)
}

/// Write `cloud` as PCD to any writer: x y z as F4, then intensity (F4), ring (U2) and t (F4)
/// when the cloud has them.
///
/// # Errors
/// [`FormatError::Stream`] when writing fails.
pub fn write_pcd_to(
    mut w: impl Write,
    cloud: &PointCloud,
    encoding: PcdEncoding,
) -> Result<(), FormatError> {
    let mut names = vec!["x", "y", "z"];
    let mut sizes = vec!["4", "4", "4"];
    let mut types = vec!["F", "F", "F"];
    if cloud.intensity().is_some() {
        names.push("intensity");
        sizes.push("4");
        types.push("F");
    }
    if cloud.ring().is_some() {
        names.push("ring");
        sizes.push("2");
        types.push("U");
    }
    if cloud.time().is_some() {
        names.push("t");
        sizes.push("4");
        types.push("F");
    }
    let n = cloud.len();
    writeln!(w, "# .PCD v0.7 - Point Cloud Data file format")?;
    writeln!(w, "VERSION 0.7")?;
    writeln!(w, "FIELDS {}", names.join(" "))?;
    writeln!(w, "SIZE {}", sizes.join(" "))?;
    writeln!(w, "TYPE {}", types.join(" "))?;
    writeln!(w, "COUNT {}", vec!["1"; names.len()].join(" "))?;
    writeln!(w, "WIDTH {n}")?;
    writeln!(w, "HEIGHT 1")?;
    writeln!(w, "VIEWPOINT 0 0 0 1 0 0 0")?;
    writeln!(w, "POINTS {n}")?;
    match encoding {
        PcdEncoding::Binary => {
            writeln!(w, "DATA binary")?;
            write_binary_records(cloud, &mut w)?;
        }
        PcdEncoding::Ascii => {
            writeln!(w, "DATA ascii")?;
            write_ascii_records(cloud, &mut w)?;
        }
    }
    w.flush()?;
    Ok(())
}

/// Write `cloud` to a PCD file.
///
/// # Errors
/// [`FormatError::Io`] when the file cannot be created, [`FormatError::Stream`] on write errors.
pub fn write_pcd(
    path: impl AsRef<Path>,
    cloud: &PointCloud,
    encoding: PcdEncoding,
) -> Result<(), FormatError> {
    write_pcd_to(create_file(path.as_ref())?, cloud, encoding)
}
