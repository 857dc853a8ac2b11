//! The error of the recording readers and writers, with the reasons a line of a recording's
//! text files is refused.

use std::num::ParseFloatError;
use std::path::PathBuf;

use thiserror::Error;

use crate::record::{BagFrames, MessageError};

/// Why a recording (spot-nav folder, bag, KITTI sequence, folder of scans) cannot be read or
/// written. Every variant names the file or folder at fault.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum RecordError {
    /// A file of a recording or a KITTI folder could not be read or written.
    #[error(transparent)]
    Format(#[from] slam_core::FormatError),
    /// The operating system refused a file or folder operation.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The path is neither a file nor a folder.
    #[error("{path}: no such file or folder")]
    NotFound {
        /// The path given.
        path: PathBuf,
    },
    /// The path is no kind of recording this crate reads.
    #[error(
        "{path}: not a bag, a spot-nav recording (index.txt), a KITTI sequence (velodyne/) or a \
         folder of .pcd/.ply scans"
    )]
    UnknownKind {
        /// The path given.
        path: PathBuf,
    },
    /// A file given as a bag has another extension.
    #[error("{path}: a bag must end in .mcap or .bag")]
    NotABag {
        /// The file.
        path: PathBuf,
    },
    /// A ROS 2 bag folder holds no `.mcap` file.
    #[error("{path}: a ROS 2 bag folder without an .mcap file (sqlite3 bags are not read)")]
    NoMcapFile {
        /// The folder.
        path: PathBuf,
    },
    /// A ROS 2 bag folder holds several `.mcap` files.
    #[error("{path}: a ROS 2 bag split over {files} .mcap files: give one")]
    SplitMcap {
        /// The folder.
        path: PathBuf,
        /// The `.mcap` files it holds.
        files: usize,
    },
    /// A file a recording names is a link to a device, a pipe or a folder.
    #[error("{path}: not a regular file")]
    NotRegularFile {
        /// The file.
        path: PathBuf,
    },
    /// A file a recording names is longer than the limit.
    #[error("{path}: {bytes} bytes, more than the limit of {limit}")]
    FileTooLarge {
        /// The file.
        path: PathBuf,
        /// Its length.
        bytes: u64,
        /// The limit, [`MAX_RECORDING_FILE_BYTES`](crate::record::MAX_RECORDING_FILE_BYTES).
        limit: u64,
    },
    /// A file grew past the limit while it was read.
    #[error("{path}: grew past the limit of {limit} bytes")]
    FileGrew {
        /// The file.
        path: PathBuf,
        /// The limit.
        limit: u64,
    },
    /// A text file is not UTF-8.
    #[error("{path}: not UTF-8 text")]
    NotUtf8 {
        /// The file.
        path: PathBuf,
    },
    /// A line of a recording's `index.txt` cannot be read.
    #[error("{path}: line {line}: {problem}")]
    IndexLine {
        /// The index file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong with it.
        problem: IndexLineProblem,
    },
    /// A recording's `calibration.txt` has no usable `body_T_lidar` line.
    #[error("{path}: {problem}")]
    Calibration {
        /// The calibration file.
        path: PathBuf,
        /// What is wrong with it.
        problem: CalibrationProblem,
    },
    /// A line of a trajectory file is not one TUM pose.
    #[error("{path}: {source}")]
    PoseLine {
        /// The trajectory file.
        path: PathBuf,
        /// The TUM reader's reason, with the line's number in the file.
        source: slam_core::FormatError,
    },
    /// A line of a trajectory file holds no single pose.
    #[error("{path}: line {line}: expected one pose")]
    NotOnePose {
        /// The trajectory file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
    },
    /// A trajectory ends before the index: a scan has no pose.
    #[error("{path}: line {line}: no pose for scan stamped {stamp}")]
    MissingPose {
        /// The trajectory file.
        path: PathBuf,
        /// 1-based line number where the pose was expected.
        line: usize,
        /// The scan's stamp (seconds).
        stamp: f64,
    },
    /// A trajectory has more poses than the index has scans.
    #[error("{path}: line {line}: more poses than scans in the index")]
    ExtraPose {
        /// The trajectory file.
        path: PathBuf,
        /// 1-based line number of the first pose too many.
        line: usize,
    },
    /// A pose's stamp is not its scan's.
    #[error("{path}: line {line}: pose stamped {pose_stamp} but its scan {scan_stamp}")]
    StampMismatch {
        /// The trajectory file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// The pose's stamp (seconds).
        pose_stamp: f64,
        /// The scan's stamp in the index (seconds).
        scan_stamp: f64,
    },
    /// A sample to write has another LiDAR mounting than the recording.
    #[error("{path}: sample {sample} has another body_T_lidar than the recording")]
    MountingChanged {
        /// The recording's folder.
        path: PathBuf,
        /// The sample's number (from 0).
        sample: usize,
    },
    /// A sample to write is stamped at or before the last one.
    #[error("{path}: stamp {stamp} does not follow {last}")]
    StampNotIncreasing {
        /// The folder written.
        path: PathBuf,
        /// The sample's stamp (seconds).
        stamp: f64,
        /// The last sample's stamp (seconds).
        last: f64,
    },
    /// A sample to write has a stamp that names no file (not a number).
    #[error("{path}: stamp {stamp} is not a number")]
    StampNotANumber {
        /// The folder written.
        path: PathBuf,
        /// The stamp.
        stamp: f64,
    },
    /// Only some of the samples written carry ground truth.
    #[error(
        "{path}: sample {sample} differs from the first in carrying ground truth; ground truth \
         must be given for all samples or none"
    )]
    PartialGroundTruth {
        /// The folder written.
        path: PathBuf,
        /// The first sample that differs (from 0).
        sample: usize,
    },
    /// A folder to write scans into already holds some.
    #[error("{path}: already holds .ply or .pcd files")]
    FolderHoldsScans {
        /// The folder.
        path: PathBuf,
    },
    /// A folder of scans holds none.
    #[error("{path}: no .pcd or .ply file")]
    NoScans {
        /// The folder.
        path: PathBuf,
    },
    /// A file lists another number of poses or times than there are scans.
    #[error("{path}: {found} {what} for {scans} scans")]
    CountMismatch {
        /// The file.
        path: PathBuf,
        /// Entries found.
        found: usize,
        /// "poses" or "times".
        what: &'static str,
        /// Scans in the folder.
        scans: usize,
    },
    /// The odometry does not cover a scan's stamp.
    #[error("{path}: no odometry around the scan stamped {stamp} s")]
    NoOdometryAt {
        /// The odometry file.
        path: PathBuf,
        /// The scan's stamp (seconds).
        stamp: f64,
    },
    /// A scan's per-point times cannot be read in seconds.
    #[error("{path}: {source}")]
    ScanTimes {
        /// The scan.
        path: PathBuf,
        /// Why the unit cannot be decided.
        source: MessageError,
    },
    /// A KITTI `times.txt` holds a value that is not a finite number.
    #[error("{path}: a time is not a finite number")]
    NonFiniteTime {
        /// The times file.
        path: PathBuf,
    },
    /// A KITTI `calib.txt` has a `Tr:` line without numbers.
    #[error("{path}: empty Tr line")]
    EmptyTrLine {
        /// The calibration file.
        path: PathBuf,
    },
    /// Ground-truth odometry is asked of a KITTI sequence without poses.
    #[error("{path}: ground-truth odometry needs poses.txt")]
    NoGroundTruth {
        /// The poses file looked for.
        path: PathBuf,
    },
    /// A file given as a ROS 1 bag does not start like one.
    #[error("{path}: not a ROS 1 bag (no \"#ROSBAG V2.0\" line)")]
    NotRos1Bag {
        /// The file.
        path: PathBuf,
    },
    /// A ROS 1 bag's header record cannot be read.
    #[error("{path}: {problem}")]
    Ros1Header {
        /// The bag.
        path: PathBuf,
        /// "truncated header", "malformed header field", "malformed `index_pos`" or "header has
        /// no `index_pos`".
        problem: &'static str,
    },
    /// A ROS 1 bag's index is missing or cut off.
    #[error(
        "{path}: truncated or unindexed ROS 1 bag: its index should start at byte {index_pos} of \
         {len} (reindex it with `rosbag reindex`)"
    )]
    Unindexed {
        /// The bag.
        path: PathBuf,
        /// Where the header says the index starts.
        index_pos: u64,
        /// The file's length.
        len: u64,
    },
    /// A ROS 1 bag's chunk holds a message of a connection its index does not list.
    #[error("{path}: a message of connection {connection} that the index does not list")]
    UnknownConnection {
        /// The bag.
        path: PathBuf,
        /// The connection's id.
        connection: u32,
    },
    /// A topic asked for is not in the bag.
    #[error("{path}: no topic {topic}; the bag has {}", topic_listing(.available))]
    NoTopic {
        /// The bag.
        path: PathBuf,
        /// The topic asked for.
        topic: String,
        /// The bag's topics, each as (name, message type).
        available: Vec<(String, String)>,
    },
    /// The bag has no point-cloud topic.
    #[error("{path}: no sensor_msgs/PointCloud2 topic; the bag has {}", topic_listing(.available))]
    NoCloudTopic {
        /// The bag.
        path: PathBuf,
        /// The bag's topics, each as (name, message type).
        available: Vec<(String, String)>,
    },
    /// The bag has several point-cloud topics and none was chosen.
    #[error("{path}: several cloud topics ({}): choose one", .topics.join(", "))]
    SeveralCloudTopics {
        /// The bag.
        path: PathBuf,
        /// The cloud topics.
        topics: Vec<String>,
    },
    /// A topic has no message.
    #[error("{path}: topic {topic} has no message")]
    EmptyTopic {
        /// The bag.
        path: PathBuf,
        /// The topic.
        topic: String,
    },
    /// The odometry frame on `/tf` has several moving children and no body frame was given.
    #[error(
        "{path}: /tf has {} moving children of {odom_frame:?} ({}): give the body frame",
        .children.len(),
        .children.join(", ")
    )]
    AmbiguousBodyFrame {
        /// The bag.
        path: PathBuf,
        /// The odometry frame.
        odom_frame: String,
        /// Its moving children.
        children: Vec<String>,
    },
    /// One message of a bag cannot be used.
    #[error("{path}: topic {topic}, message {index}: {source}")]
    Message {
        /// The bag.
        path: PathBuf,
        /// The message's topic.
        topic: String,
        /// Its index among the topic's messages (from 0).
        index: usize,
        /// What is wrong (boxed: the error enum stays small).
        source: Box<MessageError>,
    },
    /// An MCAP file cannot be read (truncated, corrupt, an unknown compression).
    #[error("{path}: {source}")]
    Mcap {
        /// The file.
        path: PathBuf,
        /// The mcap crate's reason (boxed: it is large).
        source: Box<mcap::McapError>,
    },
    /// An MCAP record holds a string, or an uncompressed chunk a record, longer than itself.
    #[error("{path}: MCAP {what} of {claimed} bytes where {left} remain")]
    McapLength {
        /// The file.
        path: PathBuf,
        /// What is too long, and where ("channel record: a string", "uncompressed chunk: a
        /// record").
        what: &'static str,
        /// The length it claims (for a length field cut off: the field's size).
        claimed: u64,
        /// The bytes left around it.
        left: u64,
    },
    /// A ROS 1 bag cannot be read (truncated, corrupt, unindexed).
    #[error("{path}: {source}")]
    Ros1Bag {
        /// The file.
        path: PathBuf,
        /// The rosbag crate's reason.
        source: rosbag::Error,
    },
    /// A bag's body frame is not joined to its LiDAR frame by fixed transforms (`/tf_static`), so
    /// the LiDAR's mounting is unknown.
    #[error(
        "{path}: no fixed transform joins the body frame {body_frame:?} ({body_from}) to the LiDAR \
         frame {lidar_frame:?}; {frames}; pass --no-odometry to run LiDAR-only, --base-frame F \
         for a body frame joined to {lidar_frame:?} (--base-frame {lidar_frame} takes the \
         odometry as the LiDAR's own), or another odometry with --odom-topic T or --odom-frame F"
    )]
    UnlinkedLidar {
        /// The bag.
        path: PathBuf,
        /// The body frame.
        body_frame: String,
        /// Where the body frame came from.
        body_from: BodyFrameSource,
        /// The LiDAR frame.
        lidar_frame: String,
        /// The frames the bag has (boxed: the error enum stays small).
        frames: Box<BagFrames>,
    },
    /// The IMU topic asked for is in a frame not joined to the body frame by fixed transforms
    /// (`/tf_static`), so its mounting is unknown.
    #[error(
        "{path}: IMU topic {topic}: no fixed transform joins its frame {imu_frame:?} to the body \
         frame {body_frame:?}; {frames}; pass --no-imu, or --base-frame F for a body frame \
         joined to both {imu_frame:?} and the LiDAR frame"
    )]
    UnlinkedImu {
        /// The bag.
        path: PathBuf,
        /// The IMU topic.
        topic: String,
        /// Its readings' frame.
        imu_frame: String,
        /// The body frame.
        body_frame: String,
        /// The frames the bag has (boxed: the error enum stays small).
        frames: Box<BagFrames>,
    },
}

impl RecordError {
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self::Io {
            path: path.into(),
            source,
        }
    }
}

/// `name (type), name (type)...`
fn topic_listing(topics: &[(String, String)]) -> String {
    topics
        .iter()
        .map(|(name, kind)| format!("{name} ({kind})"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Where a bag's body frame came from, as [`RecordError::UnlinkedLidar`] says.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum BodyFrameSource {
    /// The base frame given (`BagConfig::base_frame`).
    Given,
    /// The child frame of this odometry topic.
    OdometryTopic(String),
    /// The moving child of this odometry frame in `/tf`.
    TfChild(String),
    /// The LiDAR frame (no odometry).
    Lidar,
}

impl std::fmt::Display for BodyFrameSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Given => write!(f, "the base frame given"),
            Self::OdometryTopic(t) => write!(f, "the child frame of odometry topic {t}"),
            Self::TfChild(frame) => write!(f, "the moving child of {frame:?} in /tf"),
            Self::Lidar => write!(f, "the LiDAR frame"),
        }
    }
}

/// What is wrong with a line of a recording's `index.txt` (`index stamp cloud-path`).
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum IndexLineProblem {
    /// Not three fields.
    #[error("expected: index stamp cloud")]
    FieldCount,
    /// The index is not a whole number.
    #[error("index {0:?} is not a whole number")]
    Index(String),
    /// The stamp is not a finite number.
    #[error("stamp {0:?} is not a finite number")]
    Stamp(String),
    /// The cloud path is absolute or leaves the folder (`..`).
    #[error("cloud path {0:?} must be relative and stay inside the recording")]
    CloudOutside(String),
}

/// What is wrong with a recording's `calibration.txt`.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum CalibrationProblem {
    /// No line starts with `body_T_lidar`.
    #[error("no body_T_lidar line")]
    NoLine,
    /// A value is not a number.
    #[error("body_T_lidar: {0}")]
    NotANumber(#[source] ParseFloatError),
    /// Not 7 values, or one not finite.
    #[error("body_T_lidar needs 7 finite numbers")]
    NotSevenFinite,
    /// The quaternion is not of unit length.
    #[error("body_T_lidar quaternion is not unit")]
    NonUnitQuaternion,
}
