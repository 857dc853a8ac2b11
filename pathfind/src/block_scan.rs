//! Word-at-a-time straight jumps (Harabor & Grastien 2014, "Improving Jump Point Search"): 64
//! cells of a row and of its two neighbouring rows are read as aligned words, and
//! `trailing_zeros` / `leading_zeros` find the first blocked cell and the first forced cell at
//! once. Columns are scanned as rows of the transposed grid.

use slam_core::{BitGrid, Cell};

use crate::jump_search::Jumper;
use crate::movement::{DIRECTIONS, free};

/// Word `i` of a row, or all blocked for a row off the grid.
#[inline]
fn word(row: Option<&[u64]>, i: usize) -> u64 {
    row.map_or(u64::MAX, |r| r[i])
}

/// Scan row `y` from column `x` east (`east`) or west. Returns the column of the first jump point
/// (a cell whose side is free while the side cell behind it is blocked) or of the goal column
/// `goal` when it comes first; `None` when a wall comes first.
#[inline]
pub(crate) fn scan_row(
    grid: &BitGrid,
    x: u32,
    y: u32,
    east: bool,
    goal: Option<u32>,
) -> Option<u32> {
    let here = grid.row_words(y);
    let above = (y + 1 < grid.height()).then(|| grid.row_words(y + 1));
    let below = (y > 0).then(|| grid.row_words(y - 1));
    let stop = if east {
        scan_east(here, above, below, x)
    } else {
        scan_west(here, above, below, x)
    };
    if let Some(g) = goal {
        // The goal lies ahead, before the wall and not after the jump point.
        let ahead = if east { g > x } else { g < x };
        let g64 = i64::from(g);
        let before_stop = match stop {
            Stop::Jump(j) => {
                if east {
                    g <= j
                } else {
                    g >= j
                }
            }
            Stop::Wall(w) => {
                if east {
                    g64 < w
                } else {
                    g64 > w
                }
            }
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

#[inline]
fn scan_east(here: &[u64], above: Option<&[u64]>, below: Option<&[u64]>, x: u32) -> Stop {
    let mut i = (x / 64) as usize;
    // Only cells after x count.
    let mut mask = (u64::MAX << (x % 64)) << 1;
    let (mut carry_up, mut carry_down) = (0u64, 0u64);
    loop {
        let (h, u, d) = (here[i], word(above, i), word(below, i));
        // Forced at bit b: side free at b, side blocked at b - 1 (bit 0 looks at the word before).
        let forced = ((!u & ((u << 1) | carry_up)) | (!d & ((d << 1) | carry_down))) & mask;
        let blocked = h & mask;
        let base = i as u32 * 64;
        if forced != 0 || blocked != 0 {
            let (f, b) = (forced.trailing_zeros(), blocked.trailing_zeros());
            return if f < b {
                Stop::Jump(base + f)
            } else {
                Stop::Wall(i64::from(base + b))
            };
        }
        // Padding bits past the width are blocked; a width that fills its last word has none.
        if i + 1 == here.len() {
            return Stop::Wall(i64::from(base) + 64);
        }
        carry_up = u >> 63;
        carry_down = d >> 63;
        mask = u64::MAX;
        i += 1;
    }
}

#[inline]
fn scan_west(here: &[u64], above: Option<&[u64]>, below: Option<&[u64]>, x: u32) -> Stop {
    let mut i = (x / 64) as usize;
    // Only cells before x count.
    let mut mask = (1u64 << (x % 64)) - 1;
    let (mut carry_up, mut carry_down) = (0u64, 0u64);
    loop {
        let (h, u, d) = (here[i], word(above, i), word(below, i));
        // Travelling west, the cell behind b is b + 1 (bit 63 looks at the word after).
        let forced = ((!u & ((u >> 1) | carry_up)) | (!d & ((d >> 1) | carry_down))) & mask;
        let blocked = h & mask;
        let base = i as u32 * 64;
        if forced != 0 || blocked != 0 {
            // The highest set bit is the first stop going west; an empty mask never wins.
            let top = |m: u64| (m != 0).then(|| m.ilog2());
            return match (top(forced), top(blocked)) {
                (Some(f), Some(b)) if f > b => Stop::Jump(base + f),
                (Some(f), None) => Stop::Jump(base + f),
                (_, Some(b)) => Stop::Wall(i64::from(base + b)),
                (None, None) => Stop::Wall(-1),
            };
        }
        if i == 0 {
            return Stop::Wall(-1);
        }
        carry_up = u << 63;
        carry_down = d << 63;
        mask = u64::MAX;
        i -= 1;
    }
}

/// Jumps by word scans: rows of the grid for horizontal runs, rows of the transposed grid for
/// vertical runs, and diagonal runs one step at a time with a word scan along both components.
pub(crate) struct BlockJumper<'g> {
    grid: &'g BitGrid,
    transposed: BitGrid,
}

impl<'g> BlockJumper<'g> {
    /// Builds the transposed grid (one more bit per cell).
    pub(crate) fn new(grid: &'g BitGrid) -> Self {
        Self {
            grid,
            transposed: grid.transposed(),
        }
    }

    /// Bytes of the transposed grid.
    pub(crate) fn bytes(&self) -> usize {
        self.transposed.words().len() * 8
    }

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
