//! Online Jump Point Search (Harabor & Grastien 2011), adapted to no corner cutting.

use slam_core::{BitGrid, Cell, GridPath, PlanError, Planner};

use crate::block_scan::BlockJumper;
use crate::jump_search::{JumpSearch, Jumper};
use crate::movement::{DIRECTIONS, can_step, free};

/// Jump Point Search: A* over jump points found online, with no per-grid tables.
///
/// [`JumpPointSearch::new`] finds straight jumps with 64-cell word scans (the block-based
/// scanning of Harabor & Grastien 2014; vertical runs read a transposed copy of the grid, one
/// more bit per cell). [`JumpPointSearch::with_cell_scans`] steps one cell at a time as in the
/// 2011 paper: slower, kept as the textbook reference and for ablation. For precomputed jump
/// distances (JPS+) see [`JumpPointSearchPlus`](crate::JumpPointSearchPlus).
pub struct JumpPointSearch<'g> {
    search: JumpSearch<'g>,
    scans: Scans<'g>,
}

enum Scans<'g> {
    Words(BlockJumper<'g>),
    Cells(CellJumper<'g>),
}

impl<'g> JumpPointSearch<'g> {
    /// A planner for `grid` with word scans (labels its connected components and transposes the
    /// grid once).
    #[must_use]
    pub fn new(grid: &'g BitGrid) -> Self {
        Self {
            search: JumpSearch::new(grid),
            scans: Scans::Words(BlockJumper::new(grid)),
        }
    }

    /// A planner for `grid` that scans one cell at a time (labels its connected components once).
    #[must_use]
    pub fn with_cell_scans(grid: &'g BitGrid) -> Self {
        Self {
            search: JumpSearch::new(grid),
            scans: Scans::Cells(CellJumper(grid)),
        }
    }

    /// Bytes of preprocessed data beyond the grid and the component labels (the transposed
    /// grid with word scans, nothing with cell scans).
    #[must_use]
    pub fn preprocessed_bytes(&self) -> usize {
        match &self.scans {
            Scans::Words(b) => b.bytes(),
            Scans::Cells(_) => 0,
        }
    }
}

struct CellJumper<'g>(&'g BitGrid);

impl CellJumper<'_> {
    /// Straight jump: the first cell with a forced side, the goal, or `None` at a wall.
    fn straight(&self, mut x: i64, mut y: i64, dx: i64, dy: i64, goal: Cell) -> Option<(i64, i64)> {
        let g = self.0;
        loop {
            x += dx;
            y += dy;
            if !free(g, x, y) {
                return None;
            }
            if x == i64::from(goal.x) && y == i64::from(goal.y) {
                return Some((x, y));
            }
            let forced = if dx != 0 {
                (free(g, x, y + 1) && !free(g, x - dx, y + 1))
                    || (free(g, x, y - 1) && !free(g, x - dx, y - 1))
            } else {
                (free(g, x + 1, y) && !free(g, x + 1, y - dy))
                    || (free(g, x - 1, y) && !free(g, x - 1, y - dy))
            };
            if forced {
                return Some((x, y));
            }
        }
    }
}

impl Jumper for CellJumper<'_> {
    fn jump(&self, c: Cell, d: u8, goal: Cell) -> Option<Cell> {
        let (dx, dy) = DIRECTIONS[d as usize];
        let (dx, dy) = (i64::from(dx), i64::from(dy));
        let (mut x, mut y) = (i64::from(c.x), i64::from(c.y));
        if dx == 0 || dy == 0 {
            return self
                .straight(x, y, dx, dy, goal)
                .map(|(x, y)| Cell::new(x as u32, y as u32));
        }
        loop {
            if !can_step(self.0, x, y, dx, dy) {
                return None;
            }
            x += dx;
            y += dy;
            if (x == i64::from(goal.x) && y == i64::from(goal.y))
                || self.straight(x, y, dx, 0, goal).is_some()
                || self.straight(x, y, 0, dy, goal).is_some()
            {
                return Some(Cell::new(x as u32, y as u32));
            }
        }
    }
}

impl Planner for JumpPointSearch<'_> {
    fn plan(&mut self, start: Cell, goal: Cell) -> Result<Option<GridPath>, PlanError> {
        match &self.scans {
            Scans::Words(j) => self.search.plan(j, start, goal),
            Scans::Cells(j) => self.search.plan(j, start, goal),
        }
    }
}
