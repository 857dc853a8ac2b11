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
