//! The `Planner` trait: shortest paths on a [`BitGrid`].
//!
//! Movement model (Moving AI): 8-connected, straight cost 1, diagonal cost sqrt(2), no corner
//! cutting (a diagonal step needs both orthogonal neighbours free). Costs are in cells; multiply by
//! the grid's resolution for metres.

use crate::error::PlanError;
use crate::grid::{BitGrid, Cell};

/// A shortest path found by a [`Planner`].
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct GridPath {
    /// Cells from start to goal inclusive. Consecutive cells may be far apart for planners that
    /// return jump points only; [`GridPath::expand`] fills the gaps with every cell.
    pub cells: Vec<Cell>,
    /// Cost in cells (straight 1, diagonal sqrt(2)).
    pub length: f64,
    /// Nodes the search expanded (taken off its open list), for comparing planners.
    pub expanded: usize,
}

impl GridPath {
    /// The path with every intermediate cell, when `cells` holds turning points joined by straight
    /// or diagonal runs (as JPS returns). Already dense paths come back unchanged.
    #[must_use]
    pub fn expand(&self) -> Vec<Cell> {
        let mut out = Vec::with_capacity(self.cells.len());
        let Some(&first) = self.cells.first() else {
            return out;
        };
        out.push(first);
        for w in self.cells.windows(2) {
            let (a, b) = (w[0], w[1]);
            let dx = (i64::from(b.x) - i64::from(a.x)).signum();
            let dy = (i64::from(b.y) - i64::from(a.y)).signum();
            let (mut x, mut y) = (i64::from(a.x), i64::from(a.y));
            while (x, y) != (i64::from(b.x), i64::from(b.y)) {
                // Diagonal while both axes differ, then straight: the octile shape of a jump.
                if x != i64::from(b.x) {
                    x += dx;
                }
                if y != i64::from(b.y) {
                    y += dy;
                }
                out.push(Cell::new(x as u32, y as u32));
            }
        }
        out
    }
}

/// A shortest-path planner bound to one grid. Construction does the per-grid work (connected
/// components, JPS+ jump tables); [`Planner::plan`] answers queries.
///
/// The contract separates answers from mistakes: an unreachable goal is the answer `Ok(None)`,
/// while an error always means a bad argument (an endpoint off the grid or on a blocked cell), so
/// a caller can never take one for the other.
///
/// ```
/// use slam_core::{BitGrid, Cell, GridPath, PlanError, Planner, validate_endpoints};
///
/// /// A planner that only walks straight east (an illustration of the contract).
/// struct EastOnly<'g>(&'g BitGrid);
///
/// impl Planner for EastOnly<'_> {
///     fn plan(&mut self, start: Cell, goal: Cell) -> Result<Option<GridPath>, PlanError> {
///         validate_endpoints(self.0, start, goal)?;
///         if start.y != goal.y || goal.x < start.x {
///             return Ok(None);
///         }
///         let cells: Vec<Cell> = (start.x..=goal.x).map(|x| Cell::new(x, start.y)).collect();
///         if cells.iter().any(|&c| self.0.is_blocked(c)) {
///             return Ok(None);
///         }
///         Ok(Some(GridPath { length: f64::from(goal.x - start.x), expanded: cells.len(), cells }))
///     }
/// }
///
/// let grid = BitGrid::from_fn(10, 1, |x, _| x == 8)?;
/// let mut east = EastOnly(&grid);
/// let path = east.plan(Cell::new(2, 0), Cell::new(7, 0))?.expect("a free row");
/// assert_eq!(path.length, 5.0);
/// // Unreachable (westward): an answer, not an error.
/// assert_eq!(east.plan(Cell::new(7, 0), Cell::new(2, 0))?, None);
/// // A blocked goal: an error.
/// assert!(matches!(
///     east.plan(Cell::new(2, 0), Cell::new(8, 0)),
///     Err(PlanError::BlockedCell { which: "goal", x: 8, y: 0 })
/// ));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub trait Planner {
    /// A shortest path from `start` to `goal`, or `None` when the goal cannot be reached from the
    /// start (a normal answer).
    ///
    /// # Errors
    /// Only for bad arguments: [`PlanError::OutOfBounds`] or [`PlanError::BlockedCell`] for a
    /// start or goal off the grid or on a blocked cell.
    fn plan(&mut self, start: Cell, goal: Cell) -> Result<Option<GridPath>, PlanError>;
}

/// The checks every planner makes on its endpoints: both on the grid and free.
///
/// # Errors
/// [`PlanError::OutOfBounds`] or [`PlanError::BlockedCell`].
pub fn validate_endpoints(grid: &BitGrid, start: Cell, goal: Cell) -> Result<(), PlanError> {
    for (which, c) in [("start", start), ("goal", goal)] {
        if !grid.contains(c) {
            return Err(PlanError::OutOfBounds {
                which,
                x: c.x,
                y: c.y,
                width: grid.width(),
                height: grid.height(),
            });
        }
        if grid.is_blocked(c) {
            return Err(PlanError::BlockedCell {
                which,
                x: c.x,
                y: c.y,
            });
        }
    }
    Ok(())
}
