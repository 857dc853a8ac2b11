//! What is wrong with a point cloud or a local grid the robot sent, or with a client setting:
//! typed, so that a caller can tell the cases apart without reading text.

use slam_core::InvalidSetting;
use thiserror::Error;

/// What is wrong with a point cloud the robot sent (see [`SpotError::MalformedCloud`]).
///
/// [`SpotError::MalformedCloud`]: crate::grpc::SpotError::MalformedCloud
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum CloudProblem {
    /// The response holds no point cloud.
    #[error("the response holds no point cloud")]
    Missing,
    /// The status is OK but no cloud came with it.
    #[error("status OK without a point cloud")]
    OkWithoutCloud,
    /// An encoding other than XYZ 32F.
    #[error("encoding {code} ({name}) is not ENCODING_XYZ_32F")]
    Encoding {
        /// The encoding's number on the wire.
        code: i32,
        /// Its name, or "an unknown encoding".
        name: &'static str,
    },
    /// A negative point count.
    #[error("num_points = {0} is negative")]
    NegativeCount(i32),
    /// A point count whose bytes overflow.
    #[error("num_points = {0} overflows")]
    CountOverflows(usize),
    /// Data of another size than the count calls for.
    #[error("{bytes} bytes of data for num_points = {points} (XYZ 32F needs {needed})")]
    DataSize {
        /// Bytes received.
        bytes: usize,
        /// The declared count.
        points: usize,
        /// Bytes the count calls for.
        needed: usize,
    },
    /// A coordinate that is not finite.
    #[error("point {0} is not finite")]
    NonFinitePoint(usize),
}

/// What is wrong with a local grid the robot sent (see [`SpotError::MalformedGrid`]).
///
/// [`SpotError::MalformedGrid`]: crate::grpc::SpotError::MalformedGrid
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum GridProblem {
    /// The response lists no grid of this name.
    #[error("missing from the response")]
    Missing,
    /// The status is OK but no grid came with it.
    #[error("status OK without a grid")]
    OkWithoutGrid,
    /// No extent.
    #[error("no extent")]
    NoExtent,
    /// A negative side.
    #[error("extent {x} x {y} cells has a negative side")]
    NegativeSide {
        /// Cells along x.
        x: i32,
        /// Cells along y.
        y: i32,
    },
    /// A cell size that is not finite and positive.
    #[error("cell size {0} m is not positive")]
    CellSize(f64),
    /// More cells than a grid may hold.
    #[error("extent {x} x {y} cells is too large")]
    TooLarge {
        /// Cells along x.
        x: i32,
        /// Cells along y.
        y: i32,
    },
    /// A cell format this client does not know (or the message's unset 0).
    #[error("cell format {0} is unknown")]
    UnknownFormat(i32),
    /// Data that is not a whole number of cells.
    #[error("{bytes} bytes is not a whole number of {cell_bytes}-byte cells")]
    PartialCell {
        /// Bytes received.
        bytes: usize,
        /// Bytes a cell.
        cell_bytes: usize,
    },
    /// RAW data of another size than the extent.
    #[error("{stored} cells of data for {cells} cells of extent")]
    RawSize {
        /// Cells received.
        stored: usize,
        /// Cells of the extent.
        cells: usize,
    },
    /// An encoding neither RAW nor RLE.
    #[error("encoding {0} is neither RAW nor RLE")]
    Encoding(i32),
    /// RLE values and counts of different lengths.
    #[error("{values} run values for {counts} run counts")]
    RunLengths {
        /// Run values.
        values: usize,
        /// Run counts.
        counts: usize,
    },
    /// A run with a negative count.
    #[error("run {0} has a negative count")]
    NegativeRun(usize),
    /// Runs that hold more cells than the extent.
    #[error("the runs hold more than the {0} cells")]
    RunsTooLong(usize),
    /// Runs that hold fewer cells than the extent.
    #[error("the runs hold {held} of the {cells} cells")]
    RunsTooShort {
        /// Cells the runs hold.
        held: usize,
        /// Cells of the extent.
        cells: usize,
    },
    /// A scale or offset that is not finite.
    #[error("non-finite scale or offset")]
    NonFiniteScale,
}

/// What is wrong with a setting of the client (see [`SpotError::InvalidConfig`]).
///
/// [`SpotError::InvalidConfig`]: crate::grpc::SpotError::InvalidConfig
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ConfigProblem {
    /// Empty.
    #[error("empty")]
    Empty,
    /// No CA certificate.
    #[error("empty: the robot's CA certificate is needed")]
    NoCaCertificate,
    /// A zero duration.
    #[error("must be longer than zero")]
    ZeroDuration,
    /// No time-sync round allowed.
    #[error("at least one round")]
    NoRounds,
    /// Motion limits out of range.
    #[error("out of range")]
    Limits(#[source] InvalidSetting),
    /// Not a host name a TLS channel can name.
    #[error("{0:?} is not a host name")]
    NotAHostName(String),
}
