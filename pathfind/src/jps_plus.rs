//! JPS+: Jump Point Search over jump distances precomputed per grid (Harabor & Grastien, ICAPS
//! 2014).

use slam_core::{BitGrid, Cell, GridPath, PlanError, Planner};

use crate::error::PathfindError;
use crate::jump_search::JumpSearch;
use crate::jump_tables::{JumpTables, MAX_JUMP_TABLE_CELLS, MAX_TABLE_SIDE};

/// JPS+: the search of [`JumpPointSearch`](crate::JumpPointSearch) with every jump read from
/// tables built once per grid (the distance to the next jump point or wall from every cell in
/// every direction): O(1) per jump, 16 bytes per cell. Worth it when a grid serves hundreds of
/// queries or more (on Moving AI's den520d the tables take 5 ms longer to build than the word
/// scans' transposed grid and save 8 µs per query); otherwise, or for a side above 32,767 cells,
/// use [`JumpPointSearch::new`](crate::JumpPointSearch::new), whose word scans need no tables.
pub struct JumpPointSearchPlus<'g> {
    search: JumpSearch<'g>,
    tables: JumpTables,
}

/// The search (the grid's size); not the jump tables and records.
impl std::fmt::Debug for JumpPointSearchPlus<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("JumpPointSearchPlus")
            .field("search", &self.search)
            .finish_non_exhaustive()
    }
}

impl<'g> JumpPointSearchPlus<'g> {
    /// JPS+ for `grid`: precomputes the jump distance of every cell in every direction (and
    /// labels the grid's connected components).
    ///
    /// # Errors
    /// [`PathfindError::GridTooLargeForTables`] when a side exceeds 32,767 cells (the tables
    /// store distances as `i16`) or the grid has more than [`MAX_JUMP_TABLE_CELLS`] cells.
    pub fn new(grid: &'g BitGrid) -> Result<Self, PathfindError> {
        let cells = u64::from(grid.width()) * u64::from(grid.height());
        if grid.width() > MAX_TABLE_SIDE
            || grid.height() > MAX_TABLE_SIDE
            || cells > MAX_JUMP_TABLE_CELLS
        {
            return Err(PathfindError::GridTooLargeForTables {
                width: grid.width(),
                height: grid.height(),
                max_side: MAX_TABLE_SIDE,
                max_cells: MAX_JUMP_TABLE_CELLS,
            });
        }
        Ok(Self {
            search: JumpSearch::new(grid),
            tables: JumpTables::new(grid),
        })
    }

    /// Bytes of preprocessed data beyond the grid and the component labels (the jump tables).
    #[must_use]
    pub fn preprocessed_bytes(&self) -> usize {
        self.tables.bytes()
    }
}

impl Planner for JumpPointSearchPlus<'_> {
    fn plan(&mut self, start: Cell, goal: Cell) -> Result<Option<GridPath>, PlanError> {
        self.search.plan(&self.tables, start, goal)
    }
}
