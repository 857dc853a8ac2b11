//! Dijkstra's algorithm: the reference every other planner is tested against.

use slam_core::{BitGrid, Cell, GridPath, PlanError, Planner};

use crate::best_first::BestFirst;

/// Dijkstra's algorithm on the grid (uniform-cost search, no heuristic). Exact and simple; use
/// [`AStar`](crate::AStar) or a jump-point planner for speed.
#[derive(Debug)]
pub struct Dijkstra<'g> {
    search: BestFirst<'g>,
}

impl<'g> Dijkstra<'g> {
    /// A planner for `grid` (labels its connected components once).
    #[must_use]
    pub fn new(grid: &'g BitGrid) -> Self {
        Self {
            search: BestFirst::new(grid),
        }
    }
}

impl Planner for Dijkstra<'_> {
    fn plan(&mut self, start: Cell, goal: Cell) -> Result<Option<GridPath>, PlanError> {
        self.search.search(start, goal, |_| 0)
    }
}
