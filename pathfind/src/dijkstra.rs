//! Dijkstra's algorithm: the reference every other planner is tested against.

use slam_core::{BitGrid, Cell, GridPath, PlanError, Planner};

use crate::best_first::best_first;
use crate::closed_set::ClosedSet;
use crate::components::Components;
use crate::open_list::CellRing;
use crate::search_space::SearchSpace;

/// Dijkstra's algorithm on the grid (uniform-cost search, no heuristic). Exact and simple; use
/// [`AStar`](crate::AStar) or a jump-point planner for speed.
pub struct Dijkstra<'g> {
    grid: &'g BitGrid,
    components: Components,
    space: SearchSpace<CellRing>,
    closed: ClosedSet,
}

impl<'g> Dijkstra<'g> {
    /// A planner for `grid` (labels its connected components once).
    #[must_use]
    pub fn new(grid: &'g BitGrid) -> Self {
        Self {
            grid,
            components: Components::new(grid),
            space: SearchSpace::new(grid.width(), grid.height()),
            closed: ClosedSet::new(grid),
        }
    }
}

impl Planner for Dijkstra<'_> {
    fn plan(&mut self, start: Cell, goal: Cell) -> Result<Option<GridPath>, PlanError> {
        best_first(
            self.grid,
            &self.components,
            &mut self.space,
            &mut self.closed,
            start,
            goal,
            |_| 0,
        )
    }
}
