//! Errors of the pathfind crate (planning itself reports [`slam_core::PlanError`]).

use thiserror::Error;

/// Errors building planners and reading Moving AI files.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum PathfindError {
    /// JPS+ tables store distances as `i16` (a side limit) and take 16 bytes per cell (a total
    /// limit).
    #[error(
        "a {width}x{height} grid is too large for jump tables (at most {max_side} per side and {max_cells} cells)"
    )]
    GridTooLargeForTables {
        /// Grid width.
        width: u32,
        /// Grid height.
        height: u32,
        /// The side limit.
        max_side: u32,
        /// The total limit, [`MAX_JUMP_TABLE_CELLS`](crate::MAX_JUMP_TABLE_CELLS).
        max_cells: u64,
    },
    /// A per-cell cost array does not have one value per cell.
    #[error("{got} cell costs for a {width}x{height} grid (one per cell expected)")]
    CellCostCount {
        /// Values given.
        got: usize,
        /// Grid width.
        width: u32,
        /// Grid height.
        height: u32,
    },
    /// A free cell's cost multiplier is not finite or is below 1.
    #[error("cell ({x}, {y}) has cost multiplier {value}: must be finite and at least 1")]
    InvalidCellCost {
        /// Column.
        x: u32,
        /// Row.
        y: u32,
        /// The multiplier given.
        value: f64,
    },
    /// The multipliers are too large for the grid: the costliest path could overflow the
    /// search's fixed-point costs.
    #[error(
        "cost multipliers up to {largest} on {cells} free cells: their product must stay below 5e13"
    )]
    CellCostsTooLarge {
        /// The largest multiplier on a free cell.
        largest: f64,
        /// Free cells.
        cells: usize,
    },
    /// A Moving AI file could not be parsed.
    #[error("line {line}: {message}")]
    Parse {
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The grid could not be built.
    #[error(transparent)]
    Grid(#[from] slam_core::GridError),
}
