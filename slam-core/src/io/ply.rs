//! PLY files: `ascii`, `binary_little_endian` and `binary_big_endian`. Reads the `vertex`
//! element's x y z plus intensity (`intensity` or `scalar_intensity`), ring and time; every other
//! property and element (including list properties such as faces) is skipped.

use std::io::Write;
use std::path::Path;

use super::point_record::{write_ascii_records, write_binary_records};
use super::reading::{byte_err, line_err, next_header_line, require_xyz};
use super::scalar::{
    Channel, ChannelSink, Column, Scalar, create_file, parse_f64, read_file, ring_value,
};
use crate::cloud::PointCloud;
use crate::error::FormatError;

/// How [`write_ply`] stores the vertices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PlyEncoding {
    /// Text.
    Ascii,
    /// Little-endian binary.
    #[default]
    BinaryLittleEndian,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Ascii,
    Binary { little_endian: bool },
}

#[derive(Clone, Debug)]
enum Property {
    Scalar { name: String, scalar: Scalar },
    List { count: Scalar, item: Scalar },
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

fn scalar_of(name: &str, line: usize) -> Result<Scalar, FormatError> {
    Ok(match name {
        "char" | "int8" => Scalar::I8,
        "uchar" | "uint8" => Scalar::U8,
        "short" | "int16" => Scalar::I16,
        "ushort" | "uint16" => Scalar::U16,
        "int" | "int32" => Scalar::I32,
        "uint" | "uint32" => Scalar::U32,
        "float" | "float32" => Scalar::F32,
        "double" | "float64" => Scalar::F64,
        other => return Err(line_err(line, format!("unknown PLY type {other:?}"))),
    })
}

struct Header {
    format: Format,
    elements: Vec<Element>,
    data_offset: usize,
    data_line: usize,
}

fn parse_header(bytes: &[u8]) -> Result<Header, FormatError> {
    let mut pos = 0;
    let mut line_no = 0;
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        if pos >= bytes.len() {
            return Err(line_err(line_no, "no end_header line"));
        }
        line_no += 1;
        let text = next_header_line(bytes, &mut pos, line_no)?;
        let words: Vec<&str> = text.split_whitespace().collect();
        match words.as_slice() {
            ["ply"] if line_no == 1 => {}
            _ if line_no == 1 => return Err(line_err(1, "not a PLY file (no 'ply' magic)")),
            [] | ["comment" | "obj_info", ..] => {}
            ["format", kind, _version] => {
                format = Some(match *kind {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::Binary {
                        little_endian: true,
                    },
                    "binary_big_endian" => Format::Binary {
                        little_endian: false,
                    },
                    other => return Err(line_err(line_no, format!("unknown format {other:?}"))),
                });
            }
            ["element", name, count] => {
                let count = count.parse::<usize>().map_err(|_| {
                    line_err(line_no, format!("element count {count:?} is not a number"))
                })?;
                elements.push(Element {
                    name: (*name).to_string(),
                    count,
                    properties: Vec::new(),
                });
            }
            ["property", "list", count, item, _name] => {
                let el = elements
                    .last_mut()
                    .ok_or_else(|| line_err(line_no, "property before any element"))?;
                let count = scalar_of(count, line_no)?;
                if !count.is_integer() {
                    return Err(line_err(line_no, "list count type must be an integer"));
                }
                el.properties.push(Property::List {
                    count,
                    item: scalar_of(item, line_no)?,
                });
            }
            ["property", ty, name] => {
                let el = elements
                    .last_mut()
                    .ok_or_else(|| line_err(line_no, "property before any element"))?;
                el.properties.push(Property::Scalar {
                    name: (*name).to_string(),
                    scalar: scalar_of(ty, line_no)?,
                });
            }
            ["end_header"] => break,
            _ => {
                return Err(line_err(
                    line_no,
                    format!("unexpected header line {text:?}"),
                ));
            }
        }
    }
    let format = format.ok_or_else(|| line_err(line_no, "no format line"))?;
    Ok(Header {
        format,
        elements,
        data_offset: pos,
        data_line: line_no + 1,
    })
}

/// Which vertex property feeds a channel.
#[derive(Clone, Copy, Debug)]
struct VertexSlot {
    channel: Channel,
    /// Index of the property in the vertex element.
    property: usize,
}

/// One slot per channel found (the first property of each channel).
fn vertex_slots(el: &Element) -> Result<Vec<VertexSlot>, FormatError> {
    let mut slots: Vec<VertexSlot> = Vec::new();
    for (i, p) in el.properties.iter().enumerate() {
        if let Property::Scalar { name, scalar } = p
            && let Some(ch) = Channel::from_name(name)
            && !slots.iter().any(|s| s.channel == ch)
        {
            if ch == Channel::Ring && !scalar.is_integer() {
                return Err(FormatError::NonIntegerRing {
                    field: name.clone(),
                });
            }
            slots.push(VertexSlot {
                channel: ch,
                property: i,
            });
        }
    }
    require_xyz(|ch| slots.iter().any(|s| s.channel == ch))?;
    Ok(slots)
}

/// The layout of an element whose properties are all scalars: its record's size and the
/// (index, offset, type) of each property a channel reads.
struct FixedRecord {
    size: usize,
    fields: Vec<(usize, usize, Scalar)>,
}

/// `el`'s fixed layout for `slots`, `None` when it has a list property.
fn fixed_record(el: &Element, slots: &[VertexSlot]) -> Option<FixedRecord> {
    let mut size = 0;
    let mut fields = Vec::with_capacity(slots.len());
    for (i, p) in el.properties.iter().enumerate() {
        let Property::Scalar { scalar, .. } = *p else {
            return None;
        };
        if slots.iter().any(|s| s.property == i) {
            fields.push((i, size, scalar));
        }
        size += scalar.size();
    }
    (size > 0).then_some(FixedRecord { size, fields })
}

fn store(sink: &mut ChannelSink, slots: &[VertexSlot], values: &[f64]) -> Option<()> {
    let mut p = [0f32; 3];
    for s in slots {
        let v = values[s.property];
        match s.channel {
            Channel::X => p[0] = v as f32,
            Channel::Y => p[1] = v as f32,
            Channel::Z => p[2] = v as f32,
            Channel::Intensity => sink.intensity.as_mut()?.push(v as f32),
            Channel::Time => sink.time.as_mut()?.push(v as f32),
            Channel::Ring => {
                let r = ring_value(v)?;
                sink.ring.as_mut()?.push(r);
            }
        }
    }
    sink.xyz.push(nalgebra::Point3::new(p[0], p[1], p[2]));
    Some(())
}

/// Check that the binary data can hold the records the header states before reading them:
/// each record of an element needs at least its scalars and list counts.
fn check_binary_sizes(
    elements: &[Element],
    data_offset: usize,
    end: usize,
) -> Result<(), FormatError> {
    let data_len = end - data_offset;
    let mut need = 0usize;
    for el in elements {
        let least: usize = el
            .properties
            .iter()
            .map(|p| match p {
                Property::Scalar { scalar, .. } => scalar.size(),
                Property::List { count, .. } => count.size(),
            })
            .sum();
        need = least
            .checked_mul(el.count)
            .and_then(|n| n.checked_add(need))
            .filter(|&n| n <= data_len)
            .ok_or_else(|| {
                byte_err(
                    end,
                    format!(
                        "{} {} records of at least {least} bytes do not fit in {data_len} bytes of data",
                        el.count, el.name
                    ),
                )
            })?;
    }
    Ok(())
}

/// Parse a PLY file held in memory.
///
/// # Errors
/// [`FormatError::Line`] for header and ascii errors, [`FormatError::Byte`] for truncated or
/// malformed binary data, [`FormatError::NoVertexElement`] or [`FormatError::MissingField`] when
/// there is no vertex element with x, y, z, [`FormatError::NonIntegerRing`] for a floating-point
/// ring property.
// One walk over the header's elements, in binary or text; splitting it would scatter the cursor.
#[allow(clippy::too_many_lines)]
pub fn parse_ply(bytes: &[u8]) -> Result<PointCloud, FormatError> {
    let header = parse_header(bytes)?;
    let vi = header
        .elements
        .iter()
        .position(|e| e.name == "vertex")
        .ok_or(FormatError::NoVertexElement)?;
    let slots = vertex_slots(&header.elements[vi])?;
    let vcount = header.elements[vi].count;
    let has = |c| slots.iter().any(|s| s.channel == c);
    // Cap the preallocation by what the data could hold (a lying header must not allocate).
    let cap = vcount.min(bytes.len() - header.data_offset);
    let mut sink = ChannelSink::new(
        cap,
        has(Channel::Ring),
        has(Channel::Intensity),
        has(Channel::Time),
    );
    match header.format {
        Format::Binary { little_endian } => {
            check_binary_sizes(&header.elements[..=vi], header.data_offset, bytes.len())?;
            let mut pos = header.data_offset;
            let mut values = Vec::new();
            for (ei, el) in header.elements.iter().enumerate() {
                if ei > vi {
                    break;
                }
                // An element without properties holds no bytes, however many records it states.
                let records = if el.properties.is_empty() {
                    0
                } else {
                    el.count
                };
                if ei == vi
                    && let Some(record) = fixed_record(el, &slots)
                {
                    // Scalars only: every record has the same layout, so each channel is read
                    // as a column at its offset, one type at a time.
                    let end = records
                        .checked_mul(record.size)
                        .and_then(|n| n.checked_add(pos))
                        .filter(|&end| end <= bytes.len())
                        .ok_or_else(|| byte_err(pos, format!("{} data truncated", el.name)))?;
                    let columns: Vec<(Channel, Column<'_>)> = slots
                        .iter()
                        .filter_map(|s| {
                            let &(_, offset, scalar) =
                                record.fields.iter().find(|f| f.0 == s.property)?;
                            let data = &bytes[pos..end];
                            let stride = record.size;
                            Some((
                                s.channel,
                                Column {
                                    data,
                                    stride,
                                    offset,
                                    scalar,
                                },
                            ))
                        })
                        .collect();
                    sink.extend_columns(records, &columns, little_endian)
                        .map_err(|r| {
                            byte_err(
                                pos + (r + 1) * record.size,
                                "ring value is not a whole number in 0..=65535",
                            )
                        })?;
                    pos = end;
                    continue;
                }
                for _ in 0..records {
                    values.clear();
                    for p in &el.properties {
                        match *p {
                            Property::Scalar { scalar, .. } => {
                                let b = bytes.get(pos..pos + scalar.size()).ok_or_else(|| {
                                    byte_err(pos, format!("{} data truncated", el.name))
                                })?;
                                values.push(scalar.read(b, little_endian));
                                pos += scalar.size();
                            }
                            Property::List { count, item } => {
                                let b = bytes.get(pos..pos + count.size()).ok_or_else(|| {
                                    byte_err(pos, format!("{} data truncated", el.name))
                                })?;
                                let k = count.read(b, little_endian);
                                if k < 0.0 {
                                    return Err(byte_err(pos, "negative list length"));
                                }
                                pos = (k as usize)
                                    .checked_mul(item.size())
                                    .and_then(|n| n.checked_add(pos + count.size()))
                                    .filter(|&end| end <= bytes.len())
                                    .ok_or_else(|| {
                                        byte_err(pos, "list runs past the end of the data")
                                    })?;
                                values.push(f64::NAN);
                            }
                        }
                    }
                    if ei == vi {
                        store(&mut sink, &slots, &values).ok_or_else(|| {
                            byte_err(pos, "ring value is not a whole number in 0..=65535")
                        })?;
                    }
                }
            }
            if pos > bytes.len() {
                return Err(byte_err(bytes.len(), "data truncated"));
            }
        }
        Format::Ascii => {
            let text = std::str::from_utf8(&bytes[header.data_offset..])
                .map_err(|_| byte_err(header.data_offset, "ascii data is not UTF-8"))?;
            let mut lines = text
                .lines()
                .enumerate()
                .filter(|(_, l)| !l.trim().is_empty());
            let mut values = Vec::new();
            for (ei, el) in header.elements.iter().enumerate() {
                if ei > vi {
                    break;
                }
                for _ in 0..el.count {
                    let (k, line) = lines.next().ok_or_else(|| {
                        line_err(
                            header.data_line,
                            format!("fewer {} lines than stated", el.name),
                        )
                    })?;
                    let line_no = header.data_line + k;
                    let mut tokens = line.split_whitespace();
                    values.clear();
                    for p in &el.properties {
                        let mut next = || {
                            tokens
                                .next()
                                .ok_or_else(|| line_err(line_no, "too few values"))
                        };
                        match p {
                            Property::Scalar { .. } => {
                                values.push(parse_f64(next()?, line_no, "value")?);
                            }
                            Property::List { .. } => {
                                let n = parse_f64(next()?, line_no, "list length")?;
                                if n < 0.0 || n.fract() != 0.0 {
                                    return Err(line_err(line_no, "list length is not a count"));
                                }
                                for _ in 0..n as usize {
                                    next()?;
                                }
                                values.push(f64::NAN);
                            }
                        }
                    }
                    if tokens.next().is_some() {
                        return Err(line_err(line_no, "too many values"));
                    }
                    if ei == vi {
                        store(&mut sink, &slots, &values).ok_or_else(|| {
                            line_err(line_no, "ring value is not a whole number in 0..=65535")
                        })?;
                    }
                }
            }
        }
    }
    sink.finish()
}

/// Read a PLY file.
///
/// # Errors
/// [`FormatError::Io`] when the file cannot be read, otherwise as [`parse_ply`].
pub fn read_ply(path: impl AsRef<Path>) -> Result<PointCloud, FormatError> {
    parse_ply(&read_file(path.as_ref())?)
}

/// Write `cloud` as PLY to any writer: float x y z, then float intensity, ushort ring and float
/// time when the cloud has them.
///
/// # Errors
/// [`FormatError::Stream`] when writing fails.
pub fn write_ply_to(
    mut w: impl Write,
    cloud: &PointCloud,
    encoding: PlyEncoding,
) -> Result<(), FormatError> {
    writeln!(w, "ply")?;
    match encoding {
        PlyEncoding::Ascii => writeln!(w, "format ascii 1.0")?,
        PlyEncoding::BinaryLittleEndian => writeln!(w, "format binary_little_endian 1.0")?,
    }
    writeln!(w, "comment written by spot-nav slam-core")?;
    writeln!(w, "element vertex {}", cloud.len())?;
    for name in ["x", "y", "z"] {
        writeln!(w, "property float {name}")?;
    }
    if cloud.intensity().is_some() {
        writeln!(w, "property float intensity")?;
    }
    if cloud.ring().is_some() {
        writeln!(w, "property ushort ring")?;
    }
    if cloud.time().is_some() {
        writeln!(w, "property float time")?;
    }
    writeln!(w, "end_header")?;
    match encoding {
        PlyEncoding::BinaryLittleEndian => write_binary_records(cloud, &mut w)?,
        PlyEncoding::Ascii => write_ascii_records(cloud, &mut w)?,
    }
    w.flush()?;
    Ok(())
}

/// Write `cloud` to a PLY file.
///
/// # Errors
/// [`FormatError::Io`] when the file cannot be created, [`FormatError::Stream`] on write errors.
pub fn write_ply(
    path: impl AsRef<Path>,
    cloud: &PointCloud,
    encoding: PlyEncoding,
) -> Result<(), FormatError> {
    write_ply_to(create_file(path.as_ref())?, cloud, encoding)
}
