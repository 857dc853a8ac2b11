//! Jump Point Search with word-at-a-time scans, and optionally JPS+ jump tables.

use slam_core::{BitGrid, Cell, GridPath, PlanError, Planner};

use crate::block_scan::BlockJumper;
use crate::components::Components;
use crate::error::PathfindError;
use crate::jump_search::jump_search;
use crate::jump_tables::{JumpTables, MAX_TABLE_SIDE};
use crate::search_space::SearchSpace;

/// Jump Point Search with the search mode chosen at construction: [`JumpPointSearchPlus::new`]
/// scans 64 cells per step (Harabor & Grastien 2014; the same online search as
/// [`JumpPointSearch::new`](crate::JumpPointSearch::new)), and
/// [`JumpPointSearchPlus::with_jump_tables`] is JPS+ with precomputed jump distances (O(1) per
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
            mode: Mode::Blocks(BlockJumper::new(grid)),
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
            Mode::Blocks(b) => b.bytes(),
            Mode::Tables(t) => t.bytes(),
        }
    }
}

impl Planner for JumpPointSearchPlus<'_> {
    fn plan(&mut self, start: Cell, goal: Cell) -> Result<Option<GridPath>, PlanError> {
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
