//! TUM trajectories: `timestamp tx ty tz qx qy qz qw` per line, `#` comments.

use std::io::Write;
use std::path::Path;

use nalgebra::Translation3;

use super::scalar::{create_file, parse_f64, read_file};
use crate::error::FormatError;
use crate::geometry::{Pose3, quaternion_from_xyzw, quaternion_to_xyzw};

/// A pose with its time stamp (seconds).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StampedPose {
    /// Seconds.
    pub stamp: f64,
    /// The pose (`world_T_body` or whatever frames the file holds).
    pub pose: Pose3,
}

/// Parse a TUM trajectory. Quaternions must have a norm within 10 % of one (they are then
/// normalised).
///
/// # Errors
/// [`FormatError::Line`] for lines without 8 finite numbers or with a bad quaternion.
pub fn parse_tum(text: &str) -> Result<Vec<StampedPose>, FormatError> {
    let mut out = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let line_no = k + 1;
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|t| parse_f64(t, line_no, "TUM value"))
            .collect::<Result<_, _>>()?;
        if v.len() != 8 {
            return Err(FormatError::Line {
                line: line_no,
                message: format!("{} numbers, 8 expected", v.len()),
            });
        }
        if !v.iter().all(|x| x.is_finite()) {
            return Err(FormatError::Line {
                line: line_no,
                message: "non-finite value".into(),
            });
        }
        let q =
            quaternion_from_xyzw([v[4], v[5], v[6], v[7]]).ok_or_else(|| FormatError::Line {
                line: line_no,
                message: "quaternion is not unit".into(),
            })?;
        out.push(StampedPose {
            stamp: v[0],
            pose: Pose3::from_parts(Translation3::new(v[1], v[2], v[3]), q),
        });
    }
    Ok(out)
}

/// Read a TUM trajectory file.
///
/// # Errors
/// [`FormatError::Io`] when the file cannot be read, otherwise as [`parse_tum`].
pub fn read_tum(path: impl AsRef<Path>) -> Result<Vec<StampedPose>, FormatError> {
    let bytes = read_file(path.as_ref())?;
    let text = std::str::from_utf8(&bytes).map_err(|e| FormatError::Byte {
        offset: e.valid_up_to(),
        message: "not UTF-8 text".into(),
    })?;
    parse_tum(text)
}

/// Write a TUM trajectory (full f64 precision, so it reads back exactly).
///
/// # Errors
/// [`FormatError::Stream`] when writing fails.
pub fn write_tum_to(mut w: impl Write, poses: &[StampedPose]) -> Result<(), FormatError> {
    writeln!(w, "{TUM_HEADER}")?;
    for p in poses {
        write_tum_line(&mut w, p)?;
    }
    w.flush()?;
    Ok(())
}

/// The comment line [`write_tum_to`] starts a file with.
pub const TUM_HEADER: &str = "# timestamp tx ty tz qx qy qz qw";

/// Write one pose as a TUM line (full f64 precision), for writers that stream a trajectory
/// pose by pose.
///
/// # Errors
/// [`FormatError::Stream`] when writing fails.
pub fn write_tum_line(mut w: impl Write, pose: &StampedPose) -> Result<(), FormatError> {
    let t = pose.pose.translation.vector;
    let q = quaternion_to_xyzw(&pose.pose.rotation);
    writeln!(
        w,
        "{} {} {} {} {} {} {} {}",
        pose.stamp, t.x, t.y, t.z, q[0], q[1], q[2], q[3]
    )?;
    Ok(())
}

/// Write a TUM trajectory file.
///
/// # Errors
/// [`FormatError::Io`] when the file cannot be created, [`FormatError::Stream`] on write errors.
pub fn write_tum(path: impl AsRef<Path>, poses: &[StampedPose]) -> Result<(), FormatError> {
    write_tum_to(create_file(path.as_ref())?, poses)
}
