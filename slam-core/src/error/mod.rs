//! Error enums of slam-core and of the three backend traits.

use std::path::PathBuf;

use thiserror::Error;

use crate::robust_kernel::RobustKernel;

mod backend_error;
mod invalid_setting;

pub use backend_error::BackendError;
pub use invalid_setting::InvalidSetting;

/// `Error::backend(name, error)`, the constructor of an error's `Backend { backend, source }`
/// variant, with the docs given.
macro_rules! backend_constructor {
    ($error:ident, $(#[doc = $doc:literal])*) => {
        impl $error {
            $(#[doc = $doc])*
            pub fn backend(
                backend: &'static str,
                error: impl Into<Box<dyn std::error::Error + Send + Sync>>,
            ) -> Self {
                Self::Backend {
                    backend,
                    source: BackendError::new(error),
                }
            }
        }
    };
}

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
    /// The file name's extension is not one of a cloud format this crate reads.
    #[error("{path}: cloud extension {extension:?} is not pcd, ply or bin")]
    UnknownExtension {
        /// The file.
        path: PathBuf,
        /// Its extension (lower case, empty when it has none).
        extension: String,
    },
    /// A field every cloud needs (x, y or z) is missing: a PCD field or a PLY vertex property.
    #[error("no {field} field")]
    MissingField {
        /// `"x"`, `"y"` or `"z"`.
        field: &'static str,
    },
    /// A PLY file without a vertex element.
    #[error("no vertex element")]
    NoVertexElement,
    /// The ring channel is stored as a floating-point type, which this reader does not accept.
    #[error("ring field {field} is not of an integer type")]
    NonIntegerRing {
        /// The field's name in the file.
        field: String,
    },
    /// The fields of one point record add up to more bytes than memory can address.
    #[error("the point record size overflows")]
    RecordTooLarge,
    /// The decoded channels do not make a cloud (a reader fault: one value per point and
    /// channel is pushed).
    #[error(transparent)]
    Cloud(#[from] CloudError),
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
    /// More points than the spatial index can number.
    #[error("{what} has {points} points, at most {max} can be indexed")]
    TooManyPoints {
        /// "source" or "target".
        what: &'static str,
        /// Points given.
        points: usize,
        /// The index's limit.
        max: usize,
    },
    /// Fewer correspondences than needed survived outlier rejection.
    #[error("only {found} correspondences, at least {required} are needed")]
    TooFewCorrespondences {
        /// Correspondences found.
        found: usize,
        /// Correspondences needed.
        required: usize,
    },
    /// The problem does not determine a pose.
    #[error("degenerate problem: {cause}")]
    Degenerate {
        /// What made it degenerate.
        cause: Degeneracy,
    },
    /// The closed-form rigid fit of the correspondences failed (point-to-point ICP).
    #[error(transparent)]
    RigidFit(#[from] RigidFitError),
    /// A setting is out of its valid range.
    #[error(transparent)]
    InvalidConfig(#[from] InvalidSetting),
    /// A third-party registrator failed for a reason of its own (its error is the
    /// [`source`](std::error::Error::source)); see [`RegistrationError::backend`].
    #[error("registration backend {backend} failed")]
    Backend {
        /// The backend's name.
        backend: &'static str,
        /// The backend's own error.
        #[source]
        source: BackendError,
    },
}

backend_constructor! {
    RegistrationError,
    /// A [`RegistrationError::Backend`]: `backend`'s own `error` (any error type, or a message).
    ///
    /// ```
    /// use slam_core::RegistrationError;
    /// let io = std::io::Error::other("the GPU is gone");
    /// let e = RegistrationError::backend("cuda-icp", io);
    /// assert_eq!(e.to_string(), "registration backend cuda-icp failed");
    /// // The backend's error is the source, as it was made.
    /// let source = std::error::Error::source(&e).expect("a source");
    /// assert!(source.downcast_ref::<std::io::Error>().is_some());
    /// ```
}

/// What made a registration problem [`RegistrationError::Degenerate`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum Degeneracy {
    /// The normal equations are singular: the correspondences do not fix all six degrees of
    /// freedom.
    #[error("singular normal equations")]
    SingularNormalEquations,
    /// The solved update is not finite.
    #[error("non-finite update")]
    NonFiniteUpdate,
    /// More points than a k-d tree bucket share one coordinate, so the bucket cannot be split.
    #[error("too many points share one coordinate on axis {axis} to split them")]
    CoincidentPoints {
        /// The axis (0 = x, 1 = y, 2 = z).
        axis: usize,
    },
    /// The target's points span fewer than two dimensions: all at one place (`dimensions` 0)
    /// or on one line (1). No pose is determined (a line leaves the rotation about it free), and
    /// nearest-neighbour searches over thousands of equidistant points would take seconds.
    #[error("the target's points span {dimensions} dimension(s): coincident or collinear")]
    DegenerateTarget {
        /// Directions with a spread: 0 or 1.
        dimensions: usize,
    },
}

/// Errors of [`fit_rigid_transform`](crate::geometry::fit_rigid_transform) and
/// [`fit_weighted_rigid_transform`](crate::geometry::fit_weighted_rigid_transform).
#[derive(Debug, Clone, Copy, PartialEq, Error)]
#[non_exhaustive]
pub enum RigidFitError {
    /// The two point sets differ in length.
    #[error("rigid fit: {from} points to move but {to} to land on")]
    LengthMismatch {
        /// Points to move.
        from: usize,
        /// Points to land on.
        to: usize,
    },
    /// Fewer pairs than a rotation needs.
    #[error("rigid fit: {pairs} pairs of positive weight, at least {required} are needed")]
    TooFewPairs {
        /// Pairs of positive weight given.
        pairs: usize,
        /// Pairs needed (3).
        required: usize,
    },
    /// A coordinate is NaN or infinite.
    #[error("rigid fit: pair {index} has a non-finite coordinate")]
    NonFinitePoint {
        /// Index of the pair.
        index: usize,
    },
    /// A weight is negative, NaN or infinite.
    #[error("rigid fit: weight {index} is {weight}: must be finite and not negative")]
    InvalidWeight {
        /// Index of the pair.
        index: usize,
        /// The weight.
        weight: f64,
    },
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
    /// A pose or a measurement is not finite.
    #[error("non-finite {what}")]
    NonFinite {
        /// Which one.
        what: GraphValue,
    },
    /// A robust kernel's parameter is not finite and positive.
    #[error("robust kernel {kernel:?} of edge {edge}: its parameter must be finite and positive")]
    InvalidRobustKernel {
        /// Index the edge would have had.
        edge: usize,
        /// The kernel.
        kernel: RobustKernel,
    },
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
    /// A factorisation or linear solve failed beyond recovery.
    #[error("factorisation failed in {stage}: {cause}")]
    Factorization {
        /// The step that failed (`"symbolic Cholesky"`, `"chordal relaxation"`, ...).
        stage: &'static str,
        /// Why.
        cause: FactorizationFailure,
    },
    /// A third-party optimizer failed for a reason of its own (its error is the
    /// [`source`](std::error::Error::source)); see [`OptimizeError::backend`].
    #[error("optimizer backend {backend} failed")]
    Backend {
        /// The backend's name.
        backend: &'static str,
        /// The backend's own error.
        #[source]
        source: BackendError,
    },
}

backend_constructor! {
    OptimizeError,
    /// An [`OptimizeError::Backend`]: `backend`'s own `error` (any error type, or a message).
    ///
    /// ```
    /// use slam_core::OptimizeError;
    /// let e = OptimizeError::backend("ceres", "the solver ran out of time");
    /// assert_eq!(e.to_string(), "optimizer backend ceres failed");
    /// let source = std::error::Error::source(&e).expect("a source");
    /// assert_eq!(source.to_string(), "the solver ran out of time");
    /// ```
}

/// Which value of a [`PoseGraph`](crate::PoseGraph) an [`OptimizeError::NonFinite`] is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum GraphValue {
    /// The pose of a node.
    NodePose {
        /// The node's id.
        id: u64,
    },
    /// The measurement of an edge.
    Measurement {
        /// Index the edge would have had.
        edge: usize,
        /// Id of the node it starts at.
        from: u64,
        /// Id of the node it ends at.
        to: u64,
    },
    /// The squared error `e^T Omega e` of an edge at the current poses: every number is finite
    /// but the product overflows (a measurement or pose of 1e200 m), or a solver diverged there.
    EdgeError {
        /// Index of the edge.
        edge: usize,
        /// Id of the node it starts at.
        from: u64,
        /// Id of the node it ends at.
        to: u64,
    },
}

impl std::fmt::Display for GraphValue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::NodePose { id } => write!(f, "pose of node {id}"),
            Self::Measurement { edge, from, to } => {
                write!(f, "measurement of edge {edge} ({from} to {to})")
            }
            Self::EdgeError { edge, from, to } => {
                write!(f, "squared error of edge {edge} ({from} to {to})")
            }
        }
    }
}

/// Why a factorisation or solve in [`OptimizeError::Factorization`] failed. The sparse solver's
/// own errors (faer's out-of-memory and index-overflow, which carry nothing more) map onto
/// these one to one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum FactorizationFailure {
    /// The matrix is not positive definite to working precision.
    #[error("the matrix is not positive definite")]
    NotPositiveDefinite,
    /// The solution has a NaN or infinite entry.
    #[error("the solution is not finite")]
    NonFiniteSolution,
    /// Memory for the factor or its scratch could not be allocated.
    #[error("out of memory")]
    OutOfMemory,
    /// The factor has more entries than its index type can address.
    #[error("an index overflows its type")]
    IndexOverflow,
    /// An error of the sparse solver this version does not know.
    #[error("unrecognised sparse solver error")]
    Unrecognised,
}

/// Errors of a [`Planner`](crate::Planner): bad arguments, or a third-party planner's own
/// failure ([`PlanError::Backend`]). An unreachable goal is not an error but the answer
/// `Ok(None)` of [`Planner::plan`](crate::Planner::plan).
#[derive(Debug, Clone, PartialEq, Eq, Error)]
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
    /// A planner failed for a reason of its own, not an argument of the query (its error is
    /// the [`source`](std::error::Error::source)): a third-party planner's fault, or a grid
    /// it cannot plan on. See [`PlanError::backend`].
    #[error("planner backend {backend} failed")]
    Backend {
        /// The backend's name.
        backend: &'static str,
        /// The backend's own error.
        #[source]
        source: BackendError,
    },
}

backend_constructor! {
    PlanError,
    /// A [`PlanError::Backend`]: `backend`'s own `error` (any error type, or a message).
    ///
    /// ```
    /// use slam_core::PlanError;
    /// let e = PlanError::backend("ompl", "the state space is not set up");
    /// assert_eq!(e.to_string(), "planner backend ompl failed");
    /// assert!(std::error::Error::source(&e).is_some());
    /// ```
}

/// Errors of a [`PlaceRecognizer`](crate::PlaceRecognizer).
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum PlaceRecognitionError {
    /// Too few points of the scan fall within the descriptor's ranges to describe it.
    #[error(
        "the scan has {points} points within the descriptor's ranges, at least {required} are needed"
    )]
    TooFewPoints {
        /// Points in range.
        points: usize,
        /// Points needed.
        required: usize,
    },
    /// The recognizer holds as many keyframes as it can number.
    #[error("{what} is full: keyframe {keyframe} is beyond its {max} entries")]
    IndexFull {
        /// The full index.
        what: &'static str,
        /// 1-based number of the keyframe that did not fit.
        keyframe: usize,
        /// Entries it can hold.
        max: usize,
    },
    /// A setting is out of its valid range.
    #[error(transparent)]
    InvalidConfig(#[from] InvalidSetting),
    /// A third-party recognizer failed for a reason of its own (its error is the
    /// [`source`](std::error::Error::source)); see [`PlaceRecognitionError::backend`].
    #[error("place recognition backend {backend} failed")]
    Backend {
        /// The backend's name.
        backend: &'static str,
        /// The backend's own error.
        #[source]
        source: BackendError,
    },
}

backend_constructor! {
    PlaceRecognitionError,
    /// A [`PlaceRecognitionError::Backend`]: `backend`'s own `error` (any error type, or a
    /// message).
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
    /// A finite point lies more than 2^63 voxels from the origin: its voxel cannot be numbered.
    #[error("point {index} lies too far from the origin for voxels of {size} m")]
    VoxelOutOfRange {
        /// The point's index in the cloud.
        index: usize,
        /// The voxel size given.
        size: f32,
    },
}
