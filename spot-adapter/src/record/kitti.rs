//! KITTI-style sequence folders, so the pipeline runs on public data:
//!
//! ```text
//! DIR/velodyne/000000.bin   scans (float32 x y z reflectance), sorted by name
//! DIR/poses.txt             optional: ground truth, one 3x4 [R|t] per scan (world_T_cam0)
//! DIR/times.txt             optional: one stamp (seconds) per scan; else 10 Hz from 0
//! DIR/calib.txt             optional: a "Tr:" line, the LiDAR pose in the camera frame
//! ```
//!
//! KITTI's poses are those of the left camera, so the camera is the "body" here and `Tr` its
//! `body_T_lidar` (identity without `calib.txt`). KITTI has no robot odometry: `odom_T_body` is
//! either the identity for every scan (the engine then predicts no motion) or, on request, the
//! ground truth itself (for checking the mapping half alone).

use std::path::{Path, PathBuf};

use slam_core::Pose3;
use slam_core::io::{parse_kitti_bin, parse_kitti_poses};

use super::bounded_file::{MAX_RECORDING_FILE_BYTES, read_bounded, read_bounded_text};
use crate::record::RecordError;
use crate::record::folder_files::sorted_files;
use crate::robot::Sample;

/// Where a KITTI sequence's odometry comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum KittiOdometry {
    /// The identity for every scan: no odometry.
    #[default]
    None,
    /// The ground-truth poses (requires `poses.txt`).
    GroundTruth,
}

/// A KITTI-style sequence folder.
#[derive(Clone, Debug)]
pub struct KittiSequence {
    scans: Vec<PathBuf>,
    stamps: Vec<f64>,
    poses: Option<Vec<Pose3>>,
    body_t_lidar: Pose3,
    odometry: KittiOdometry,
}

fn read_text(path: &Path) -> Result<String, RecordError> {
    read_bounded_text(path, MAX_RECORDING_FILE_BYTES)
}

/// The `Tr:` line of a KITTI `calib.txt` as a pose.
fn parse_calib(path: &Path, text: &str) -> Result<Option<Pose3>, RecordError> {
    let Some(line) = text.lines().find_map(|l| l.trim().strip_prefix("Tr:")) else {
        return Ok(None);
    };
    // The pose reader checks and re-orthonormalises the rotation.
    let pose = parse_kitti_poses(line)?
        .pop()
        .ok_or_else(|| RecordError::EmptyTrLine {
            path: path.to_path_buf(),
        })?;
    Ok(Some(pose))
}

impl KittiSequence {
    /// Open the sequence in `dir`.
    ///
    /// # Errors
    /// [`RecordError::Io`] without a readable `velodyne` folder, [`RecordError::Format`] for
    /// malformed pose or calibration files, [`RecordError::NonFiniteTime`] for a malformed
    /// time, [`RecordError::EmptyTrLine`] for a calibration without numbers,
    /// [`RecordError::CountMismatch`] when the counts of scans, poses and times differ and
    /// [`RecordError::NoGroundTruth`] when `GroundTruth` odometry is asked for without poses.
    pub fn open(dir: impl AsRef<Path>, odometry: KittiOdometry) -> Result<Self, RecordError> {
        let dir = dir.as_ref();
        let velodyne = dir.join("velodyne");
        let scans = sorted_files(&velodyne, |p| p.extension().is_some_and(|x| x == "bin"))?;
        let poses_path = dir.join("poses.txt");
        let poses = if poses_path.exists() {
            let p = parse_kitti_poses(&read_text(&poses_path)?)?;
            if p.len() != scans.len() {
                return Err(RecordError::CountMismatch {
                    path: poses_path,
                    found: p.len(),
                    what: "poses",
                    scans: scans.len(),
                });
            }
            Some(p)
        } else {
            None
        };
        let times_path = dir.join("times.txt");
        let stamps = if times_path.exists() {
            let text = read_text(&times_path)?;
            let t: Vec<f64> = text
                .split_whitespace()
                .map(|v| v.parse::<f64>().ok().filter(|x| x.is_finite()))
                .collect::<Option<_>>()
                .ok_or_else(|| RecordError::NonFiniteTime {
                    path: times_path.clone(),
                })?;
            if t.len() != scans.len() {
                return Err(RecordError::CountMismatch {
                    path: times_path,
                    found: t.len(),
                    what: "times",
                    scans: scans.len(),
                });
            }
            t
        } else {
            (0..scans.len()).map(|i| i as f64 * 0.1).collect()
        };
        let calib_path = dir.join("calib.txt");
        let body_t_lidar = if calib_path.exists() {
            parse_calib(&calib_path, &read_text(&calib_path)?)?.unwrap_or_else(Pose3::identity)
        } else {
            Pose3::identity()
        };
        if odometry == KittiOdometry::GroundTruth && poses.is_none() {
            return Err(RecordError::NoGroundTruth { path: poses_path });
        }
        Ok(Self {
            scans,
            stamps,
            poses,
            body_t_lidar,
            odometry,
        })
    }

    /// Number of scans.
    #[must_use]
    pub fn len(&self) -> usize {
        self.scans.len()
    }

    /// Whether the sequence has no scan.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.scans.is_empty()
    }

    /// The LiDAR pose in the camera ("body") frame.
    #[must_use]
    pub fn body_t_lidar(&self) -> Pose3 {
        self.body_t_lidar
    }

    /// Ground-truth poses (`world_T_cam0`), when the folder has them.
    #[must_use]
    pub fn poses(&self) -> Option<&[Pose3]> {
        self.poses.as_deref()
    }

    /// Scan stamps (seconds).
    #[must_use]
    pub fn stamps(&self) -> &[f64] {
        &self.stamps
    }

    /// Sample `i` (its scan read from disk), `None` past the end.
    ///
    /// # Errors
    /// [`RecordError::Format`] when the scan cannot be read.
    pub fn sample(&self, i: usize) -> Option<Result<Sample, RecordError>> {
        let path = self.scans.get(i)?;
        let gt = self.poses.as_ref().map(|p| p[i]);
        let odom_t_body = match self.odometry {
            KittiOdometry::GroundTruth => gt.unwrap_or_else(Pose3::identity),
            KittiOdometry::None => Pose3::identity(),
        };
        Some(
            read_bounded(path, MAX_RECORDING_FILE_BYTES)
                .and_then(|bytes| Ok(parse_kitti_bin(&bytes)?))
                .map(|cloud| Sample {
                    stamp: self.stamps[i],
                    odom_t_body,
                    body_t_lidar: self.body_t_lidar,
                    cloud,
                    ground_truth: gt,
                    gyro_orientation: None,
                }),
        )
    }

    /// Every sample in order, each scan read when reached.
    #[must_use]
    pub fn samples(&self) -> KittiSamples {
        self.clone().into_iter()
    }
}

/// A KITTI sequence's samples read one scan at a time (from [`KittiSequence::into_iter`]).
#[derive(Clone, Debug)]
pub struct KittiSamples {
    sequence: KittiSequence,
    next: usize,
}

impl Iterator for KittiSamples {
    type Item = Result<Sample, RecordError>;

    fn next(&mut self) -> Option<Self::Item> {
        let item = self.sequence.sample(self.next)?;
        self.next += 1;
        Some(item)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.sequence.len() - self.next;
        (left, Some(left))
    }
}

impl ExactSizeIterator for KittiSamples {}

impl IntoIterator for KittiSequence {
    type Item = Result<Sample, RecordError>;
    type IntoIter = KittiSamples;

    fn into_iter(self) -> KittiSamples {
        KittiSamples {
            sequence: self,
            next: 0,
        }
    }
}
