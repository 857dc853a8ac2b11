//! Writing a recording (see [`recording`](super::recording) for the layout): scan by scan, each
//! file flushed as it goes, so a run of any length writes in bounded memory.

use std::fs::{self, File};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use slam_core::io::{PcdEncoding, StampedPose, TUM_HEADER, write_pcd, write_tum_line};
use slam_core::{FormatError, Pose3};

use super::recording::{
    CALIBRATION, CLOUDS, GROUND_TRUTH, HEADER, INDEX, IndexEntry, ODOMETRY, calibration_text,
};
use crate::record::RecordError;
use crate::robot::Sample;

/// A text file being written line by line.
#[derive(Debug)]
struct LineFile {
    path: PathBuf,
    out: BufWriter<File>,
}

impl LineFile {
    fn create(path: PathBuf, header: &str) -> Result<Self, RecordError> {
        let file = File::create(&path).map_err(|e| RecordError::io(&path, e))?;
        let mut out = BufWriter::new(file);
        writeln!(out, "{header}").map_err(|e| RecordError::io(&path, e))?;
        Ok(Self { path, out })
    }

    fn pose(&mut self, pose: &StampedPose) -> Result<(), RecordError> {
        write_tum_line(&mut self.out, pose).map_err(|e| match e {
            FormatError::Stream(source) => RecordError::io(&self.path, source),
            other => other.into(),
        })
    }

    fn line(&mut self, text: &str) -> Result<(), RecordError> {
        writeln!(self.out, "{text}").map_err(|e| RecordError::io(&self.path, e))
    }

    fn finish(mut self) -> Result<(), RecordError> {
        self.out.flush().map_err(|e| RecordError::io(&self.path, e))
    }
}

/// Writes samples into a recording folder as they come (a cloud file and a line in each
/// trajectory per sample); call [`RecordingWriter::finish`] at the end.
#[derive(Debug)]
pub struct RecordingWriter {
    dir: PathBuf,
    body_t_lidar: Pose3,
    index: LineFile,
    odometry: LineFile,
    ground_truth: Option<LineFile>,
    written: usize,
    last_stamp: Option<f64>,
}

impl RecordingWriter {
    /// Create (or reuse) the folder `dir` for a recording with the LiDAR mounted at
    /// `body_t_lidar`; writes the calibration at once.
    ///
    /// # Errors
    /// [`RecordError::Io`] when the folders or files cannot be created.
    pub fn create(dir: impl AsRef<Path>, body_t_lidar: Pose3) -> Result<Self, RecordError> {
        let dir = dir.as_ref().to_path_buf();
        let clouds = dir.join(CLOUDS);
        fs::create_dir_all(&clouds).map_err(|e| RecordError::io(&clouds, e))?;
        let path = dir.join(CALIBRATION);
        fs::write(&path, calibration_text(&body_t_lidar)).map_err(|e| RecordError::io(&path, e))?;
        // A stale ground truth from an earlier recording in the same folder would disagree.
        let stale = dir.join(GROUND_TRUTH);
        if stale.exists() {
            fs::remove_file(&stale).map_err(|e| RecordError::io(&stale, e))?;
        }
        Ok(Self {
            index: LineFile::create(dir.join(INDEX), &format!("{HEADER}\n# index stamp cloud"))?,
            odometry: LineFile::create(dir.join(ODOMETRY), TUM_HEADER)?,
            ground_truth: None,
            dir,
            body_t_lidar,
            written: 0,
            last_stamp: None,
        })
    }

    /// Write one sample: its cloud file, its index line and its poses.
    ///
    /// # Errors
    /// [`RecordError::MountingChanged`] when the sample's mounting differs from the recording's,
    /// [`RecordError::StampNotIncreasing`] when its stamp does not increase,
    /// [`RecordError::PartialGroundTruth`] when only some samples carry ground truth;
    /// [`RecordError::Format`] or [`RecordError::Io`] when a file cannot be written.
    pub fn write(&mut self, sample: &Sample) -> Result<(), RecordError> {
        let path = || self.dir.clone();
        let d = self.body_t_lidar.inverse() * sample.body_t_lidar;
        if d.translation.vector.norm() > 1e-9 || d.rotation.angle() > 1e-9 {
            return Err(RecordError::MountingChanged {
                path: path(),
                sample: self.written,
            });
        }
        if let Some(last) = self.last_stamp
            && sample.stamp.partial_cmp(&last) != Some(std::cmp::Ordering::Greater)
        {
            return Err(RecordError::StampNotIncreasing {
                path: path(),
                stamp: sample.stamp,
                last,
            });
        }
        // The first sample decides whether the recording carries ground truth.
        if self.written == 0 && sample.ground_truth.is_some() {
            self.ground_truth = Some(LineFile::create(self.dir.join(GROUND_TRUTH), TUM_HEADER)?);
        }
        if sample.ground_truth.is_some() != self.ground_truth.is_some() {
            return Err(RecordError::PartialGroundTruth {
                path: path(),
                sample: self.written,
            });
        }
        let entry = IndexEntry {
            index: self.written as u64,
            stamp: sample.stamp,
            cloud: PathBuf::from(format!("{CLOUDS}/{:06}.pcd", self.written)),
        };
        write_pcd(
            self.dir.join(&entry.cloud),
            &sample.cloud,
            PcdEncoding::Binary,
        )?;
        self.index.line(&entry.to_line())?;
        self.odometry.pose(&StampedPose {
            stamp: sample.stamp,
            pose: sample.odom_t_body,
        })?;
        if let (Some(file), Some(pose)) = (&mut self.ground_truth, sample.ground_truth) {
            file.pose(&StampedPose {
                stamp: sample.stamp,
                pose,
            })?;
        }
        self.written += 1;
        self.last_stamp = Some(sample.stamp);
        Ok(())
    }

    /// Flush the index and the trajectories; returns the folder.
    ///
    /// # Errors
    /// [`RecordError::Io`] when a file cannot be written.
    pub fn finish(self) -> Result<PathBuf, RecordError> {
        self.index.finish()?;
        self.odometry.finish()?;
        if let Some(gt) = self.ground_truth {
            gt.finish()?;
        }
        Ok(self.dir)
    }
}
