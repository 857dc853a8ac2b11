//! Word-at-a-time straight jumps (Harabor & Grastien 2014, "Improving Jump Point Search"): 64
//! cells of a row and of its two neighbouring rows are read as aligned words, and
//! `trailing_zeros` / `leading_zeros` find the first blocked cell and the first forced cell at
//! once. Columns are scanned as rows of the transposed grid.

use slam_core::{BitGrid, Cell};

use crate::jump_search::Jumper;

/// Scan row `y` of `grid` from column `x` east (`EAST`) or west. Returns the column of the first
/// jump point (a cell whose side is free while the side cell behind it is blocked) or of the goal
/// column `goal` when it comes first; `None` when a wall comes first. `wall` is a row of
/// `grid.stride_words()` blocked words that stands in for rows off the grid.
// Inlined into each jump direction so the scan's direction is a constant there (measured: LLVM
// keeps one out-of-line copy with plain `#[inline]`).
#[allow(clippy::inline_always)]
#[inline(always)]
fn scan_row<const EAST: bool>(
    grid: &BitGrid,
    wall: &[u64],
    x: u32,
    y: u32,
    goal: Option<u32>,
) -> Option<u32> {
    let here = grid.row_words(y);
    let above = if y + 1 < grid.height() {
        grid.row_words(y + 1)
    } else {
        wall
    };
    let below = if y > 0 { grid.row_words(y - 1) } else { wall };
    let stop = if EAST {
        scan_east(here, above, below, x)
    } else {
        scan_west(here, above, below, x)
    };
    if let Some(g) = goal {
        // The goal lies ahead, before the wall and not after the jump point.
        let (ahead, before_stop) = match (EAST, stop) {
            (true, Stop::Jump(j)) => (g > x, g <= j),
            (true, Stop::Wall(w)) => (g > x, i64::from(g) < w),
            (false, Stop::Jump(j)) => (g < x, g >= j),
            (false, Stop::Wall(w)) => (g < x, i64::from(g) > w),
        };
        if ahead && before_stop {
            return Some(g);
        }
    }
    match stop {
        Stop::Jump(j) => Some(j),
        Stop::Wall(_) => None,
    }
}

/// Where a straight scan ends.
#[derive(Clone, Copy)]
enum Stop {
    /// At a jump point (this column).
    Jump(u32),
    /// At a blocked column, or one past the grid's edge (-1 to the west, the width to the east).
    Wall(i64),
}

/// The stop among the set bits of `forced | blocked` at bit `b` of word `i`: a blocked cell is a
/// wall even where its side looks forced.
#[inline]
fn stop_at(blocked: u64, i: usize, b: u32) -> Stop {
    let column = i as u32 * 64 + b;
    if blocked >> b & 1 != 0 {
        Stop::Wall(i64::from(column))
    } else {
        Stop::Jump(column)
    }
}

/// Scan east of column `x` along `here`, with the rows `above` and `below` (same length).
#[allow(clippy::inline_always)]
#[inline(always)]
fn scan_east(here: &[u64], above: &[u64], below: &[u64], x: u32) -> Stop {
    let first = (x / 64) as usize;
    // Only cells after x count.
    let mut mask = (u64::MAX << (x % 64)) << 1;
    let (mut carry_up, mut carry_down) = (0u64, 0u64);
    let words = here[first..]
        .iter()
        .zip(&above[first..])
        .zip(&below[first..]);
    for (i, ((&h, &u), &d)) in (first..).zip(words) {
        // Forced at bit b: side free at b, side blocked at b - 1 (bit 0 looks at the word before).
        let forced = (!u & ((u << 1) | carry_up)) | (!d & ((d << 1) | carry_down));
        let blocked = h & mask;
        let stops = (forced & mask) | blocked;
        if stops != 0 {
            return stop_at(blocked, i, stops.trailing_zeros());
        }
        carry_up = u >> 63;
        carry_down = d >> 63;
        mask = u64::MAX;
    }
    // Padding bits past the width are blocked; a width that fills its last word has none.
    Stop::Wall(here.len() as i64 * 64)
}

/// Scan west of column `x` along `here`, with the rows `above` and `below` (same length).
#[allow(clippy::inline_always)]
#[inline(always)]
fn scan_west(here: &[u64], above: &[u64], below: &[u64], x: u32) -> Stop {
    let first = (x / 64) as usize;
    // Only cells before x count.
    let mut mask = (1u64 << (x % 64)) - 1;
    let (mut carry_up, mut carry_down) = (0u64, 0u64);
    let words = here[..=first]
        .iter()
        .zip(&above[..=first])
        .zip(&below[..=first])
        .enumerate()
        .rev();
    for (i, ((&h, &u), &d)) in words {
        // Travelling west, the cell behind b is b + 1 (bit 63 looks at the word after).
        let forced = (!u & ((u >> 1) | carry_up)) | (!d & ((d >> 1) | carry_down));
        let blocked = h & mask;
        let stops = (forced & mask) | blocked;
        if stops != 0 {
            // The highest set bit is the first stop going west.
            return stop_at(blocked, i, stops.ilog2());
        }
        carry_up = u << 63;
        carry_down = d << 63;
        mask = u64::MAX;
    }
    Stop::Wall(-1)
}

/// Jumps by word scans: rows of the grid for horizontal runs, rows of the transposed grid for
/// vertical runs, and diagonal runs one step at a time with a word scan along both components.
pub(crate) struct BlockJumper<'g> {
    grid: &'g BitGrid,
    transposed: BitGrid,
    /// Blocked words standing in for the rows beyond the edges of either grid.
    wall: Vec<u64>,
}

impl<'g> BlockJumper<'g> {
    /// Builds the transposed grid (one more bit per cell).
    pub(crate) fn new(grid: &'g BitGrid) -> Self {
        let transposed = grid.transposed();
        let wall = vec![u64::MAX; grid.stride_words().max(transposed.stride_words())];
        Self {
            grid,
            transposed,
            wall,
        }
    }

    /// The jumper for `grid` reusing `transposed` when `of` is the same grid (compared cell by
    /// cell).
    pub(crate) fn reusing(grid: &'g BitGrid, of: &BitGrid, transposed: BitGrid) -> Self {
        if of != grid {
            return Self::new(grid);
        }
        let wall = vec![u64::MAX; grid.stride_words().max(transposed.stride_words())];
        Self {
            grid,
            transposed,
            wall,
        }
    }

    /// The grid it scans.
    pub(crate) fn grid(&self) -> &'g BitGrid {
        self.grid
    }

    /// The transposed grid, for [`Self::reusing`].
    pub(crate) fn into_transposed(self) -> BitGrid {
        self.transposed
    }

    /// Bytes of the transposed grid.
    pub(crate) fn bytes(&self) -> usize {
        self.transposed.words().len() * 8
    }

    /// The next stop of a horizontal jump from `(x, y)`, east when `EAST`.
    // Inlined into the diagonal loop (measured: a call per step otherwise).
    #[allow(clippy::inline_always)]
    #[inline(always)]
    fn horizontal<const EAST: bool>(&self, x: u32, y: u32, goal: Cell) -> Option<u32> {
        let wall = &self.wall[..self.grid.stride_words()];
        scan_row::<EAST>(self.grid, wall, x, y, (goal.y == y).then_some(goal.x))
    }

    /// The next stop of a vertical jump from `(x, y)`, towards larger `y` when `NORTH`.
    // Inlined into the diagonal loop (measured: a call per step otherwise).
    #[allow(clippy::inline_always)]
    #[inline(always)]
    fn vertical<const NORTH: bool>(&self, x: u32, y: u32, goal: Cell) -> Option<u32> {
        let wall = &self.wall[..self.transposed.stride_words()];
        let goal = (goal.x == x).then_some(goal.y);
        scan_row::<NORTH>(&self.transposed, wall, y, x, goal)
    }

    /// A diagonal jump from `c` towards larger `x` when `EAST` and larger `y` when `NORTH`: one
    /// step at a time, stopping where a straight component finds a jump point or the goal.
    #[inline]
    fn diagonal<const EAST: bool, const NORTH: bool>(&self, c: Cell, goal: Cell) -> Option<Cell> {
        let g = self.grid;
        let (dx, dy) = (if EAST { 1 } else { -1 }, if NORTH { 1 } else { -1 });
        let (mut x, mut y) = (c.x, c.y);
        loop {
            let (nx, ny) = (x.wrapping_add_signed(dx), y.wrapping_add_signed(dy));
            // Off the grid (a step west of column 0 wraps past the width).
            if nx >= g.width() || ny >= g.height() {
                return None;
            }
            // The step needs (nx, y), (x, ny) and (nx, ny) free.
            let (row, next) = (g.row_words(y), g.row_words(ny));
            let bit = |r: &[u64], x: u32| r[(x / 64) as usize] >> (x % 64);
            if (bit(row, nx) | bit(next, x) | bit(next, nx)) & 1 != 0 {
                return None;
            }
            (x, y) = (nx, ny);
            // Both scans without a short cut: most steps find nothing in either, and two
            // independent scans overlap in the pipeline.
            let across = self.horizontal::<EAST>(x, y, goal).is_some();
            let along = self.vertical::<NORTH>(x, y, goal).is_some();
            if (x == goal.x && y == goal.y) | across | along {
                return Some(Cell::new(x, y));
            }
        }
    }
}

impl Jumper for BlockJumper<'_> {
    #[inline]
    fn jump(&self, c: Cell, d: u8, goal: Cell) -> Option<Cell> {
        // The order of `crate::movement::DIRECTIONS`.
        match d {
            0 => self
                .horizontal::<true>(c.x, c.y, goal)
                .map(|x| Cell::new(x, c.y)),
            1 => self
                .horizontal::<false>(c.x, c.y, goal)
                .map(|x| Cell::new(x, c.y)),
            2 => self
                .vertical::<true>(c.x, c.y, goal)
                .map(|y| Cell::new(c.x, y)),
            3 => self
                .vertical::<false>(c.x, c.y, goal)
                .map(|y| Cell::new(c.x, y)),
            4 => self.diagonal::<true, true>(c, goal),
            5 => self.diagonal::<true, false>(c, goal),
            6 => self.diagonal::<false, true>(c, goal),
            _ => self.diagonal::<false, false>(c, goal),
        }
    }
}
