//! Recordings on disk: a folder a simulated or real run is written to and read back from.
//!
//! ```text
//! DIR/index.txt          "# spot-nav recording v1", then one line per scan: index stamp cloud-path
//! DIR/calibration.txt    "body_T_lidar tx ty tz qx qy qz qw" (metres, TUM quaternion order)
//! DIR/odometry.tum       odom_T_body per scan (TUM: stamp tx ty tz qx qy qz qw)
//! DIR/ground_truth.tum   world_T_body per scan, optional
//! DIR/clouds/000000.pcd  points in the LiDAR frame (binary PCD with ring and time channels)
//! ```
//!
//! Stamps in the index and in the trajectories must agree line by line; the reader checks it.

use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};

use nalgebra::Translation3;
use slam_core::io::{PcdEncoding, StampedPose, read_pcd, read_tum, write_pcd, write_tum};
use slam_core::{Pose3, quaternion_from_xyzw, quaternion_to_xyzw};

use crate::error::AdapterError;
use crate::sample::Sample;

const INDEX: &str = "index.txt";
const CALIBRATION: &str = "calibration.txt";
const ODOMETRY: &str = "odometry.tum";
const GROUND_TRUTH: &str = "ground_truth.tum";
const CLOUDS: &str = "clouds";
const HEADER: &str = "# spot-nav recording v1";
/// Largest stamp difference (seconds) between the index and a trajectory line.
const STAMP_TOLERANCE: f64 = 1e-6;

/// Writes samples into a recording folder; call [`RecordingWriter::finish`] at the end.
#[derive(Debug)]
pub struct RecordingWriter {
    dir: PathBuf,
    body_t_lidar: Pose3,
    entries: Vec<(f64, String)>,
    odometry: Vec<StampedPose>,
    ground_truth: Vec<StampedPose>,
}

impl RecordingWriter {
    /// Create (or reuse) the folder `dir` for a recording with the LiDAR mounted at
    /// `body_t_lidar`.
    ///
    /// # Errors
    /// [`AdapterError::Io`] when the folders cannot be created.
    pub fn create(dir: impl AsRef<Path>, body_t_lidar: Pose3) -> Result<Self, AdapterError> {
        let dir = dir.as_ref().to_path_buf();
        let clouds = dir.join(CLOUDS);
        fs::create_dir_all(&clouds).map_err(|e| AdapterError::io(&clouds, e))?;
        Ok(Self {
            dir,
            body_t_lidar,
            entries: Vec::new(),
            odometry: Vec::new(),
            ground_truth: Vec::new(),
        })
    }

    /// Write one sample's cloud and keep its poses for [`RecordingWriter::finish`].
    ///
    /// # Errors
    /// [`AdapterError::Recording`] when the sample's mounting differs from the recording's,
    /// its stamp does not increase, or only some samples carry ground truth;
    /// [`AdapterError::Format`] when the cloud cannot be written.
    pub fn write(&mut self, sample: &Sample) -> Result<(), AdapterError> {
        let err = |message: String| AdapterError::Recording {
            path: self.dir.clone(),
            message,
        };
        let d = self.body_t_lidar.inverse() * sample.body_t_lidar;
        if d.translation.vector.norm() > 1e-9 || d.rotation.angle() > 1e-9 {
            return Err(err(format!(
                "sample {} has another body_T_lidar than the recording",
                self.entries.len()
            )));
        }
        if let Some(&(last, _)) = self.entries.last()
            && sample.stamp.partial_cmp(&last) != Some(std::cmp::Ordering::Greater)
        {
            return Err(err(format!(
                "stamp {} does not follow {last}",
                sample.stamp
            )));
        }
        // The first sample decides whether the recording carries ground truth.
        let with_truth = if self.entries.is_empty() {
            sample.ground_truth.is_some()
        } else {
            !self.ground_truth.is_empty()
        };
        if sample.ground_truth.is_some() != with_truth {
            return Err(err(
                "ground truth must be given for all samples or none".into()
            ));
        }
        let name = format!("{CLOUDS}/{:06}.pcd", self.entries.len());
        write_pcd(self.dir.join(&name), &sample.cloud, PcdEncoding::Binary)?;
        self.entries.push((sample.stamp, name));
        self.odometry.push(StampedPose {
            stamp: sample.stamp,
            pose: sample.odom_t_body,
        });
        if let Some(pose) = sample.ground_truth {
            self.ground_truth.push(StampedPose {
                stamp: sample.stamp,
                pose,
            });
        }
        Ok(())
    }

    /// Write the index, the calibration and the trajectories.
    ///
    /// # Errors
    /// [`AdapterError::Io`] or [`AdapterError::Format`] when a file cannot be written.
    pub fn finish(self) -> Result<PathBuf, AdapterError> {
        let mut index = String::from(HEADER);
        index.push_str("\n# index stamp cloud\n");
        for (i, (stamp, name)) in self.entries.iter().enumerate() {
            let _ = writeln!(index, "{i} {stamp} {name}");
        }
        let path = self.dir.join(INDEX);
        fs::write(&path, index).map_err(|e| AdapterError::io(&path, e))?;
        let t = self.body_t_lidar.translation.vector;
        let q = quaternion_to_xyzw(&self.body_t_lidar.rotation);
        let calib = format!(
            "# LiDAR pose in Spot's body frame: tx ty tz qx qy qz qw\nbody_T_lidar {} {} {} {} {} {} {}\n",
            t.x, t.y, t.z, q[0], q[1], q[2], q[3]
        );
        let path = self.dir.join(CALIBRATION);
        fs::write(&path, calib).map_err(|e| AdapterError::io(&path, e))?;
        write_tum(self.dir.join(ODOMETRY), &self.odometry)?;
        if !self.ground_truth.is_empty() {
            write_tum(self.dir.join(GROUND_TRUTH), &self.ground_truth)?;
        }
        Ok(self.dir)
    }
}

/// A recording opened for reading: index, calibration and trajectories are loaded; clouds are
/// read when a sample is asked for.
#[derive(Clone, Debug)]
pub struct Recording {
    dir: PathBuf,
    body_t_lidar: Pose3,
    clouds: Vec<PathBuf>,
    odometry: Vec<StampedPose>,
    ground_truth: Option<Vec<StampedPose>>,
}

fn parse_calibration(path: &Path, text: &str) -> Result<Pose3, AdapterError> {
    let bad = |message: String| AdapterError::Recording {
        path: path.to_path_buf(),
        message,
    };
    let line = text
        .lines()
        .map(str::trim)
        .find(|l| l.starts_with("body_T_lidar"))
        .ok_or_else(|| bad("no body_T_lidar line".into()))?;
    let v: Vec<f64> = line
        .split_whitespace()
        .skip(1)
        .map(str::parse)
        .collect::<Result<_, _>>()
        .map_err(|e| bad(format!("body_T_lidar: {e}")))?;
    if v.len() != 7 || !v.iter().all(|x| x.is_finite()) {
        return Err(bad("body_T_lidar needs 7 finite numbers".into()));
    }
    let q = quaternion_from_xyzw([v[3], v[4], v[5], v[6]])
        .ok_or_else(|| bad("body_T_lidar quaternion is not unit".into()))?;
    Ok(Pose3::from_parts(Translation3::new(v[0], v[1], v[2]), q))
}

impl Recording {
    /// Open the recording in `dir`.
    ///
    /// # Errors
    /// [`AdapterError::Io`] or [`AdapterError::Format`] when a file is missing or malformed,
    /// [`AdapterError::Recording`] when the files disagree (counts, stamps).
    pub fn open(dir: impl AsRef<Path>) -> Result<Self, AdapterError> {
        let dir = dir.as_ref().to_path_buf();
        let read = |name: &str| {
            let path = dir.join(name);
            fs::read_to_string(&path)
                .map(|text| (path.clone(), text))
                .map_err(|e| AdapterError::io(&path, e))
        };
        let (cal_path, cal) = read(CALIBRATION)?;
        let body_t_lidar = parse_calibration(&cal_path, &cal)?;
        let (index_path, index) = read(INDEX)?;
        let bad = |path: &Path, message: String| AdapterError::Recording {
            path: path.to_path_buf(),
            message,
        };
        let mut stamps = Vec::new();
        let mut clouds = Vec::new();
        for (k, line) in index.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let f: Vec<&str> = line.split_whitespace().collect();
            let stamp = match f.as_slice() {
                [_, stamp, _] => stamp.parse::<f64>().ok().filter(|s| s.is_finite()),
                _ => None,
            }
            .ok_or_else(|| {
                bad(
                    &index_path,
                    format!("line {}: expected: index stamp cloud", k + 1),
                )
            })?;
            stamps.push(stamp);
            clouds.push(dir.join(f[2]));
        }
        let check = |path: &Path, poses: &[StampedPose]| {
            if poses.len() != stamps.len() {
                return Err(bad(
                    path,
                    format!("{} poses for {} scans", poses.len(), stamps.len()),
                ));
            }
            for (k, (p, s)) in poses.iter().zip(&stamps).enumerate() {
                if (p.stamp - s).abs() > STAMP_TOLERANCE {
                    return Err(bad(
                        path,
                        format!("pose {k} has stamp {} but scan {k} has {s}", p.stamp),
                    ));
                }
            }
            Ok(())
        };
        let odometry = read_tum(dir.join(ODOMETRY))?;
        check(&dir.join(ODOMETRY), &odometry)?;
        let gt_path = dir.join(GROUND_TRUTH);
        let ground_truth = if gt_path.exists() {
            let gt = read_tum(&gt_path)?;
            check(&gt_path, &gt)?;
            Some(gt)
        } else {
            None
        };
        Ok(Self {
            dir,
            body_t_lidar,
            clouds,
            odometry,
            ground_truth,
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
        self.clouds.len()
    }

    /// Whether the recording has no scan.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.clouds.is_empty()
    }

    /// The LiDAR mounting.
    #[must_use]
    pub fn body_t_lidar(&self) -> Pose3 {
        self.body_t_lidar
    }

    /// The odometry, one pose per scan.
    #[must_use]
    pub fn odometry(&self) -> &[StampedPose] {
        &self.odometry
    }

    /// The ground truth, one pose per scan, when recorded.
    #[must_use]
    pub fn ground_truth(&self) -> Option<&[StampedPose]> {
        self.ground_truth.as_deref()
    }

    /// Sample `i` (its cloud read from disk), `None` past the end.
    ///
    /// # Errors
    /// [`AdapterError::Format`] when the cloud file cannot be read.
    pub fn sample(&self, i: usize) -> Option<Result<Sample, AdapterError>> {
        let path = self.clouds.get(i)?;
        let odom = self.odometry[i];
        Some(
            read_pcd(path)
                .map_err(AdapterError::from)
                .map(|cloud| Sample {
                    stamp: odom.stamp,
                    odom_t_body: odom.pose,
                    body_t_lidar: self.body_t_lidar,
                    cloud,
                    ground_truth: self.ground_truth.as_ref().map(|g| g[i].pose),
                }),
        )
    }

    /// Every sample in order, each cloud read when reached.
    #[must_use]
    pub fn samples(&self) -> impl ExactSizeIterator<Item = Result<Sample, AdapterError>> + '_ {
        (0..self.len()).map(|i| {
            self.sample(i)
                .unwrap_or_else(|| Err(AdapterError::InvalidConfig("index out of range".into())))
        })
    }
}

/// An owning iterator over a recording's samples (from [`Recording::into_iter`]).
#[derive(Clone, Debug)]
pub struct RecordingSamples {
    recording: Recording,
    next: usize,
}

impl Iterator for RecordingSamples {
    type Item = Result<Sample, AdapterError>;

    fn next(&mut self) -> Option<Self::Item> {
        let item = self.recording.sample(self.next)?;
        self.next += 1;
        Some(item)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.recording.len() - self.next;
        (left, Some(left))
    }
}

impl ExactSizeIterator for RecordingSamples {}

impl IntoIterator for Recording {
    type Item = Result<Sample, AdapterError>;
    type IntoIter = RecordingSamples;

    /// Every sample in order, each cloud read when reached; the iterator owns the recording, so
    /// it can be returned or boxed beside a [`SimulatedSpot`](crate::SimulatedSpot).
    fn into_iter(self) -> RecordingSamples {
        RecordingSamples {
            recording: self,
            next: 0,
        }
    }
}
