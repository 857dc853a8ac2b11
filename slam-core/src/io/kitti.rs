//! KITTI files: velodyne scans (`.bin`, float32 x y z reflectance records) and pose files (one
//! row-major 3x4 matrix `[R | t]` per line).

use std::io::Write;
use std::path::Path;

use nalgebra::{Matrix3, Point3, Rotation3, Translation3, UnitQuaternion};

use super::scalar::{create_file, parse_f64, read_file};
use crate::cloud::PointCloud;
use crate::error::FormatError;
use crate::geometry::Pose3;

/// Parse a KITTI velodyne scan held in memory. Reflectance becomes the intensity channel.
///
/// # Errors
/// [`FormatError::Byte`] when the length is not a multiple of 16 bytes.
pub fn parse_kitti_bin(bytes: &[u8]) -> Result<PointCloud, FormatError> {
    if !bytes.len().is_multiple_of(16) {
        return Err(FormatError::Byte {
            offset: bytes.len() - bytes.len() % 16,
            message: format!(
                "{} bytes is not a whole number of 16-byte records",
                bytes.len()
            ),
        });
    }
    let f = |b: &[u8]| f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
    let n = bytes.len() / 16;
    let mut points = Vec::with_capacity(n);
    let mut intensity = Vec::with_capacity(n);
    for r in bytes.chunks_exact(16) {
        points.push(Point3::new(f(&r[0..]), f(&r[4..]), f(&r[8..])));
        intensity.push(f(&r[12..]));
    }
    Ok(PointCloud::from_points(points).with_intensity(intensity)?)
}

/// Read a KITTI velodyne `.bin` scan.
///
/// # Errors
/// [`FormatError::Io`] when the file cannot be read, otherwise as [`parse_kitti_bin`].
pub fn read_kitti_bin(path: impl AsRef<Path>) -> Result<PointCloud, FormatError> {
    parse_kitti_bin(&read_file(path.as_ref())?)
}

/// Write a cloud as a KITTI `.bin` scan; the intensity channel (zero when absent) is the
/// reflectance. Ring and time channels have no place in this format: use PCD to keep them.
///
/// # Errors
/// [`FormatError::Stream`] when writing fails.
pub fn write_kitti_bin_to(mut w: impl Write, cloud: &PointCloud) -> Result<(), FormatError> {
    let mut buf = Vec::with_capacity(cloud.len() * 16);
    for (i, p) in cloud.points().iter().enumerate() {
        let r = cloud.intensity().map_or(0.0, |c| c[i]);
        for v in [p.x, p.y, p.z, r] {
            buf.extend_from_slice(&v.to_le_bytes());
        }
    }
    w.write_all(&buf)?;
    w.flush()?;
    Ok(())
}

/// Write a KITTI `.bin` scan file.
///
/// # Errors
/// [`FormatError::Io`] when the file cannot be created, [`FormatError::Stream`] on write errors.
pub fn write_kitti_bin(path: impl AsRef<Path>, cloud: &PointCloud) -> Result<(), FormatError> {
    write_kitti_bin_to(create_file(path.as_ref())?, cloud)
}

/// Largest deviation of `R^T R` from the identity that is repaired (re-orthonormalised) rather
/// than rejected: the 6 to 9 significant digits KITTI files print leave errors near 1e-6.
pub const KITTI_ROTATION_TOLERANCE: f64 = 1e-3;

/// Parse KITTI poses (12 numbers per line, row-major `[R | t]`). Rotations within
/// [`KITTI_ROTATION_TOLERANCE`] of orthonormal are re-orthonormalised; others are an error.
///
/// # Errors
/// [`FormatError::Line`] for a line without 12 numbers or with a rotation that is not one.
pub fn parse_kitti_poses(text: &str) -> Result<Vec<Pose3>, FormatError> {
    let mut poses = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let line_no = k + 1;
        if line.trim().is_empty() {
            continue;
        }
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|t| parse_f64(t, line_no, "pose value"))
            .collect::<Result<_, _>>()?;
        if v.len() != 12 {
            return Err(FormatError::Line {
                line: line_no,
                message: format!("{} numbers, 12 expected", v.len()),
            });
        }
        if !v.iter().all(|x| x.is_finite()) {
            return Err(FormatError::Line {
                line: line_no,
                message: "non-finite value".into(),
            });
        }
        let r = Matrix3::new(v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10]);
        let dev = (r.transpose() * r - Matrix3::identity()).amax();
        if dev > KITTI_ROTATION_TOLERANCE || r.determinant() <= 0.0 {
            return Err(FormatError::Line {
                line: line_no,
                message: format!(
                    "not a rotation (|R^T R - I| = {dev:.2e}, det = {:.3})",
                    r.determinant()
                ),
            });
        }
        let rot = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix(&r));
        poses.push(Pose3::from_parts(Translation3::new(v[3], v[7], v[11]), rot));
    }
    Ok(poses)
}

/// Read a KITTI pose file.
///
/// # Errors
/// [`FormatError::Io`] when the file cannot be read, otherwise as [`parse_kitti_poses`].
pub fn read_kitti_poses(path: impl AsRef<Path>) -> Result<Vec<Pose3>, FormatError> {
    let bytes = read_file(path.as_ref())?;
    let text = std::str::from_utf8(&bytes).map_err(|e| FormatError::Byte {
        offset: e.valid_up_to(),
        message: "not UTF-8 text".into(),
    })?;
    parse_kitti_poses(text)
}

/// Write poses in KITTI's format (full f64 precision).
///
/// # Errors
/// [`FormatError::Stream`] when writing fails.
pub fn write_kitti_poses_to(mut w: impl Write, poses: &[Pose3]) -> Result<(), FormatError> {
    for p in poses {
        let r = p.rotation.to_rotation_matrix();
        let t = p.translation.vector;
        let m = r.matrix();
        writeln!(
            w,
            "{:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e} {:e}",
            m[(0, 0)],
            m[(0, 1)],
            m[(0, 2)],
            t.x,
            m[(1, 0)],
            m[(1, 1)],
            m[(1, 2)],
            t.y,
            m[(2, 0)],
            m[(2, 1)],
            m[(2, 2)],
            t.z
        )?;
    }
    w.flush()?;
    Ok(())
}

/// Write a KITTI pose file.
///
/// # Errors
/// [`FormatError::Io`] when the file cannot be created, [`FormatError::Stream`] on write errors.
pub fn write_kitti_poses(path: impl AsRef<Path>, poses: &[Pose3]) -> Result<(), FormatError> {
    write_kitti_poses_to(create_file(path.as_ref())?, poses)
}
