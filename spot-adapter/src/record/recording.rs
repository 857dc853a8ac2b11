//! Recordings on disk: a folder a simulated or real run is written to and read back from,
//! scan by scan in both directions, so memory does not grow with the run's length.
//!
//! ```text
//! DIR/index.txt          "# spot-nav recording v1", then one line per scan: index stamp cloud-path
//! DIR/calibration.txt    "body_T_lidar tx ty tz qx qy qz qw" (metres, TUM quaternion order)
//! DIR/odometry.tum       odom_T_body per scan (TUM: stamp tx ty tz qx qy qz qw)
//! DIR/ground_truth.tum   world_T_body per scan, optional
//! DIR/clouds/000000.pcd  points in the LiDAR frame (binary PCD with ring and time channels)
//! ```
//!
//! Stamps in the index and in the trajectories must agree line by line, and cloud paths must
//! lie inside the folder; the reader checks both. Every file read must be a regular file of at
//! most [`MAX_RECORDING_FILE_BYTES`](super::MAX_RECORDING_FILE_BYTES) (a link to `/dev/zero` is
//! refused). [`parse_index`] and [`parse_calibration`] read the two text formats from memory.

use std::fs::File;
use std::io::{BufRead, BufReader, Lines};
use std::path::{Component, Path, PathBuf};

use nalgebra::Translation3;
use slam_core::io::{StampedPose, parse_pcd, parse_tum, read_tum};
use slam_core::{FormatError, Pose3, quaternion_from_xyzw, quaternion_to_xyzw};

use super::bounded_file::{
    MAX_RECORDING_FILE_BYTES, check_regular_file, open_regular_file, read_bounded,
    read_bounded_text,
};
use crate::record::{CalibrationProblem, IndexLineProblem, RecordError};
use crate::robot::Sample;

pub(super) const INDEX: &str = "index.txt";
pub(super) const CALIBRATION: &str = "calibration.txt";
pub(super) const ODOMETRY: &str = "odometry.tum";
pub(super) const GROUND_TRUTH: &str = "ground_truth.tum";
pub(super) const CLOUDS: &str = "clouds";
pub(super) const HEADER: &str = "# spot-nav recording v1";
/// Largest stamp difference (seconds) between the index and a trajectory line.
const STAMP_TOLERANCE: f64 = 1e-6;

/// A recording opened for reading. Opening checks the whole folder line by line (counts,
/// stamps, cloud paths) without keeping it; [`Recording::samples`] then reads one scan at a
/// time.
#[derive(Clone, Debug)]
pub struct Recording {
    dir: PathBuf,
    body_t_lidar: Pose3,
    len: usize,
    has_ground_truth: bool,
}

/// A text file read line by line, with its path and the line number reached.
struct LineReader {
    path: PathBuf,
    lines: Lines<BufReader<File>>,
    line: usize,
}

impl std::fmt::Debug for LineReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "LineReader({}, line {})", self.path.display(), self.line)
    }
}

impl LineReader {
    fn open(path: PathBuf) -> Result<Self, RecordError> {
        let file = open_regular_file(&path, MAX_RECORDING_FILE_BYTES)?;
        Ok(Self {
            lines: BufReader::new(file).lines(),
            path,
            line: 0,
        })
    }

    /// The next line that is neither blank nor a comment, with its 1-based number.
    fn next_entry(&mut self) -> Result<Option<(usize, String)>, RecordError> {
        for line in self.lines.by_ref() {
            self.line += 1;
            let line = line.map_err(|e| RecordError::io(&self.path, e))?;
            let trimmed = line.trim();
            if !(trimmed.is_empty() || trimmed.starts_with('#')) {
                return Ok(Some((self.line, trimmed.to_owned())));
            }
        }
        Ok(None)
    }

    /// The next pose of a TUM file, `None` at its end.
    fn next_pose(&mut self) -> Result<Option<StampedPose>, RecordError> {
        let Some((line, text)) = self.next_entry()? else {
            return Ok(None);
        };
        match parse_tum(&text) {
            Ok(mut poses) if poses.len() == 1 => Ok(poses.pop()),
            Ok(_) => Err(RecordError::NotOnePose {
                path: self.path.clone(),
                line,
            }),
            // Numbered as the line of the file, not of the one line parsed.
            Err(FormatError::Line { message, .. }) => Err(RecordError::PoseLine {
                path: self.path.clone(),
                source: FormatError::Line { line, message },
            }),
            Err(other) => Err(other.into()),
        }
    }
}

/// One line of a recording's index: `index stamp cloud-path`.
#[derive(Clone, Debug, PartialEq)]
pub struct IndexEntry {
    /// The scan's number as written (the writer counts from 0).
    pub index: u64,
    /// The scan's stamp, seconds.
    pub stamp: f64,
    /// The cloud file, relative to the recording's folder and inside it.
    pub cloud: PathBuf,
}

impl IndexEntry {
    /// The entry of one index line, or what is wrong with it.
    fn parse(text: &str) -> Result<Self, IndexLineProblem> {
        let fields: Vec<&str> = text.split_whitespace().collect();
        let [index, stamp, cloud] = fields.as_slice() else {
            return Err(IndexLineProblem::FieldCount);
        };
        let index = index
            .parse::<u64>()
            .map_err(|_| IndexLineProblem::Index((*index).to_owned()))?;
        let stamp = stamp
            .parse::<f64>()
            .ok()
            .filter(|s| s.is_finite())
            .ok_or_else(|| IndexLineProblem::Stamp((*stamp).to_owned()))?;
        let relative = Path::new(cloud);
        if !relative
            .components()
            .all(|c| matches!(c, Component::Normal(_) | Component::CurDir))
        {
            return Err(IndexLineProblem::CloudOutside((*cloud).to_owned()));
        }
        Ok(Self {
            index,
            stamp,
            cloud: relative.to_path_buf(),
        })
    }

    /// The index line of this entry (the stamp printed so that it reads back exactly).
    #[must_use]
    pub fn to_line(&self) -> String {
        format!("{} {} {}", self.index, self.stamp, self.cloud.display())
    }
}

/// Parse the text of a recording's `index.txt`: blank lines and `#` comments skipped, one
/// [`IndexEntry`] per other line.
///
/// # Errors
/// [`RecordError::IndexLine`] naming `index.txt`, the line and its [`IndexLineProblem`]: not
/// three fields, an index that is not a whole number, a stamp that is not finite, a cloud path
/// that is absolute or leaves the folder (`..`).
pub fn parse_index(text: &str) -> Result<Vec<IndexEntry>, RecordError> {
    text.lines()
        .enumerate()
        .map(|(k, l)| (k + 1, l.trim()))
        .filter(|(_, l)| !(l.is_empty() || l.starts_with('#')))
        .map(|(line, l)| {
            IndexEntry::parse(l).map_err(|problem| RecordError::IndexLine {
                path: PathBuf::from(INDEX),
                line,
                problem,
            })
        })
        .collect()
}

/// The text of `calibration.txt` for a LiDAR mounted at `body_t_lidar` (reads back exactly).
#[must_use]
pub fn calibration_text(body_t_lidar: &Pose3) -> String {
    let t = body_t_lidar.translation.vector;
    let q = quaternion_to_xyzw(&body_t_lidar.rotation);
    format!(
        "# LiDAR pose in Spot's body frame: tx ty tz qx qy qz qw\nbody_T_lidar {} {} {} {} {} {} {}\n",
        t.x, t.y, t.z, q[0], q[1], q[2], q[3]
    )
}

/// Parse the text of a recording's `calibration.txt`: the `body_T_lidar tx ty tz qx qy qz qw`
/// line.
///
/// # Errors
/// [`RecordError::Calibration`] naming `calibration.txt` and its [`CalibrationProblem`]: no
/// such line, not 7 finite numbers, or a quaternion that is not unit.
pub fn parse_calibration(text: &str) -> Result<Pose3, RecordError> {
    let bad = |problem: CalibrationProblem| RecordError::Calibration {
        path: PathBuf::from(CALIBRATION),
        problem,
    };
    let line = text
        .lines()
        .map(str::trim)
        .find(|l| l.starts_with("body_T_lidar"))
        .ok_or_else(|| bad(CalibrationProblem::NoLine))?;
    let v: Vec<f64> = line
        .split_whitespace()
        .skip(1)
        .map(str::parse)
        .collect::<Result<_, _>>()
        .map_err(|e| bad(CalibrationProblem::NotANumber(e)))?;
    if v.len() != 7 || !v.iter().all(|x| x.is_finite()) {
        return Err(bad(CalibrationProblem::NotSevenFinite));
    }
    let q = quaternion_from_xyzw([v[3], v[4], v[5], v[6]])
        .ok_or_else(|| bad(CalibrationProblem::NonUnitQuaternion))?;
    Ok(Pose3::from_parts(Translation3::new(v[0], v[1], v[2]), q))
}

/// Errors of an in-memory parse of the file `name`, renamed to the file's full `path`.
fn at_path(mut e: RecordError, name: &str, path: &Path) -> RecordError {
    if let RecordError::Calibration { path: p, .. } | RecordError::IndexLine { path: p, .. } =
        &mut e
        && p == Path::new(name)
    {
        *p = path.to_path_buf();
    }
    e
}

impl Recording {
    /// Open the recording in `dir`, checking it whole in one streaming pass.
    ///
    /// # Errors
    /// [`RecordError::Io`] or [`RecordError::Format`] when a file is missing or malformed;
    /// [`RecordError::NotRegularFile`], [`RecordError::FileTooLarge`] or
    /// [`RecordError::NotUtf8`] for a file that cannot be read whole; [`RecordError::Calibration`],
    /// [`RecordError::IndexLine`] or [`RecordError::PoseLine`] for a malformed line; and
    /// [`RecordError::MissingPose`], [`RecordError::ExtraPose`] or
    /// [`RecordError::StampMismatch`] when the files disagree.
    pub fn open(dir: impl AsRef<Path>) -> Result<Self, RecordError> {
        let dir = dir.as_ref().to_path_buf();
        let cal_path = dir.join(CALIBRATION);
        let cal = read_bounded_text(&cal_path, MAX_RECORDING_FILE_BYTES)?;
        let body_t_lidar =
            parse_calibration(&cal).map_err(|e| at_path(e, CALIBRATION, &cal_path))?;
        let has_ground_truth = dir.join(GROUND_TRUTH).exists();
        let mut recording = Self {
            dir,
            body_t_lidar,
            len: 0,
            has_ground_truth,
        };
        let mut len = 0;
        for sample in recording.entries()? {
            sample?;
            len += 1;
        }
        recording.len = len;
        Ok(recording)
    }

    /// The entries (stamp, cloud path, poses) without reading the clouds.
    fn entries(&self) -> Result<Entries, RecordError> {
        Ok(Entries {
            dir: self.dir.clone(),
            index: LineReader::open(self.dir.join(INDEX))?,
            odometry: LineReader::open(self.dir.join(ODOMETRY))?,
            ground_truth: if self.has_ground_truth {
                Some(LineReader::open(self.dir.join(GROUND_TRUTH))?)
            } else {
                None
            },
            done: false,
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
        self.len
    }

    /// Whether the recording has no scan.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The LiDAR mounting.
    #[must_use]
    pub fn body_t_lidar(&self) -> Pose3 {
        self.body_t_lidar
    }

    /// Whether the recording carries ground truth.
    #[must_use]
    pub fn has_ground_truth(&self) -> bool {
        self.has_ground_truth
    }

    /// The whole ground-truth trajectory (one pose per scan, for evaluating a run), `None`
    /// when the recording has none.
    ///
    /// # Errors
    /// [`RecordError::Format`] when the file cannot be read.
    pub fn read_ground_truth(&self) -> Result<Option<Vec<StampedPose>>, RecordError> {
        if !self.has_ground_truth {
            return Ok(None);
        }
        Ok(Some(read_tum(self.dir.join(GROUND_TRUTH))?))
    }

    /// The whole odometry trajectory, one pose per scan.
    ///
    /// # Errors
    /// [`RecordError::Format`] when the file cannot be read.
    pub fn read_odometry(&self) -> Result<Vec<StampedPose>, RecordError> {
        Ok(read_tum(self.dir.join(ODOMETRY))?)
    }

    /// Every sample in order, each read from disk when reached; the recording stays usable.
    #[must_use]
    pub fn samples(&self) -> RecordingSamples {
        self.clone().into_iter()
    }
}

/// Index and trajectory lines read in step.
#[derive(Debug)]
struct Entries {
    dir: PathBuf,
    index: LineReader,
    odometry: LineReader,
    ground_truth: Option<LineReader>,
    done: bool,
}

/// One scan's entry: stamp, cloud path, odometry, ground truth.
struct Entry {
    stamp: f64,
    cloud: PathBuf,
    odom_t_body: Pose3,
    ground_truth: Option<Pose3>,
}

impl Entries {
    fn read(&mut self) -> Result<Option<Entry>, RecordError> {
        let Some((line, text)) = self.index.next_entry()? else {
            // The trajectories must end with the index.
            for reader in std::iter::once(&mut self.odometry).chain(self.ground_truth.as_mut()) {
                if let Some((line, _)) = reader.next_entry()? {
                    return Err(RecordError::ExtraPose {
                        path: reader.path.clone(),
                        line,
                    });
                }
            }
            return Ok(None);
        };
        let entry = IndexEntry::parse(&text).map_err(|problem| RecordError::IndexLine {
            path: self.index.path.clone(),
            line,
            problem,
        })?;
        let (stamp, cloud) = (entry.stamp, self.dir.join(entry.cloud));
        // Refused when the folder is opened, not only when the scan is reached.
        check_regular_file(&cloud, MAX_RECORDING_FILE_BYTES)?;
        let pose_of = |reader: &mut LineReader| -> Result<Pose3, RecordError> {
            let at = reader.line;
            let pose = reader
                .next_pose()?
                .ok_or_else(|| RecordError::MissingPose {
                    path: reader.path.clone(),
                    line: at + 1,
                    stamp,
                })?;
            if (pose.stamp - stamp).abs() > STAMP_TOLERANCE {
                return Err(RecordError::StampMismatch {
                    path: reader.path.clone(),
                    line: reader.line,
                    pose_stamp: pose.stamp,
                    scan_stamp: stamp,
                });
            }
            Ok(pose.pose)
        };
        let odom_t_body = pose_of(&mut self.odometry)?;
        let ground_truth = match self.ground_truth.as_mut() {
            Some(reader) => Some(pose_of(reader)?),
            None => None,
        };
        Ok(Some(Entry {
            stamp,
            cloud,
            odom_t_body,
            ground_truth,
        }))
    }
}

impl Iterator for Entries {
    type Item = Result<Entry, RecordError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let item = self.read().transpose();
        // After an error or the end, nothing more: a malformed line is not skipped.
        if !matches!(item, Some(Ok(_))) {
            self.done = true;
        }
        item
    }
}

/// A recording's samples read one at a time (from [`Recording::into_iter`] or
/// [`Recording::samples`]); memory stays that of one scan however long the recording is.
#[derive(Debug)]
pub struct RecordingSamples {
    body_t_lidar: Pose3,
    entries: Result<Entries, Option<RecordError>>,
    left: usize,
}

impl Iterator for RecordingSamples {
    type Item = Result<Sample, RecordError>;

    fn next(&mut self) -> Option<Self::Item> {
        // As many samples as the recording had when it was opened (the exact length), unless an
        // error ends the reading early.
        if self.left == 0 {
            return None;
        }
        let entries = match &mut self.entries {
            Ok(entries) => entries,
            // The files could not be opened again: say so once.
            Err(e) => {
                self.left = 0;
                return e.take().map(Err);
            }
        };
        let entry = match entries.next()? {
            Ok(entry) => entry,
            Err(e) => {
                self.left = 0;
                return Some(Err(e));
            }
        };
        self.left = self.left.saturating_sub(1);
        Some(
            read_bounded(&entry.cloud, MAX_RECORDING_FILE_BYTES)
                .and_then(|bytes| Ok(parse_pcd(&bytes)?))
                .map(|cloud| Sample {
                    stamp: entry.stamp,
                    odom_t_body: entry.odom_t_body,
                    body_t_lidar: self.body_t_lidar,
                    cloud,
                    ground_truth: entry.ground_truth,
                    gyro_orientation: None,
                }),
        )
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        (self.left, Some(self.left))
    }
}

impl ExactSizeIterator for RecordingSamples {}

impl IntoIterator for Recording {
    type Item = Result<Sample, RecordError>;
    type IntoIter = RecordingSamples;

    /// Every sample in order, each cloud read when reached; the iterator owns what it reads
    /// from, so it can be returned or boxed beside a simulated run.
    fn into_iter(self) -> RecordingSamples {
        RecordingSamples {
            body_t_lidar: self.body_t_lidar,
            entries: self.entries().map_err(Some),
            left: self.len,
        }
    }
}
