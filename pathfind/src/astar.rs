//! A* with the octile heuristic.

use slam_core::{BitGrid, Cell, GridPath, PlanError, Planner};

use crate::best_first::{BestFirst, BestFirstMemory};
use crate::cost::octile;

/// A* with the octile-distance heuristic (admissible and consistent for this movement model, so
/// the first time the goal is expanded its cost is optimal). Ties in `f` go to the larger `g`.
#[derive(Debug)]
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

    /// A planner for `grid` that reuses an earlier planner's memory ([`Self::into_memory`]): its
    /// component labels on the grid they were made for (compared cell by cell), its search
    /// records on a grid of the same size. The paths are those of a new planner.
    #[must_use]
    pub fn with_memory(grid: &'g BitGrid, memory: BestFirstMemory) -> Self {
        Self {
            search: BestFirst::with_memory(grid, memory),
        }
    }

    /// What a later planner on the same grid can reuse ([`Self::with_memory`]).
    #[must_use]
    pub fn into_memory(self) -> BestFirstMemory {
        self.search.into_memory()
    }
}

impl Planner for AStar<'_> {
    fn plan(&mut self, start: Cell, goal: Cell) -> Result<Option<GridPath>, PlanError> {
        self.search.search(start, goal, |c| octile(c, goal))
    }
}
