//! Error enums of slam-core and of the three backend traits.

use std::path::PathBuf;

use thiserror::Error;

/// Errors building or addressing a [`BitGrid`](crate::BitGrid).
#[derive(Debug, Clone, Copy, PartialEq, Error)]
#[non_exhaustive]
pub enum GridError {
    /// A grid needs at least one row and one column.
    #[error("grid of {width}x{height} cells is empty")]
    EmptyGrid {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
    },
    /// The grid would exceed the cell budget.
    #[error("grid of {width}x{height} cells exceeds the budget of {max_cells} cells")]
    TooLarge {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
        /// The budget.
        max_cells: u64,
    },
    /// A cell outside the grid was addressed.
    #[error("cell ({x}, {y}) is outside the {width}x{height} grid")]
    OutOfBounds {
        /// Column asked for.
        x: i64,
        /// Row asked for.
        y: i64,
        /// Grid width.
        width: u32,
        /// Grid height.
        height: u32,
    },
    /// The resolution must be finite and positive.
    #[error("grid resolution {resolution} m is not finite and positive")]
    InvalidResolution {
        /// The resolution given.
        resolution: f64,
    },
    /// The origin must be finite.
    #[error("grid origin is not finite")]
    NonFiniteOrigin,
    /// Stored grid data has the wrong number of words for its size.
    #[error("grid data has {got} words, {expected} expected for its size")]
    WordCount {
        /// Words a grid of that size has.
        expected: usize,
        /// Words given.
        got: usize,
    },
}

/// Errors reading or writing the file formats in [`io`](crate::io).
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum FormatError {
    /// The operating system refused a read or write.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// An I/O error on a stream without a path.
    #[error(transparent)]
    Stream(#[from] std::io::Error),
    /// A text line could not be parsed.
    #[error("line {line}: {message}")]
    Line {
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// Binary content could not be parsed.
    #[error("byte {offset}: {message}")]
    Byte {
        /// 0-based byte offset.
        offset: usize,
        /// What is wrong.
        message: String,
    },
    /// The file is valid but uses a feature this reader does not implement.
    #[error("unsupported: {0}")]
    Unsupported(String),
}

/// Errors of a [`Registrator`](crate::Registrator).
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum RegistrationError {
    /// Too few usable points (after filtering) to register.
    #[error("{what} has {points} usable points, at least {required} are needed")]
    TooFewPoints {
        /// "source" or "target".
        what: &'static str,
        /// Points left.
        points: usize,
        /// Points needed.
        required: usize,
    },
    /// The initial guess is not a finite rigid transform.
    #[error("initial pose is not finite")]
    NonFiniteInitialGuess,
    /// Fewer correspondences than needed survived outlier rejection.
    #[error("only {found} correspondences, at least {required} are needed")]
    TooFewCorrespondences {
        /// Correspondences found.
        found: usize,
        /// Correspondences needed.
        required: usize,
    },
    /// The linear system was singular or produced a non-finite step.
    #[error("degenerate problem: {0}")]
    Degenerate(String),
    /// A configuration value is out of its valid range.
    #[error("invalid configuration: {0}")]
    InvalidConfig(String),
}

/// Errors of an [`Optimizer`](crate::Optimizer) or of building a [`PoseGraph`](crate::PoseGraph).
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum OptimizeError {
    /// A node id was used twice.
    #[error("node {id} already exists")]
    DuplicateNode {
        /// The repeated id.
        id: u64,
    },
    /// An edge or fix refers to a node that does not exist.
    #[error("node {id} does not exist")]
    UnknownNode {
        /// The missing id.
        id: u64,
    },
    /// An edge joins a node to itself.
    #[error("edge joins node {id} to itself")]
    SelfLoop {
        /// The node.
        id: u64,
    },
    /// A pose, measurement or information value is not finite.
    #[error("non-finite value in {0}")]
    NonFinite(String),
    /// An information matrix is not symmetric positive definite.
    #[error("information matrix of edge {edge} is not symmetric positive definite")]
    InformationNotPositiveDefinite {
        /// Index of the edge.
        edge: usize,
    },
    /// No node is fixed and the optimizer has no gauge of its own.
    #[error("no node is fixed: the problem has a free gauge")]
    NoFixedNode,
    /// Some nodes are not connected to a fixed node.
    #[error("{count} nodes are not connected to a fixed node (first: {first_id})")]
    Disconnected {
        /// How many.
        count: usize,
        /// One of them.
        first_id: u64,
    },
    /// The graph has no nodes.
    #[error("the graph has no nodes")]
    EmptyGraph,
    /// The sparse factorisation failed beyond recovery.
    #[error("factorisation failed: {0}")]
    Factorization(String),
}

/// Errors of a [`Planner`](crate::Planner): bad arguments only. An unreachable goal is not an
/// error but the answer `Ok(None)` of [`Planner::plan`](crate::Planner::plan).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum PlanError {
    /// Start or goal is off the grid.
    #[error("{which} ({x}, {y}) is outside the {width}x{height} grid")]
    OutOfBounds {
        /// "start" or "goal".
        which: &'static str,
        /// Column.
        x: u32,
        /// Row.
        y: u32,
        /// Grid width.
        width: u32,
        /// Grid height.
        height: u32,
    },
    /// Start or goal is a blocked cell.
    #[error("{which} ({x}, {y}) is a blocked cell")]
    BlockedCell {
        /// "start" or "goal".
        which: &'static str,
        /// Column.
        x: u32,
        /// Row.
        y: u32,
    },
}

/// Errors building or combining a [`PointCloud`](crate::PointCloud).
#[derive(Debug, Clone, Copy, PartialEq, Error)]
#[non_exhaustive]
pub enum CloudError {
    /// A channel does not have one value per point.
    #[error("{channel} channel has {got} values for {expected} points")]
    ChannelLength {
        /// The channel.
        channel: &'static str,
        /// Points in the cloud.
        expected: usize,
        /// Values given.
        got: usize,
    },
    /// Two clouds to combine do not carry the same channels.
    #[error("one cloud has a {channel} channel and the other does not")]
    ChannelMismatch {
        /// The channel.
        channel: &'static str,
    },
    /// The voxel size must be finite and positive.
    #[error("voxel size {size} m is not finite and positive")]
    InvalidVoxelSize {
        /// The size given.
        size: f32,
    },
}
