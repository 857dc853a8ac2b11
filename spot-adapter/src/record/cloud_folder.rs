//! A folder of PCD or PLY scans, one file per scan, sorted by name:
//!
//! ```text
//! DIR/1503604882.703390000.pcd   a scan; a name that is a number is its stamp (seconds)
//! DIR/...
//! ODOMETRY.tum                   optional (given by argument): odom_T_body, TUM format
//! ```
//!
//! Stamps come from the file names when every name is a number (and the scans are then taken
//! in stamp order), else from the odometry file
//! (one line per scan), else 10 Hz from 0. With the names as stamps, the odometry is
//! interpolated at each scan's stamp; otherwise its lines are taken in order. The LiDAR mounting
//! is given by argument (identity by default). A per-point time is taken in seconds since the
//! scan's start, or in nanoseconds (Ouster's PCDs) when that is what fits one scan period.
//! Without odometry every `odom_T_body` is the
//! identity: feed them to the engine with
//! [`Sample::lidar_only_input`](crate::robot::Sample::lidar_only_input) for a LiDAR-only run.

use std::fs;
use std::path::{Path, PathBuf};

use slam_core::Pose3;
use slam_core::io::read_tum;

use crate::record::RecordError;
use crate::record::folder_files::sorted_files;
use crate::record::frame_tree::PoseSeries;
use crate::record::no_return::{DroppedPoints, ReturnFilter};
use crate::record::time_unit::TimeUnitInference;
use crate::robot::Sample;

/// Seconds between scans when nothing gives their stamps.
const DEFAULT_PERIOD: f64 = 0.1;

/// How to read a cloud folder.
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct CloudFolderConfig {
    /// The LiDAR mounting (`body_T_lidar`); identity when the scans are the body's.
    pub body_t_lidar: Option<Pose3>,
    /// A TUM file of `odom_T_body`.
    pub odometry: Option<PathBuf>,
    /// Which points are returns.
    pub returns: ReturnFilter,
}

/// A folder of PCD or PLY scans.
#[derive(Clone, Debug)]
pub struct CloudFolder {
    dir: PathBuf,
    scans: Vec<PathBuf>,
    stamps: Vec<f64>,
    odometry: Option<Vec<Pose3>>,
    body_t_lidar: Pose3,
    returns: ReturnFilter,
}

/// Whether `dir` holds PCD or PLY files (and is no spot-nav recording or KITTI sequence).
#[must_use]
pub fn is_cloud_folder(dir: &Path) -> bool {
    fs::read_dir(dir).is_ok_and(|entries| {
        entries
            .filter_map(Result::ok)
            .any(|e| is_cloud_file(&e.path()))
    })
}

fn is_cloud_file(path: &Path) -> bool {
    path.is_file()
        && path
            .extension()
            .and_then(|x| x.to_str())
            .is_some_and(|x| x.eq_ignore_ascii_case("pcd") || x.eq_ignore_ascii_case("ply"))
}

impl CloudFolder {
    /// Open the folder `dir`.
    ///
    /// # Errors
    /// [`RecordError::Io`] for an unreadable folder, [`RecordError::NoScans`] when it holds
    /// no PCD or PLY file, [`RecordError::NoOdometryAt`] when the odometry does not cover every
    /// scan's stamp, [`RecordError::CountMismatch`] when (without stamps in the names) it has
    /// another count of lines; [`RecordError::Format`] for a malformed TUM file.
    pub fn open(dir: impl AsRef<Path>, config: &CloudFolderConfig) -> Result<Self, RecordError> {
        let dir = dir.as_ref().to_path_buf();
        let mut scans = sorted_files(&dir, is_cloud_file)?;
        if scans.is_empty() {
            return Err(RecordError::NoScans { path: dir });
        }
        let stamp_of = |p: &PathBuf| {
            p.file_stem()?
                .to_str()?
                .parse::<f64>()
                .ok()
                .filter(|t| t.is_finite())
        };
        // Names that are stamps sort by their value ("100.pcd" before "100.1.pcd").
        let named: Option<Vec<f64>> = scans.iter().map(stamp_of).collect();
        let named = named.and_then(|_| {
            scans.sort_by(|a, b| {
                stamp_of(a)
                    .partial_cmp(&stamp_of(b))
                    .unwrap_or(std::cmp::Ordering::Equal)
            });
            let t: Vec<f64> = scans.iter().filter_map(stamp_of).collect();
            t.windows(2).all(|w| w[1] > w[0]).then_some(t)
        });
        let tum = match &config.odometry {
            Some(path) => Some((path, read_tum(path)?)),
            None => None,
        };
        let (stamps, odometry) = match (named, tum) {
            (Some(stamps), Some((path, poses))) => {
                let mut series = PoseSeries::default();
                for p in &poses {
                    series.push(p.stamp, p.pose);
                }
                let odometry = stamps
                    .iter()
                    .map(|&t| {
                        series.at(t).ok_or_else(|| RecordError::NoOdometryAt {
                            path: path.clone(),
                            stamp: t,
                        })
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                (stamps, Some(odometry))
            }
            (None, Some((path, poses))) => {
                if poses.len() != scans.len() {
                    return Err(RecordError::CountMismatch {
                        path: path.clone(),
                        found: poses.len(),
                        what: "poses",
                        scans: scans.len(),
                    });
                }
                (
                    poses.iter().map(|p| p.stamp).collect(),
                    Some(poses.iter().map(|p| p.pose).collect()),
                )
            }
            (Some(stamps), None) => (stamps, None),
            (None, None) => (
                (0..scans.len())
                    .map(|i| i as f64 * DEFAULT_PERIOD)
                    .collect(),
                None,
            ),
        };
        Ok(Self {
            dir,
            scans,
            stamps,
            odometry,
            body_t_lidar: config.body_t_lidar.unwrap_or_else(Pose3::identity),
            returns: config.returns,
        })
    }

    /// The folder.
    #[must_use]
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Number of scans.
    #[must_use]
    pub fn len(&self) -> usize {
        self.scans.len()
    }

    /// Whether there is no scan (never: opening needs one).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.scans.is_empty()
    }

    /// Scan stamps (seconds).
    #[must_use]
    pub fn stamps(&self) -> &[f64] {
        &self.stamps
    }

    /// Whether the samples carry odometry.
    #[must_use]
    pub fn has_odometry(&self) -> bool {
        self.odometry.is_some()
    }

    /// The LiDAR mounting.
    #[must_use]
    pub fn body_t_lidar(&self) -> Pose3 {
        self.body_t_lidar
    }

    /// Every sample in order, each scan read when reached.
    #[must_use]
    pub fn samples(&self) -> CloudFolderSamples {
        CloudFolderSamples {
            folder: self.clone(),
            next: 0,
            dropped: DroppedPoints::default(),
            times: TimeUnitInference::default(),
        }
    }
}

/// A cloud folder's samples, read one file at a time.
#[derive(Clone, Debug)]
pub struct CloudFolderSamples {
    folder: CloudFolder,
    next: usize,
    dropped: DroppedPoints,
    /// Decides the per-point time unit (seconds or Ouster's nanoseconds) once.
    times: TimeUnitInference,
}

impl CloudFolderSamples {
    /// Points removed from the scans read so far.
    #[must_use]
    pub fn dropped_points(&self) -> DroppedPoints {
        self.dropped
    }
}

impl Iterator for CloudFolderSamples {
    type Item = Result<Sample, RecordError>;

    fn next(&mut self) -> Option<Self::Item> {
        let i = self.next;
        let path = self.folder.scans.get(i)?;
        self.next += 1;
        let f = &self.folder;
        let cloud = match slam_core::io::read_cloud(path) {
            Ok(c) => c,
            Err(e) => return Some(Err(e.into())),
        };
        let cloud = match self.times.times_in_seconds(cloud) {
            Ok(c) => c,
            Err(e) => {
                return Some(Err(RecordError::ScanTimes {
                    path: path.clone(),
                    source: e,
                }));
            }
        };
        let (cloud, dropped) = f.returns.apply(cloud);
        self.dropped.add(dropped);
        Some(Ok(Sample {
            stamp: f.stamps[i],
            odom_t_body: f.odometry.as_ref().map_or_else(Pose3::identity, |o| o[i]),
            body_t_lidar: f.body_t_lidar,
            cloud,
            ground_truth: None,
            gyro_orientation: None,
        }))
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.folder.len() - self.next;
        (left, Some(left))
    }
}

impl ExactSizeIterator for CloudFolderSamples {}
