//! `OccupancyGrid`: free, occupied, stairs or unknown per cell, over three bit grids.

use slam_core::{BitGrid, Cell, GridGeometry};

use crate::error::GridMapError;
use crate::extent::CellExtent;
use crate::planning::CellRect;

/// What is known of a cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum CellState {
    /// Seen empty (a ray passed through), or assumed free when no ray casting was done.
    Free,
    /// An obstacle was observed in the height slice.
    Occupied,
    /// Never observed.
    Unknown,
    /// A flight of stairs (see [`crate::stairs_cells`]): neither a wall nor floor to walk on.
    /// Planners on this floor treat it as an obstacle; a stairs controller crosses it.
    Stairs,
}

/// How a planner should treat unknown cells.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum UnknownCells {
    /// Unknown cells are obstacles (safe: the robot stays in mapped space).
    #[default]
    Blocked,
    /// Unknown cells are free (exploration).
    Free,
}

/// A 2D occupancy grid. Cell (0, 0) is the lower-left corner at `geometry().origin`, row `y` grows
/// along world +y, each cell is `geometry().resolution` metres wide. An occupied cell may also
/// hold where in it its obstacle points lie ([`OccupancyGrid::extent`]), for clearances measured
/// from the points.
#[derive(Debug, PartialEq, Eq)]
pub struct OccupancyGrid {
    occupied: BitGrid,
    free: BitGrid,
    stairs: BitGrid,
    /// Per cell, row-major: the box of the obstacle points in it (read only where occupied).
    extents: Vec<CellExtent>,
}

impl Clone for OccupancyGrid {
    fn clone(&self) -> Self {
        Self {
            occupied: self.occupied.clone(),
            free: self.free.clone(),
            stairs: self.stairs.clone(),
            extents: self.extents.clone(),
        }
    }

    /// A copy of `source` in this grid's memory, reallocated only when `source` is larger.
    fn clone_from(&mut self, source: &Self) {
        self.occupied.clone_from(&source.occupied);
        self.free.clone_from(&source.free);
        self.stairs.clone_from(&source.stairs);
        self.extents.clone_from(&source.extents);
    }
}

impl OccupancyGrid {
    /// A grid of `width` x `height` cells, all in state `fill`.
    ///
    /// # Errors
    /// [`GridMapError::Grid`] for an empty or oversized grid.
    pub fn new(
        width: u32,
        height: u32,
        geometry: GridGeometry,
        fill: CellState,
    ) -> Result<Self, GridMapError> {
        let occupied = BitGrid::from_fn(width, height, |_, _| fill == CellState::Occupied)?
            .with_geometry(geometry);
        let free = BitGrid::from_fn(width, height, |_, _| fill == CellState::Free)?
            .with_geometry(geometry);
        let stairs = BitGrid::from_fn(width, height, |_, _| fill == CellState::Stairs)?
            .with_geometry(geometry);
        Ok(Self {
            occupied,
            free,
            stairs,
            extents: vec![CellExtent::CENTRE; width as usize * height as usize],
        })
    }

    /// Columns.
    #[must_use]
    pub fn width(&self) -> u32 {
        self.occupied.width()
    }

    /// Rows.
    #[must_use]
    pub fn height(&self) -> u32 {
        self.occupied.height()
    }

    /// Placement in the world.
    #[must_use]
    pub fn geometry(&self) -> &GridGeometry {
        self.occupied.geometry()
    }

    /// The state of `cell` (`Unknown` off the grid).
    #[must_use]
    pub fn state(&self, cell: Cell) -> CellState {
        if !self.occupied.contains(cell) {
            CellState::Unknown
        } else if self.occupied.is_blocked(cell) {
            CellState::Occupied
        } else if self.free.is_blocked(cell) {
            CellState::Free
        } else if self.stairs.is_blocked(cell) {
            CellState::Stairs
        } else {
            CellState::Unknown
        }
    }

    /// Set the state of `cell` (an occupied cell set so reads as its centre: no points are
    /// recorded in it; see [`Self::set_occupied_within`]).
    ///
    /// # Errors
    /// [`GridMapError::Grid`] when `cell` is off the grid.
    pub fn set(&mut self, cell: Cell, state: CellState) -> Result<(), GridMapError> {
        self.set_cell(cell, state, CellExtent::CENTRE)
    }

    /// Set `cell` occupied with its obstacle points within `extent` (e.g. the union of
    /// [`CellExtent::of_point`] over the points that fell in it).
    ///
    /// # Errors
    /// [`GridMapError::Grid`] when `cell` is off the grid.
    pub fn set_occupied_within(
        &mut self,
        cell: Cell,
        extent: CellExtent,
    ) -> Result<(), GridMapError> {
        self.set_cell(cell, CellState::Occupied, extent)
    }

    fn set_cell(
        &mut self,
        cell: Cell,
        state: CellState,
        extent: CellExtent,
    ) -> Result<(), GridMapError> {
        self.occupied.set(cell, state == CellState::Occupied)?;
        self.free.set(cell, state == CellState::Free)?;
        self.stairs.set(cell, state == CellState::Stairs)?;
        let i = cell.y as usize * self.width() as usize + cell.x as usize;
        self.extents[i] = extent;
        Ok(())
    }

    /// Where in `cell` its obstacle points lie: `Some` for an occupied cell ([`CellExtent::CENTRE`]
    /// when none were recorded), `None` for any other cell and off the grid.
    #[must_use]
    pub fn extent(&self, cell: Cell) -> Option<CellExtent> {
        (self.occupied.contains(cell) && self.occupied.is_blocked(cell))
            .then(|| self.extents[cell.y as usize * self.width() as usize + cell.x as usize])
    }

    /// The smallest rectangle holding every cell whose state differs from `earlier`'s, or whose
    /// obstacle points' [`extent`](Self::extent) does (empty when none does): the rectangle a [`crate::PlanningGrid`] built on `earlier` is
    /// [refreshed](crate::PlanningGrid::refresh) over to match this grid. Word by word, 64 cells
    /// at a time.
    ///
    /// # Errors
    /// [`GridMapError::GeometryMismatch`] when `earlier` is not the same size and placement.
    pub fn changed_from(&self, earlier: &Self) -> Result<CellRect, GridMapError> {
        if (self.width(), self.height()) != (earlier.width(), earlier.height())
            || self.geometry() != earlier.geometry()
        {
            return Err(GridMapError::GeometryMismatch);
        }
        let mut changed = CellRect {
            x0: 0,
            y0: 0,
            x1: 0,
            y1: 0,
        };
        for y in 0..self.height() {
            let pairs = [
                (self.occupied.row_words(y), earlier.occupied.row_words(y)),
                (self.free.row_words(y), earlier.free.row_words(y)),
                (self.stairs.row_words(y), earlier.stairs.row_words(y)),
            ];
            for (now, then) in pairs {
                for (i, (a, b)) in now.iter().zip(then).enumerate() {
                    let diff = a ^ b;
                    if diff == 0 {
                        continue;
                    }
                    // Bit k of word i is column 64 i + k; the padding past the width is set in
                    // both grids, so it never differs.
                    let base = i as u32 * 64;
                    let row = CellRect {
                        x0: base + diff.trailing_zeros(),
                        y0: y,
                        x1: (base + 64 - diff.leading_zeros()).min(self.width()),
                        y1: y + 1,
                    };
                    changed = changed.union(&row);
                }
            }
            // Cells occupied in both whose points moved within them.
            let (now, then) = (self.occupied.row_words(y), earlier.occupied.row_words(y));
            let base = y as usize * self.width() as usize;
            for (i, (a, b)) in now.iter().zip(then).enumerate() {
                let mut both = a & b;
                while both != 0 {
                    let x = i as u32 * 64 + both.trailing_zeros();
                    both &= both - 1;
                    if x < self.width()
                        && self.extents[base + x as usize] != earlier.extents[base + x as usize]
                    {
                        changed = changed.union(&CellRect::cell(Cell::new(x, y)));
                    }
                }
            }
        }
        Ok(changed)
    }

    /// Occupied cells as a bit grid (1 = occupied).
    #[must_use]
    pub fn occupied(&self) -> &BitGrid {
        &self.occupied
    }

    /// Known-free cells as a bit grid (1 = free).
    #[must_use]
    pub fn known_free(&self) -> &BitGrid {
        &self.free
    }

    /// Mark the cells set in `stairs` (a grid of this one's size and placement, e.g. from
    /// [`crate::stairs_cells`]) as [`CellState::Stairs`], whatever they were. Word by word.
    ///
    /// # Errors
    /// [`GridMapError::GeometryMismatch`] when `stairs` is not the size and placement of this
    /// grid.
    pub fn mark_stairs(&mut self, stairs: &BitGrid) -> Result<(), GridMapError> {
        if (stairs.width(), stairs.height()) != (self.width(), self.height())
            || stairs.geometry() != self.geometry()
        {
            return Err(GridMapError::GeometryMismatch);
        }
        for y in 0..self.height() {
            let marks = stairs.row_words(y);
            for (s, m) in self.stairs.row_words_mut(y).iter_mut().zip(marks) {
                *s |= *m;
            }
            for (o, m) in self.occupied.row_words_mut(y).iter_mut().zip(marks) {
                *o &= !*m;
            }
            for (f, m) in self.free.row_words_mut(y).iter_mut().zip(marks) {
                *f &= !*m;
            }
        }
        // The padding past the width: as the other grids keep it.
        self.stairs.restore_padding();
        // No obstacle points are kept in stairs cells.
        let w = self.width() as usize;
        for y in 0..self.height() {
            for (x, e) in self.extents[y as usize * w..(y as usize + 1) * w]
                .iter_mut()
                .enumerate()
            {
                if stairs.is_blocked(Cell::new(x as u32, y)) {
                    *e = CellExtent::CENTRE;
                }
            }
        }
        self.occupied.restore_padding();
        self.free.restore_padding();
        Ok(())
    }

    /// Stairs cells as a bit grid (1 = stairs).
    #[must_use]
    pub fn stairs(&self) -> &BitGrid {
        &self.stairs
    }

    /// The grid a planner on this floor searches: occupied and stairs cells blocked, unknown
    /// cells as `unknown` says.
    #[must_use]
    pub fn to_planning_grid(&self, unknown: UnknownCells) -> BitGrid {
        let mut out = self.occupied.clone();
        for y in 0..self.height() {
            let (free, stairs) = (self.free.row_words(y), self.stairs.row_words(y));
            for ((o, f), s) in out.row_words_mut(y).iter_mut().zip(free).zip(stairs) {
                // Blocked unless known free when unknown is blocked; occupied stays blocked.
                *o |= *s;
                if unknown == UnknownCells::Blocked {
                    *o |= !f;
                }
            }
        }
        out.restore_padding();
        out
    }

    /// Number of cells in each state: (free, occupied, unknown); stairs cells are in none of
    /// them ([`BitGrid::count_blocked`] of [`Self::stairs`] counts them).
    #[must_use]
    pub fn counts(&self) -> (usize, usize, usize) {
        let occupied = self.occupied.count_blocked();
        let free = self.free.count_blocked();
        let stairs = self.stairs.count_blocked();
        (
            free,
            occupied,
            self.occupied.len() - free - occupied - stairs,
        )
    }
}
