//! The points of a cloud as the records of the PCD and PLY writers: `x y z`, then the channels
//! the cloud has, in the order both formats' headers list them (intensity, ring, time).

use std::io::Write;

use crate::cloud::PointCloud;

/// Writes every point's record, little-endian (f32 coordinates, intensity and time, u16 ring).
pub(crate) fn write_binary_records(cloud: &PointCloud, w: &mut impl Write) -> std::io::Result<()> {
    let mut rec = Vec::with_capacity(22);
    for i in 0..cloud.len() {
        rec.clear();
        binary_record(cloud, i, &mut rec);
        w.write_all(&rec)?;
    }
    Ok(())
}

/// Writes every point's record as one line of text (see [`ascii_record`]).
pub(crate) fn write_ascii_records(cloud: &PointCloud, w: &mut impl Write) -> std::io::Result<()> {
    for i in 0..cloud.len() {
        ascii_record(cloud, i, w)?;
    }
    Ok(())
}

/// Appends point `i`'s record to `out`, little-endian (f32 coordinates, intensity and time,
/// u16 ring).
fn binary_record(cloud: &PointCloud, i: usize, out: &mut Vec<u8>) {
    let p = cloud.points()[i];
    for v in [p.x, p.y, p.z] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    if let Some(c) = cloud.intensity() {
        out.extend_from_slice(&c[i].to_le_bytes());
    }
    if let Some(c) = cloud.ring() {
        out.extend_from_slice(&c[i].to_le_bytes());
    }
    if let Some(c) = cloud.time() {
        out.extend_from_slice(&c[i].to_le_bytes());
    }
}

/// Writes point `i`'s record as one line of text, values apart by single spaces. `{}` prints
/// the shortest text that reads back to the same f32.
fn ascii_record(cloud: &PointCloud, i: usize, w: &mut impl Write) -> std::io::Result<()> {
    let p = cloud.points()[i];
    write!(w, "{} {} {}", p.x, p.y, p.z)?;
    if let Some(c) = cloud.intensity() {
        write!(w, " {}", c[i])?;
    }
    if let Some(c) = cloud.ring() {
        write!(w, " {}", c[i])?;
    }
    if let Some(c) = cloud.time() {
        write!(w, " {}", c[i])?;
    }
    writeln!(w)
}
