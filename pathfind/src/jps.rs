//! Online Jump Point Search (Harabor & Grastien 2011), adapted to no corner cutting.

use slam_core::{BitGrid, Cell, GridPath, PlanError, Planner};

use crate::block_scan::BlockJumper;
use crate::components::Components;
use crate::jump_search::{JumpSearch, Jumper};
use crate::movement::{DIRECTIONS, can_step, free};
use crate::search_space::SearchSpace;

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

/// The search (the grid's size) and which scans it uses; not the tables and records.
impl std::fmt::Debug for JumpPointSearch<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let scans = match self.scans {
            Scans::Words(_) => "words",
            Scans::Cells(_) => "cells",
        };
        f.debug_struct("JumpPointSearch")
            .field("search", &self.search)
            .field("scans", &scans)
            .finish_non_exhaustive()
    }
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

/// What a [`JumpPointSearch`] keeps for the next planner on the same grid
/// ([`JumpPointSearch::into_memory`], [`JumpPointSearch::with_memory`]): the component labels,
/// the search records and, with word scans, the transposed grid.
pub struct JumpPointSearchMemory {
    labelled: BitGrid,
    components: Components,
    space: SearchSpace,
    transposed: Option<BitGrid>,
}

impl std::fmt::Debug for JumpPointSearchMemory {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("JumpPointSearchMemory")
            .field("width", &self.labelled.width())
            .field("height", &self.labelled.height())
            .finish_non_exhaustive()
    }
}

impl<'g> JumpPointSearch<'g> {
    /// A planner for `grid` with word scans that reuses an earlier planner's memory
    /// ([`Self::into_memory`]): on the grid it was made for (compared cell by cell) its labels and
    /// transposed grid, on a grid of the same size its search records. The paths are those of
    /// a new planner.
    ///
    /// ```
    /// use pathfind::JumpPointSearch;
    /// use slam_core::{BitGrid, Cell, Planner};
    ///
    /// let mut grid = BitGrid::new(30, 30)?;
    /// let mut planner = JumpPointSearch::new(&grid);
    /// assert!(planner.plan(Cell::new(0, 0), Cell::new(29, 29))?.is_some());
    /// let memory = planner.into_memory();
    /// for y in 0..30 {
    ///     grid.set(Cell::new(15, y), true)?;
    /// }
    /// let mut planner = JumpPointSearch::with_memory(&grid, memory);
    /// assert_eq!(planner.plan(Cell::new(0, 0), Cell::new(29, 29))?, None);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    #[must_use]
    pub fn with_memory(grid: &'g BitGrid, memory: JumpPointSearchMemory) -> Self {
        let search =
            JumpSearch::with_parts(grid, &memory.labelled, memory.components, memory.space);
        let scans = match memory.transposed {
            Some(t) => BlockJumper::reusing(grid, &memory.labelled, t),
            None => BlockJumper::new(grid),
        };
        Self {
            search,
            scans: Scans::Words(scans),
        }
    }

    /// What a later planner on the same grid can reuse ([`Self::with_memory`]).
    #[must_use]
    pub fn into_memory(self) -> JumpPointSearchMemory {
        let (labelled, transposed) = match self.scans {
            Scans::Words(b) => (b.grid().clone(), Some(b.into_transposed())),
            Scans::Cells(c) => (c.0.clone(), None),
        };
        let (components, space) = self.search.into_parts();
        JumpPointSearchMemory {
            labelled,
            components,
            space,
            transposed,
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
