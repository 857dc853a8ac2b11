//! The cell-by-cell best-first search behind [`Dijkstra`](crate::Dijkstra) and
//! [`AStar`](crate::AStar), with the state both keep between queries.

use slam_core::{BitGrid, Cell, GridPath, PlanError, validate_endpoints};

use crate::closed_set::ClosedSet;
use crate::components::Components;
use crate::cost::{Cost, STEP};
use crate::movement::DIRECTIONS;
use crate::open_list::CellRing;
use crate::search_space::SearchSpace;

/// A best-first search on one grid: its connected components, labelled once, and search state
/// reused by every query. The planners differ only in the heuristic they pass to
/// [`BestFirst::search`].
pub(crate) struct BestFirst<'g> {
    grid: &'g BitGrid,
    components: Components,
    space: SearchSpace<CellRing>,
    closed: ClosedSet,
}

/// The grid's size; not the labels and search records.
impl std::fmt::Debug for BestFirst<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BestFirst")
            .field("width", &self.grid.width())
            .field("height", &self.grid.height())
            .finish_non_exhaustive()
    }
}

/// What an [`AStar`](crate::AStar) keeps for the next planner on the same grid (see
/// [`AStar::with_memory`](crate::AStar::with_memory)): the component labels and the search
/// records.
pub struct BestFirstMemory {
    labelled: BitGrid,
    components: Components,
    space: SearchSpace<CellRing>,
    closed: ClosedSet,
}

impl std::fmt::Debug for BestFirstMemory {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BestFirstMemory")
            .field("width", &self.labelled.width())
            .field("height", &self.labelled.height())
            .finish_non_exhaustive()
    }
}

impl<'g> BestFirst<'g> {
    /// A search for `grid` (labels its connected components once).
    pub(crate) fn new(grid: &'g BitGrid) -> Self {
        Self {
            grid,
            components: Components::new(grid),
            space: SearchSpace::new(grid.width(), grid.height()),
            closed: ClosedSet::new(grid),
        }
    }

    /// A search for `grid` reusing `memory`: its labels on the grid they were made for
    /// (compared cell by cell), its search records on a grid of the same size.
    pub(crate) fn with_memory(grid: &'g BitGrid, memory: BestFirstMemory) -> Self {
        let same_size =
            (memory.labelled.width(), memory.labelled.height()) == (grid.width(), grid.height());
        if !same_size {
            return Self::new(grid);
        }
        let components = if memory.labelled == *grid {
            memory.components
        } else {
            Components::new(grid)
        };
        Self {
            grid,
            components,
            space: memory.space,
            closed: memory.closed,
        }
    }

    /// What the next search on the same grid can reuse.
    pub(crate) fn into_memory(self) -> BestFirstMemory {
        BestFirstMemory {
            labelled: self.grid.clone(),
            components: self.components,
            space: self.space,
            closed: self.closed,
        }
    }

    /// Search from `start` to `goal` expanding the 8 neighbours of each cell, with priority
    /// `g + heuristic(cell)`; `None` when the goal is unreachable.
    pub(crate) fn search(
        &mut self,
        start: Cell,
        goal: Cell,
        heuristic: impl Fn(Cell) -> Cost,
    ) -> Result<Option<GridPath>, PlanError> {
        let Self {
            grid,
            components,
            space,
            closed,
        } = self;
        let grid = *grid;
        validate_endpoints(grid, start, goal)?;
        if !components.connected(start, goal) {
            return Ok(None);
        }
        closed.reset();
        let (s, t) = (space.index(start), space.index(goal));
        space.start(s, heuristic(start));
        // Index offset of the neighbour in each direction (row-major, rows `width` apart), modulo
        // 2^32.
        let offset = DIRECTIONS.map(|(dx, dy)| {
            dy.cast_unsigned()
                .wrapping_mul(grid.width())
                .wrapping_add(dx.cast_unsigned())
        });
        let mut expanded = 0;
        while let Some((i, g, _)) = space.pop() {
            expanded += 1;
            if i == t {
                return Ok(Some(space.path(s, t, expanded)));
            }
            let c = space.cell(i);
            closed.insert(c);
            let mut steps = closed.legal_open_steps(grid, c);
            while steps != 0 {
                let d = steps.trailing_zeros() as usize;
                steps &= steps - 1;
                let (dx, dy) = DIRECTIONS[d];
                let n = || Cell::new(c.x.wrapping_add_signed(dx), c.y.wrapping_add_signed(dy));
                let j = i.wrapping_add(offset[d]);
                space.relax(j, g + STEP[d], || heuristic(n()), i, d as u8);
            }
        }
        // The open list ran dry: unreachable (the component check above normally answers first).
        Ok(None)
    }
}
