//! A* with the octile heuristic.

use slam_core::{BitGrid, Cell, GridPath, PlanError, Planner};

use crate::best_first::BestFirst;
use crate::cost::octile;

/// A* with the octile-distance heuristic (admissible and consistent for this movement model, so
/// the first time the goal is expanded its cost is optimal). Ties in `f` go to the larger `g`.
pub struct AStar<'g> {
    search: BestFirst<'g>,
}

impl<'g> AStar<'g> {
    /// A planner for `grid` (labels its connected components once).
    #[must_use]
    pub fn new(grid: &'g BitGrid) -> Self {
        Self {
            search: BestFirst::new(grid),
        }
    }
}

impl Planner for AStar<'_> {
    fn plan(&mut self, start: Cell, goal: Cell) -> Result<Option<GridPath>, PlanError> {
        self.search.search(start, goal, |c| octile(c, goal))
    }
}
