//! The error enum of spot-adapter.

use std::path::PathBuf;

use thiserror::Error;

/// Errors of the robot interface, the simulator, the recordings, the evaluation and the
/// navigator.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum AdapterError {
    /// A setting is out of its valid range.
    #[error("{setting} = {value}: must be {expected}")]
    InvalidConfig {
        /// The setting, as its field is named.
        setting: &'static str,
        /// The value given (counts and flags as numbers).
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
    /// A trajectory command is malformed.
    #[error("trajectory point {point}: {problem}")]
    InvalidTrajectory {
        /// Index of the first bad point.
        point: usize,
        /// What is wrong.
        problem: &'static str,
    },
    /// A command names a frame this robot does not have.
    #[error("this robot has no frame {frame:?}")]
    UnsupportedFrame {
        /// The frame's name.
        frame: &'static str,
    },
    /// A goal is not a finite point.
    #[error("goal ({x}, {y}) is not a finite point")]
    NonFiniteGoal {
        /// Goal x (metres).
        x: f64,
        /// Goal y (metres).
        y: f64,
    },
    /// A file of a recording or a KITTI folder could not be read or written.
    #[error(transparent)]
    Format(#[from] slam_core::FormatError),
    /// A grid could not be built.
    #[error(transparent)]
    Grid(#[from] slam_core::GridError),
    /// The navigator's occupancy grid could not be built from the map.
    #[error("the navigation grid cannot be built from the map")]
    NavigationGrid(#[source] gridmap::GridMapError),
    /// The navigator's map cannot be prepared for registration.
    #[error("the map cannot be prepared for localisation")]
    LocalisationMap(#[source] slam_core::RegistrationError),
    /// A planner refused its arguments (a start or goal off the grid or blocked).
    #[error("the planner refused its arguments")]
    Planner(#[source] slam_core::PlanError),
    /// The operating system refused a file or folder operation.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A recording's files do not agree with each other.
    #[error("{path}: {message}")]
    Recording {
        /// The file at fault.
        path: PathBuf,
        /// What is wrong.
        message: String,
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
        /// Where the body frame came from ("the child frame of odometry topic /odom", "the base
        /// frame given").
        body_from: String,
        /// The LiDAR frame.
        lidar_frame: String,
        /// The frames the bag has (boxed: the error enum stays small).
        frames: Box<crate::record::BagFrames>,
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
        frames: Box<crate::record::BagFrames>,
    },
    /// A route's start or goal lies inside an obstacle or outside the building.
    #[error("{which} ({x:.2}, {y:.2}) m is not free floor")]
    BlockedEndpoint {
        /// "start" or "goal".
        which: &'static str,
        /// World x (metres).
        x: f64,
        /// World y (metres).
        y: f64,
    },
    /// No collision-free route joins the two points.
    #[error("no route from the start to the goal")]
    NoRoute,
    /// A box to add to a building is not a finite, non-empty box.
    #[error("a box needs finite corners with min below max on every axis")]
    InvalidBox,
    /// Two trajectories cannot be aligned (a non-finite position).
    #[error("the trajectories cannot be aligned")]
    Alignment(#[source] slam_core::RigidFitError),
    /// Two trajectories to compare have too few poses in common.
    #[error("{found} associated poses, at least {required} are needed")]
    TooFewPoses {
        /// Pairs found.
        found: usize,
        /// Pairs needed.
        required: usize,
    },
}

impl AdapterError {
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self::Io {
            path: path.into(),
            source,
        }
    }

    /// An [`AdapterError::InvalidConfig`] for `setting` = `value`.
    pub(crate) fn invalid(setting: &'static str, value: f64, expected: &'static str) -> Self {
        Self::InvalidConfig {
            setting,
            value,
            expected,
        }
    }
}

/// Why [`drive`](crate::nav::drive) stopped early; the robot was sent a stop first.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum DriveError<E: std::error::Error + 'static> {
    /// The robot failed to deliver a sample or take a command.
    #[error("the robot failed")]
    Robot(#[source] E),
    /// The navigator failed.
    #[error("the navigator failed")]
    Navigation(#[source] AdapterError),
}

/// Why one message of a bag (or one cloud) cannot be used.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum MessageError {
    /// The payload ends before a field it declares.
    #[error("payload truncated: {needed} bytes needed at offset {offset}, {left} left")]
    Truncated {
        /// Byte offset in the payload.
        offset: usize,
        /// Bytes the field needs.
        needed: usize,
        /// Bytes left.
        left: usize,
    },
    /// A CDR payload whose encapsulation is not plain CDR.
    #[error("CDR encapsulation {kind:?} is not plain little- or big-endian CDR")]
    Encapsulation {
        /// The first two header bytes.
        kind: [u8; 2],
    },
    /// A string is not UTF-8 (or, in CDR, lacks its terminating NUL).
    #[error("invalid string at offset {offset}")]
    InvalidString {
        /// Byte offset of its length.
        offset: usize,
    },
    /// The topic carries another message type than the reader needs there.
    #[error("message type {found:?} where {expected} is needed")]
    UnknownType {
        /// The type the bag names.
        found: String,
        /// The type needed.
        expected: &'static str,
    },
    /// A point cloud lacks a coordinate field.
    #[error("the cloud has no {axis:?} field (fields: {fields})")]
    MissingCoordinate {
        /// `x`, `y` or `z`.
        axis: &'static str,
        /// The fields it has, comma-separated.
        fields: String,
    },
    /// A point field has a datatype code outside `sensor_msgs/PointField`'s, or one unfit for
    /// its role (a coordinate that is not a float).
    #[error("field {field:?}: datatype {datatype} cannot be read as {role}")]
    UnsupportedDatatype {
        /// The field's name.
        field: String,
        /// Its datatype code.
        datatype: u8,
        /// What it was to be read as.
        role: &'static str,
    },
    /// A point field does not fit inside one point.
    #[error(
        "field {field:?} (offset {offset}, {size} bytes) does not fit in a point of {point_step} bytes"
    )]
    FieldOutsidePoint {
        /// The field's name.
        field: String,
        /// Its offset.
        offset: u32,
        /// Its size in bytes.
        size: usize,
        /// Bytes per point.
        point_step: u32,
    },
    /// `width`, `height`, `point_step`, `row_step` and the data's length disagree.
    #[error(
        "cloud shape: {width} x {height} points of {point_step} bytes, rows of {row_step} bytes, \
         {data_len} bytes of data"
    )]
    CloudShape {
        /// Points per row.
        width: u32,
        /// Rows.
        height: u32,
        /// Bytes per point.
        point_step: u32,
        /// Bytes per row.
        row_step: u32,
        /// Bytes of data.
        data_len: usize,
    },
    /// No unit makes the per-point times fit in one scan period after the header stamp (or more
    /// than one does).
    #[error(
        "per-point time {field:?} in [{min}, {max}] (stamp {stamp} s): {problem} within a scan \
         period of {period} s"
    )]
    TimeUnit {
        /// The time field (or fields).
        field: String,
        /// Smallest raw value.
        min: f64,
        /// Largest raw value.
        max: f64,
        /// The header stamp (seconds).
        stamp: f64,
        /// The longest scan period allowed (seconds).
        period: f64,
        /// "no unit fits" or "seconds and nanoseconds both fit", or the unit that stopped fitting.
        problem: String,
    },
    /// A pose with a non-finite value or a quaternion far from unit length.
    #[error("{what} is not a valid pose (non-finite or non-unit quaternion)")]
    InvalidPose {
        /// Which pose.
        what: &'static str,
    },
    /// The frame tree does not join two frames.
    #[error("no transform from {parent:?} to {child:?} at {stamp} s in the tf messages")]
    MissingTransform {
        /// The frame looked up from.
        parent: String,
        /// The frame looked up.
        child: String,
        /// The time (seconds).
        stamp: f64,
    },
}
