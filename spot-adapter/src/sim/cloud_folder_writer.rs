//! A run written as a folder of scans that any tool reads (KISS-ICP, `Open3D`, `CloudCompare`, and
//! spot-nav's own cloud-folder reader):
//!
//! ```text
//! DIR/000000.000000000.ply   one sample: points in the LiDAR frame, x y z float32 and time
//!                            float32 (seconds since the stamp); named by its stamp (seconds)
//! DIR/...
//! DIR/ground_truth.tum       world_T_lidar at each stamp (TUM), when the samples carry it
//! DIR/odometry.tum           odom_T_lidar at each stamp (TUM): the robot's odometry carried to
//!                            the LiDAR
//! ```
//!
//! The trajectories are of the LiDAR, so a reader that takes the folder with no calibration
//! (body = LiDAR) compares its estimate with `ground_truth.tum` directly. Names are zero-padded
//! so that sorting them as text sorts them by stamp; readers that pick `.ply`/`.pcd` files skip
//! the two TUM files.

use std::fs;
use std::path::{Path, PathBuf};

use slam_core::PointCloud;
use slam_core::io::{PcdEncoding, PlyEncoding, StampedPose, write_pcd, write_ply, write_tum};

use crate::record::RecordError;
use crate::record::is_cloud_folder;
use crate::robot::Sample;
use crate::sim::SimError;

/// The LiDAR's true trajectory in a cloud folder.
pub const CLOUD_FOLDER_GROUND_TRUTH: &str = "ground_truth.tum";
/// The odometry, carried to the LiDAR, in a cloud folder.
pub const CLOUD_FOLDER_ODOMETRY: &str = "odometry.tum";

/// The file format of each scan.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum CloudFormat {
    /// Binary little-endian PLY, properties `x y z time` (all float).
    #[default]
    Ply,
    /// Binary PCD v0.7, fields `x y z t` (all float).
    Pcd,
}

impl CloudFormat {
    /// The file extension, without the dot.
    #[must_use]
    pub fn extension(self) -> &'static str {
        match self {
            Self::Ply => "ply",
            Self::Pcd => "pcd",
        }
    }
}

/// Writes samples into a cloud folder as they come (one scan file each); call
/// [`CloudFolderWriter::finish`] at the end to write the trajectories.
///
/// ```
/// use spot_adapter::record::{CloudFolder, CloudFolderConfig};
/// use spot_adapter::sim::{CloudFolderWriter, CloudFormat, SimulatedSpot, SimulationConfig};
///
/// let dir = std::env::temp_dir().join(format!("cloud-folder-doc-{}", std::process::id()));
/// let mut writer = CloudFolderWriter::create(&dir, CloudFormat::Ply)?;
/// for sample in SimulatedSpot::corridor_loop(&SimulationConfig::default())?.take(2) {
///     writer.write(&sample)?;
/// }
/// writer.finish()?;
/// let folder = CloudFolder::open(&dir, &CloudFolderConfig::default())?;
/// assert_eq!(folder.stamps(), [0.0, 0.2]);
/// # std::fs::remove_dir_all(&dir).ok();
/// # Ok::<(), spot_adapter::sim::SimError>(())
/// ```
#[derive(Debug)]
pub struct CloudFolderWriter {
    dir: PathBuf,
    format: CloudFormat,
    ground_truth: Vec<StampedPose>,
    odometry: Vec<StampedPose>,
    written: usize,
}

impl CloudFolderWriter {
    /// Create the folder `dir` (or take an empty or scan-free one).
    ///
    /// # Errors
    /// [`SimError::Record`] with [`RecordError::Io`] when the folder cannot be created, or
    /// [`RecordError::FolderHoldsScans`] when it already holds PLY or PCD files (they would be
    /// read as scans of this run).
    pub fn create(dir: impl AsRef<Path>, format: CloudFormat) -> Result<Self, SimError> {
        let dir = dir.as_ref().to_path_buf();
        if is_cloud_folder(&dir) {
            return Err(RecordError::FolderHoldsScans { path: dir }.into());
        }
        fs::create_dir_all(&dir).map_err(|e| RecordError::io(&dir, e))?;
        Ok(Self {
            dir,
            format,
            ground_truth: Vec::new(),
            odometry: Vec::new(),
            written: 0,
        })
    }

    /// Write one sample's scan; its poses are kept for [`CloudFolderWriter::finish`].
    ///
    /// # Errors
    /// [`SimError::Record`] with [`RecordError::StampNotIncreasing`] when its stamp (to the
    /// nanosecond, as its file is named) does not follow the last one,
    /// [`RecordError::StampNotANumber`] when it is not a number, or
    /// [`RecordError::PartialGroundTruth`] when only some samples carry ground truth;
    /// [`SimError::Record`] with [`RecordError::Format`] when the scan cannot be written.
    pub fn write(&mut self, sample: &Sample) -> Result<(), SimError> {
        let name = format!("{:016.9}", sample.stamp);
        // The stamp a reader takes from the name, so the trajectories agree with it exactly.
        let stamp: f64 = name.parse().map_err(|_| RecordError::StampNotANumber {
            path: self.dir.clone(),
            stamp: sample.stamp,
        })?;
        if let Some(last) = self.odometry.last().filter(|last| stamp <= last.stamp) {
            return Err(RecordError::StampNotIncreasing {
                path: self.dir.clone(),
                stamp,
                last: last.stamp,
            }
            .into());
        }
        if sample.ground_truth.is_some() != (self.ground_truth.len() == self.written) {
            return Err(RecordError::PartialGroundTruth {
                path: self.dir.clone(),
                sample: self.written,
            }
            .into());
        }
        let cloud = plain(&sample.cloud);
        let path = self.dir.join(format!("{name}.{}", self.format.extension()));
        match self.format {
            CloudFormat::Ply => write_ply(&path, &cloud, PlyEncoding::BinaryLittleEndian),
            CloudFormat::Pcd => write_pcd(&path, &cloud, PcdEncoding::Binary),
        }
        .map_err(RecordError::from)?;
        self.odometry.push(StampedPose {
            stamp,
            pose: sample.odom_t_body * sample.body_t_lidar,
        });
        if let Some(world_t_body) = sample.ground_truth {
            self.ground_truth.push(StampedPose {
                stamp,
                pose: world_t_body * sample.body_t_lidar,
            });
        }
        self.written += 1;
        Ok(())
    }

    /// Write the trajectories and return the folder.
    ///
    /// # Errors
    /// [`SimError::Record`] with [`RecordError::Format`] when a trajectory file cannot be
    /// written.
    pub fn finish(self) -> Result<PathBuf, SimError> {
        write_tum(self.dir.join(CLOUD_FOLDER_ODOMETRY), &self.odometry)
            .map_err(RecordError::from)?;
        if !self.ground_truth.is_empty() {
            write_tum(self.dir.join(CLOUD_FOLDER_GROUND_TRUTH), &self.ground_truth)
                .map_err(RecordError::from)?;
        }
        Ok(self.dir)
    }
}

/// `cloud` with only the channels every reader takes: the points and their times.
fn plain(cloud: &PointCloud) -> PointCloud {
    let points = PointCloud::from_points(cloud.points().to_vec());
    match cloud.time() {
        // The channel has one time per point by construction, so this never falls back.
        Some(time) => points.with_time(time.to_vec()).unwrap_or_default(),
        None => points,
    }
}
