//! The search loop shared by the jump-point planners: pruning rules for the no-corner-cutting
//! movement model and best-first search over jump points.
//!
//! Pruning (derived for strict no-corner-cutting; a diagonal step needs both orthogonal
//! neighbours free, which removes the diagonal forced neighbours of the 2011 rules):
//! - arriving diagonally `(dx, dy)`: continue `(dx, dy)`, `(dx, 0)` and `(0, dy)` only; a cell
//!   beside the diagonal is always reached as cheaply through one of those.
//! - arriving straight `(dx, 0)`: continue `(dx, 0)`; the side `s` is forced when `(x, y + s)` is
//!   free but `(x - dx, y + s)` is blocked (the side cell could not be reached diagonally from the
//!   previous cell), and then both `(0, s)` and `(dx, s)` are added.
//! - a straight jump stops at a cell with a forced side; a diagonal jump stops at a cell from which
//!   one of its straight components finds a jump point (or the goal).

use slam_core::{BitGrid, Cell, GridPath, PlanError, validate_endpoints};

use crate::components::Components;
use crate::cost::octile;
use crate::movement::{DIRECTIONS, can_step, free};
use crate::search_space::{NO_DIRECTION, SearchSpace};

/// Direction index of `(dx, dy)` in [`DIRECTIONS`].
#[inline]
pub(crate) fn direction_index(dx: i64, dy: i64) -> u8 {
    match (dx, dy) {
        (1, 0) => 0,
        (-1, 0) => 1,
        (0, 1) => 2,
        (0, -1) => 3,
        (1, 1) => 4,
        (1, -1) => 5,
        (-1, 1) => 6,
        _ => 7,
    }
}

/// Bit mask of the directions to search from `(x, y)` after arriving in direction `arrive`.
#[inline]
pub(crate) fn pruned_directions(grid: &BitGrid, x: i64, y: i64, arrive: u8) -> u8 {
    if arrive == NO_DIRECTION {
        let mut m = 0u8;
        for (d, &(dx, dy)) in DIRECTIONS.iter().enumerate() {
            if can_step(grid, x, y, i64::from(dx), i64::from(dy)) {
                m |= 1 << d;
            }
        }
        return m;
    }
    let (dx, dy) = DIRECTIONS[arrive as usize];
    let (dx, dy) = (i64::from(dx), i64::from(dy));
    let mut m = 0u8;
    if dx != 0 && dy != 0 {
        if free(grid, x + dx, y) {
            m |= 1 << direction_index(dx, 0);
        }
        if free(grid, x, y + dy) {
            m |= 1 << direction_index(0, dy);
        }
        if can_step(grid, x, y, dx, dy) {
            m |= 1 << arrive;
        }
    } else if dx != 0 {
        let ahead = free(grid, x + dx, y);
        if ahead {
            m |= 1 << arrive;
        }
        for s in [1i64, -1] {
            if free(grid, x, y + s) && !free(grid, x - dx, y + s) {
                m |= 1 << direction_index(0, s);
                if ahead && free(grid, x + dx, y + s) {
                    m |= 1 << direction_index(dx, s);
                }
            }
        }
    } else {
        let ahead = free(grid, x, y + dy);
        if ahead {
            m |= 1 << arrive;
        }
        for s in [1i64, -1] {
            if free(grid, x + s, y) && !free(grid, x + s, y - dy) {
                m |= 1 << direction_index(s, 0);
                if ahead && free(grid, x + s, y + dy) {
                    m |= 1 << direction_index(s, dy);
                }
            }
        }
    }
    m
}

/// Finds the next jump point from a cell in one direction.
pub(crate) trait Jumper {
    /// The successor of `c` in direction `d` (an index into [`DIRECTIONS`]): a jump point, the
    /// goal, or a cell lined up with the goal; `None` when the jump runs into a wall.
    fn jump(&self, c: Cell, d: u8, goal: Cell) -> Option<Cell>;
}

/// What every jump-point planner holds besides its jumper: the grid, its component labels and
/// the search records, built once per grid.
pub(crate) struct JumpSearch<'g> {
    grid: &'g BitGrid,
    components: Components,
    space: SearchSpace,
}

/// The grid's size; not the labels and search records.
impl std::fmt::Debug for JumpSearch<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("JumpSearch")
            .field("width", &self.grid.width())
            .field("height", &self.grid.height())
            .finish_non_exhaustive()
    }
}

impl<'g> JumpSearch<'g> {
    /// The search state for `grid` (labels its connected components).
    pub(crate) fn new(grid: &'g BitGrid) -> Self {
        Self {
            grid,
            components: Components::new(grid),
            space: SearchSpace::new(grid.width(), grid.height()),
        }
    }

    /// The search state for `grid` reusing `components` when `labelled` is the same grid
    /// (compared cell by cell) and `space` when it has the same size.
    pub(crate) fn with_parts(
        grid: &'g BitGrid,
        labelled: &BitGrid,
        components: Components,
        space: SearchSpace,
    ) -> Self {
        if (labelled.width(), labelled.height()) != (grid.width(), grid.height()) {
            return Self::new(grid);
        }
        Self {
            grid,
            components: if labelled == grid {
                components
            } else {
                Components::new(grid)
            },
            space,
        }
    }

    /// The labels and the search records, for [`Self::with_parts`].
    pub(crate) fn into_parts(self) -> (Components, SearchSpace) {
        (self.components, self.space)
    }

    /// A shortest path from `start` to `goal` with successors from `jumper` (see
    /// [`jump_search`]).
    pub(crate) fn plan(
        &mut self,
        jumper: &impl Jumper,
        start: Cell,
        goal: Cell,
    ) -> Result<Option<GridPath>, PlanError> {
        jump_search(
            self.grid,
            &self.components,
            &mut self.space,
            jumper,
            start,
            goal,
        )
    }
}

/// Best-first search over jump points; returns the jump points as the path's cells, or `None`
/// when the goal is unreachable.
fn jump_search(
    grid: &BitGrid,
    components: &Components,
    space: &mut SearchSpace,
    jumper: &impl Jumper,
    start: Cell,
    goal: Cell,
) -> Result<Option<GridPath>, PlanError> {
    validate_endpoints(grid, start, goal)?;
    if !components.connected(start, goal) {
        return Ok(None);
    }
    let (s, t) = (space.index(start), space.index(goal));
    space.start(s, octile(start, goal));
    let mut expanded = 0;
    while let Some((i, g, arrive)) = space.pop() {
        expanded += 1;
        if i == t {
            return Ok(Some(space.path(s, t, expanded)));
        }
        let c = space.cell(i);
        let mut dirs = pruned_directions(grid, i64::from(c.x), i64::from(c.y), arrive);
        while dirs != 0 {
            let d = dirs.trailing_zeros() as u8;
            dirs &= dirs - 1;
            if let Some(n) = jumper.jump(c, d, goal) {
                space.relax(space.index(n), g + octile(c, n), || octile(n, goal), i, d);
            }
        }
    }
    // The open list ran dry: unreachable (the component check above normally answers first).
    Ok(None)
}
