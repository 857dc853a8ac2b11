//! A* with the octile heuristic.

use slam_core::{BitGrid, Cell, GridPath, PlanError, Planner};

use crate::best_first::best_first;
use crate::closed_set::ClosedSet;
use crate::components::Components;
use crate::cost::octile;
use crate::open_list::CellRing;
use crate::search_space::SearchSpace;

/// A* with the octile-distance heuristic (admissible and consistent for this movement model, so
/// the first time the goal is expanded its cost is optimal). Ties in `f` go to the larger `g`.
pub struct AStar<'g> {
    grid: &'g BitGrid,
    components: Components,
    space: SearchSpace<CellRing>,
    closed: ClosedSet,
}

impl<'g> AStar<'g> {
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

impl Planner for AStar<'_> {
    fn plan(&mut self, start: Cell, goal: Cell) -> Result<Option<GridPath>, PlanError> {
        best_first(
            self.grid,
            &self.components,
            &mut self.space,
            &mut self.closed,
            start,
            goal,
            |c| octile(c, goal),
        )
    }
}
