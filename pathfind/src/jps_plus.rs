//! Jump Point Search with word-at-a-time scans, and optionally JPS+ jump tables.

use slam_core::{BitGrid, Cell, GridPath, PlanError, Planner};

use crate::block_scan::scan_row;
use crate::components::Components;
use crate::error::PathfindError;
use crate::jump_search::{Jumper, jump_search};
use crate::jump_tables::{JumpTables, MAX_TABLE_SIDE};
use crate::movement::{DIRECTIONS, free};
use crate::search_space::SearchSpace;

/// Jump Point Search whose straight jumps read 64 cells per step (Harabor & Grastien 2014), on
/// the grid's rows and on a transposed copy for columns; or, when built with
/// [`JumpPointSearchPlus::with_jump_tables`], JPS+ with precomputed jump distances (O(1) per
/// jump, 16 bytes per cell, built once per grid).
pub struct JumpPointSearchPlus<'g> {
    grid: &'g BitGrid,
    components: Components,
    space: SearchSpace,
    mode: Mode<'g>,
}

enum Mode<'g> {
    Blocks(BlockJumper<'g>),
    Tables(JumpTables),
}

impl<'g> JumpPointSearchPlus<'g> {
    /// Block-scan JPS for `grid` (builds the transposed grid and the component labels).
    #[must_use]
    pub fn new(grid: &'g BitGrid) -> Self {
        Self {
            grid,
            components: Components::new(grid),
            space: SearchSpace::new(grid.width(), grid.height()),
            mode: Mode::Blocks(BlockJumper {
                grid,
                transposed: grid.transposed(),
            }),
        }
    }

    /// JPS+ for `grid`: precomputes the jump distance of every cell in every direction.
    ///
    /// # Errors
    /// [`PathfindError::GridTooLargeForTables`] when a side exceeds 32,767 cells (use
    /// [`JumpPointSearchPlus::new`] there).
    pub fn with_jump_tables(grid: &'g BitGrid) -> Result<Self, PathfindError> {
        if grid.width() > MAX_TABLE_SIDE || grid.height() > MAX_TABLE_SIDE {
            return Err(PathfindError::GridTooLargeForTables {
                width: grid.width(),
                height: grid.height(),
                max_side: MAX_TABLE_SIDE,
            });
        }
        Ok(Self {
            grid,
            components: Components::new(grid),
            space: SearchSpace::new(grid.width(), grid.height()),
            mode: Mode::Tables(JumpTables::new(grid)),
        })
    }

    /// Bytes of preprocessed data beyond the grid itself (transposed grid or jump tables).
    #[must_use]
    pub fn preprocessed_bytes(&self) -> usize {
        match &self.mode {
            Mode::Blocks(b) => b.transposed.words().len() * 8,
            Mode::Tables(t) => t.bytes(),
        }
    }
}

struct BlockJumper<'g> {
    grid: &'g BitGrid,
    transposed: BitGrid,
}

impl BlockJumper<'_> {
    #[inline]
    fn horizontal(&self, x: u32, y: u32, dx: i32, goal: Cell) -> Option<u32> {
        scan_row(self.grid, x, y, dx > 0, (goal.y == y).then_some(goal.x))
    }

    #[inline]
    fn vertical(&self, x: u32, y: u32, dy: i32, goal: Cell) -> Option<u32> {
        scan_row(
            &self.transposed,
            y,
            x,
            dy > 0,
            (goal.x == x).then_some(goal.y),
        )
    }
}

impl Jumper for BlockJumper<'_> {
    #[inline]
    fn jump(&self, c: Cell, d: u8, goal: Cell) -> Option<Cell> {
        let (dx, dy) = DIRECTIONS[d as usize];
        if dy == 0 {
            return self
                .horizontal(c.x, c.y, dx, goal)
                .map(|x| Cell::new(x, c.y));
        }
        if dx == 0 {
            return self.vertical(c.x, c.y, dy, goal).map(|y| Cell::new(c.x, y));
        }
        let g = self.grid;
        let (mut x, mut y) = (i64::from(c.x), i64::from(c.y));
        let (dx64, dy64) = (i64::from(dx), i64::from(dy));
        loop {
            if !(free(g, x + dx64, y) && free(g, x, y + dy64) && free(g, x + dx64, y + dy64)) {
                return None;
            }
            x += dx64;
            y += dy64;
            let (ux, uy) = (x as u32, y as u32);
            if (ux == goal.x && uy == goal.y)
                || self.horizontal(ux, uy, dx, goal).is_some()
                || self.vertical(ux, uy, dy, goal).is_some()
            {
                return Some(Cell::new(ux, uy));
            }
        }
    }
}

impl Planner for JumpPointSearchPlus<'_> {
    fn plan(&mut self, start: Cell, goal: Cell) -> Result<GridPath, PlanError> {
        match &self.mode {
            Mode::Blocks(j) => {
                jump_search(self.grid, &self.components, &mut self.space, j, start, goal)
            }
            Mode::Tables(j) => {
                jump_search(self.grid, &self.components, &mut self.space, j, start, goal)
            }
        }
    }
}
