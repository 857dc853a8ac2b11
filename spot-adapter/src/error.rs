//! The error enum of spot-adapter.

use std::path::PathBuf;

use thiserror::Error;

/// Errors of the simulator, the recordings and the evaluation.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum AdapterError {
    /// A configuration value is out of its valid range.
    #[error("invalid configuration: {0}")]
    InvalidConfig(String),
    /// A file of a recording or a KITTI folder could not be read or written.
    #[error(transparent)]
    Format(#[from] slam_core::FormatError),
    /// A grid could not be built.
    #[error(transparent)]
    Grid(#[from] slam_core::GridError),
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
}
