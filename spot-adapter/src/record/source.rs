//! Any recording opened from its path, the kind detected from what the path is: a `.mcap` or
//! `.bag` file, a ROS 2 bag folder (`metadata.yaml` beside one `.mcap`), a spot-nav recording
//! (`index.txt`), a KITTI sequence (`velodyne/`), or a folder of PCD or PLY scans. Each comes
//! out as a [`SampleSource`] with no-return points removed and counted.

use std::path::{Path, PathBuf};

use slam_core::Pose3;
use slam_core::io::StampedPose;

use crate::record::RecordError;
use crate::record::bag::{Bag, BagConfig};
use crate::record::bag_file::BagFormat;
use crate::record::bag_samples::BagSamples;
use crate::record::cloud_folder::{
    CloudFolder, CloudFolderConfig, CloudFolderSamples, is_cloud_folder,
};
use crate::record::kitti::{KittiOdometry, KittiSequence};
use crate::record::no_return::{DroppedPoints, ReturnFilter};
use crate::record::recording::Recording;
use crate::robot::Sample;

/// A stream of samples from a recording, with the points its reader removed. `Send`, so that
/// it can be read ahead on a thread of its own ([`ReadAhead`](crate::record::ReadAhead)).
pub trait SampleSource: ExactSizeIterator<Item = Result<Sample, RecordError>> + Send {
    /// Points removed from the samples read so far (non-finite and no-return).
    fn dropped_points(&self) -> DroppedPoints;
}

impl SampleSource for BagSamples {
    fn dropped_points(&self) -> DroppedPoints {
        BagSamples::dropped_points(self)
    }
}

impl SampleSource for CloudFolderSamples {
    fn dropped_points(&self) -> DroppedPoints {
        CloudFolderSamples::dropped_points(self)
    }
}

impl SampleSource for Box<dyn SampleSource> {
    fn dropped_points(&self) -> DroppedPoints {
        (**self).dropped_points()
    }
}

/// Any sample iterator with no-return and non-finite points removed from its clouds.
#[derive(Clone, Debug)]
pub struct ReturnFiltered<I> {
    samples: I,
    filter: ReturnFilter,
    dropped: DroppedPoints,
}

impl<I> ReturnFiltered<I> {
    /// `samples` filtered by `filter`.
    pub fn new(samples: I, filter: ReturnFilter) -> Self {
        Self {
            samples,
            filter,
            dropped: DroppedPoints::default(),
        }
    }
}

impl<I: Iterator<Item = Result<Sample, RecordError>>> Iterator for ReturnFiltered<I> {
    type Item = Result<Sample, RecordError>;

    fn next(&mut self) -> Option<Self::Item> {
        Some(self.samples.next()?.map(|mut s| {
            let (cloud, dropped) = self.filter.apply(std::mem::take(&mut s.cloud));
            self.dropped.add(dropped);
            s.cloud = cloud;
            s
        }))
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        self.samples.size_hint()
    }
}

impl<I: ExactSizeIterator<Item = Result<Sample, RecordError>>> ExactSizeIterator
    for ReturnFiltered<I>
{
}

impl<I: ExactSizeIterator<Item = Result<Sample, RecordError>> + Send> SampleSource
    for ReturnFiltered<I>
{
    fn dropped_points(&self) -> DroppedPoints {
        self.dropped
    }
}

/// What kind of recording a path is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RecordingKind {
    /// A ROS 1 bag or a ROS 2 MCAP bag.
    Bag(BagFormat),
    /// A spot-nav recording folder.
    SpotNav,
    /// A KITTI odometry sequence.
    Kitti,
    /// A folder of PCD or PLY scans.
    CloudFolder,
}

/// The kind of recording at `path`, and the file or folder to open (a ROS 2 bag folder's
/// `.mcap`).
///
/// # Errors
/// [`RecordError::NotFound`] for a path that is no file or folder, [`RecordError::NotABag`]
/// for a file that is not `.mcap` or `.bag`, [`RecordError::NoMcapFile`] or
/// [`RecordError::SplitMcap`] for a ROS 2 bag folder without one `.mcap`, and
/// [`RecordError::UnknownKind`] for a folder of none of the kinds.
pub fn detect(path: &Path) -> Result<(RecordingKind, PathBuf), RecordError> {
    let path_buf = || path.to_path_buf();
    if path.is_file() {
        return BagFormat::from_path(path)
            .map(|f| (RecordingKind::Bag(f), path.to_path_buf()))
            .ok_or_else(|| RecordError::NotABag { path: path_buf() });
    }
    if !path.is_dir() {
        return Err(RecordError::NotFound { path: path_buf() });
    }
    if path.join("index.txt").is_file() {
        return Ok((RecordingKind::SpotNav, path.to_path_buf()));
    }
    if path.join("velodyne").is_dir() {
        return Ok((RecordingKind::Kitti, path.to_path_buf()));
    }
    if path.join("metadata.yaml").is_file() {
        let mut mcaps: Vec<PathBuf> = std::fs::read_dir(path)
            .map_err(|e| RecordError::io(path, e))?
            .filter_map(Result::ok)
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|x| x == "mcap"))
            .collect();
        mcaps.sort();
        return match mcaps.as_slice() {
            [one] => Ok((RecordingKind::Bag(BagFormat::Mcap), one.clone())),
            [] => Err(RecordError::NoMcapFile { path: path_buf() }),
            many => Err(RecordError::SplitMcap {
                path: path_buf(),
                files: many.len(),
            }),
        };
    }
    if is_cloud_folder(path) {
        return Ok((RecordingKind::CloudFolder, path.to_path_buf()));
    }
    Err(RecordError::UnknownKind { path: path_buf() })
}

/// How to open a recording; each field applies to the kinds that name it.
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct SourceConfig {
    /// Bags: topics, frames and cloud decoding (its return filter is used by every kind).
    pub bag: BagConfig,
    /// Cloud folders: the LiDAR mounting.
    pub body_t_lidar: Option<Pose3>,
    /// Cloud folders: a TUM odometry file.
    pub odometry: Option<PathBuf>,
}

/// A recording opened: its samples and what is known about it.
pub struct OpenedSource {
    /// What kind it is.
    pub kind: RecordingKind,
    /// What was found, in a few lines (topics, counts, duration, layout, frames).
    pub description: String,
    /// The LiDAR mounting.
    pub body_t_lidar: Pose3,
    /// Whether the samples carry odometry; without, their `odom_T_body` is the identity: feed
    /// them with [`Sample::lidar_only_input`](crate::robot::Sample::lidar_only_input).
    pub has_odometry: bool,
    /// `world_T_body` per scan when the recording has ground truth.
    pub ground_truth: Option<Vec<StampedPose>>,
    /// The samples.
    pub samples: Box<dyn SampleSource>,
}

impl std::fmt::Debug for OpenedSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("OpenedSource")
            .field("kind", &self.kind)
            .field("description", &self.description)
            .field("has_odometry", &self.has_odometry)
            .finish_non_exhaustive()
    }
}

/// Open the recording at `path`, whatever its kind.
///
/// # Errors
/// As [`detect`] and the kind's reader.
pub fn open_recording(path: &Path, config: &SourceConfig) -> Result<OpenedSource, RecordError> {
    let (kind, path) = detect(path)?;
    let returns = config.bag.cloud.returns;
    Ok(match kind {
        RecordingKind::Bag(_) => {
            let bag = Bag::open(&path, &config.bag)?;
            OpenedSource {
                kind,
                description: bag.summary().to_string(),
                body_t_lidar: bag.body_t_lidar(),
                has_odometry: bag.has_odometry(),
                ground_truth: None,
                samples: Box::new(bag.samples()?),
            }
        }
        RecordingKind::SpotNav => {
            let rec = Recording::open(&path)?;
            OpenedSource {
                kind,
                description: format!(
                    "recording {} (spot-nav): {} scans{}",
                    path.display(),
                    rec.len(),
                    if rec.has_ground_truth() {
                        ", ground truth"
                    } else {
                        ""
                    }
                ),
                body_t_lidar: rec.body_t_lidar(),
                has_odometry: true,
                ground_truth: rec.read_ground_truth()?,
                samples: Box::new(ReturnFiltered::new(rec.into_iter(), returns)),
            }
        }
        RecordingKind::Kitti => {
            let seq = KittiSequence::open(&path, KittiOdometry::None)?;
            let ground_truth = seq.poses().map(|p| {
                p.iter()
                    .zip(seq.stamps())
                    .map(|(&pose, &stamp)| StampedPose { stamp, pose })
                    .collect()
            });
            OpenedSource {
                kind,
                description: format!(
                    "KITTI sequence {}: {} scans over {:.1} s{}",
                    path.display(),
                    seq.len(),
                    seq.stamps().last().unwrap_or(&0.0) - seq.stamps().first().unwrap_or(&0.0),
                    if ground_truth.is_some() {
                        ", poses.txt as ground truth"
                    } else {
                        ""
                    }
                ),
                body_t_lidar: seq.body_t_lidar(),
                has_odometry: false,
                ground_truth,
                samples: Box::new(ReturnFiltered::new(seq.into_iter(), returns)),
            }
        }
        RecordingKind::CloudFolder => {
            let folder = CloudFolder::open(
                &path,
                &CloudFolderConfig {
                    body_t_lidar: config.body_t_lidar,
                    odometry: config.odometry.clone(),
                    returns,
                },
            )?;
            let stamps = folder.stamps();
            OpenedSource {
                kind,
                description: format!(
                    "cloud folder {}: {} scans over {:.1} s, {}",
                    path.display(),
                    folder.len(),
                    stamps.last().unwrap_or(&0.0) - stamps.first().unwrap_or(&0.0),
                    if folder.has_odometry() {
                        "odometry from the TUM file"
                    } else {
                        "no odometry (LiDAR-only)"
                    }
                ),
                body_t_lidar: folder.body_t_lidar(),
                has_odometry: folder.has_odometry(),
                ground_truth: None,
                samples: Box::new(folder.samples()),
            }
        }
    })
}
