//! The planner a [`Navigator`](crate::nav::Navigator) plans with: any [`NavPlanner`], ours
//! ([`PlannerKind`]) or a user's own.

use gridmap::PlanningGrid;
use pathfind::{
    AStar, BestFirstMemory, CellCostAStar, CellCostMemory, JumpPointSearch, JumpPointSearchMemory,
};
use slam_core::{Cell, GridPath, PlanError, Planner};

use crate::nav::config::PlannerKind;

/// A planner the [`Navigator`](crate::nav::Navigator) plans with. The navigator plans on
/// grids that change as it goes (the map's occupancy with what the scans show, hard-inflated),
/// so it hands the grid to each query; a [`slam_core::Planner`], which is built for one grid,
/// plugs in by building itself on it. The navigator plans on two grids (the live one and the
/// map's own, to see how far the way round something new is) and keeps a
/// [`NavPlanner::Memory`] for each, so a planner can reuse what it built for a grid while the
/// grid does not change.
///
/// [`PlannerKind`] (one of pathfind's planners, the default) is a `NavPlanner`; plug in your own
/// with [`Navigator::with_planner`](crate::nav::Navigator::with_planner).
///
/// The contract is [`Planner::plan`]'s: `Ok(None)` when no path joins the endpoints (an answer),
/// an error only for a fault. The navigator gives endpoints on free cells of the grid and checks
/// the path it gets back (every cell free, 8-connected steps without cutting corners, from the
/// start to the goal).
///
/// ```
/// use gridmap::PlanningGrid;
/// use pathfind::Dijkstra;
/// use slam_core::{Cell, GridPath, PlanError, Planner};
/// use spot_adapter::nav::NavPlanner;
///
/// /// Dijkstra's algorithm built afresh for each query, counting its queries.
/// #[derive(Debug, Default)]
/// struct CountingDijkstra {
///     queries: usize,
/// }
///
/// impl NavPlanner for CountingDijkstra {
///     type Memory = ();
///
///     fn plan(
///         &mut self,
///         grid: &PlanningGrid,
///         _memory: &mut (),
///         start: Cell,
///         goal: Cell,
///     ) -> Result<Option<GridPath>, PlanError> {
///         self.queries += 1;
///         Dijkstra::new(grid.blocked()).plan(start, goal)
///     }
/// }
///
/// // A 10 x 10 m room of free cells, 0.1 m each.
/// let cells = slam_core::GridGeometry { resolution: 0.1, ..Default::default() };
/// let occupancy = gridmap::OccupancyGrid::new(100, 100, cells, gridmap::CellState::Free)?;
/// let grid = PlanningGrid::new(&occupancy, gridmap::PlanningGridConfig::default())?;
/// let mut planner = CountingDijkstra::default();
/// let path = planner.plan(&grid, &mut (), Cell::new(20, 20), Cell::new(80, 30))?;
/// assert_eq!(path.expect("a free room").cells.last(), Some(&Cell::new(80, 30)));
/// assert_eq!(planner.queries, 1);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub trait NavPlanner {
    /// What the planner keeps from one query to the next on a grid (`()` for nothing): the
    /// navigator keeps one per grid it plans on, starting from `Default`.
    type Memory: Default;

    /// A path on `grid` from `start` to `goal` (free cells of `grid.blocked()`), or `None` when
    /// the goal cannot be reached from the start. `memory` is what this planner kept from its
    /// last query on the same grid, which may have changed since.
    ///
    /// # Errors
    /// The planner's own failure, e.g. [`PlanError::Backend`] carrying its error.
    fn plan(
        &mut self,
        grid: &PlanningGrid,
        memory: &mut Self::Memory,
        start: Cell,
        goal: Cell,
    ) -> Result<Option<GridPath>, PlanError>;
}

/// What one of our planners ([`PlannerKind`]) keeps from one plan to the next on a grid (its
/// component labels, search records and, for JPS, the transposed grid): a replan on an
/// unchanged map builds none of them again, and on a changed one only what depends on the
/// cells. A cache: a clone starts empty.
#[derive(Debug, Default)]
pub struct PlannerMemory(Kept);

/// The memory of the last planner that ran.
#[derive(Debug, Default)]
enum Kept {
    #[default]
    Nothing,
    CellCost(CellCostMemory),
    AStar(BestFirstMemory),
    Jps(JumpPointSearchMemory),
}

impl Clone for PlannerMemory {
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl NavPlanner for PlannerKind {
    type Memory = PlannerMemory;

    /// The path by this planner, reusing and keeping `memory`.
    ///
    /// # Errors
    /// [`PlanError::Backend`] with pathfind's error when [`PlannerKind::CellCostAStar`] refuses
    /// the grid's step costs (not one per cell, below 1, not finite, or too large), which
    /// gridmap's planning grids rule out.
    fn plan(
        &mut self,
        grid: &PlanningGrid,
        memory: &mut PlannerMemory,
        start: Cell,
        goal: Cell,
    ) -> Result<Option<GridPath>, PlanError> {
        let kept = std::mem::take(&mut memory.0);
        let blocked = grid.blocked();
        let (found, kept) = match self {
            Self::CellCostAStar => {
                let costs = grid.step_costs();
                let mut search = match kept {
                    Kept::CellCost(kept) => CellCostAStar::with_memory(blocked, costs, kept),
                    _ => CellCostAStar::new(blocked, costs),
                }
                .map_err(|e| PlanError::backend("CellCostAStar", e))?;
                let found = search.plan(start, goal);
                (found, Kept::CellCost(search.into_memory()))
            }
            Self::JumpPointSearch => {
                let mut search = match kept {
                    Kept::Jps(kept) => JumpPointSearch::with_memory(blocked, kept),
                    _ => JumpPointSearch::new(blocked),
                };
                let found = search.plan(start, goal);
                (found, Kept::Jps(search.into_memory()))
            }
            Self::AStar => {
                let mut search = match kept {
                    Kept::AStar(kept) => AStar::with_memory(blocked, kept),
                    _ => AStar::new(blocked),
                };
                let found = search.plan(start, goal);
                (found, Kept::AStar(search.into_memory()))
            }
        };
        memory.0 = kept;
        found
    }
}
