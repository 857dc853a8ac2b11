//! The movement model shared by every planner: 8-connected, straight cost 1, diagonal cost
//! sqrt(2), no corner cutting (a diagonal step needs both orthogonal neighbours free).

use slam_core::{BitGrid, Cell};

/// sqrt(2), the cost of a diagonal step.
pub const SQRT_2: f64 = std::f64::consts::SQRT_2;

/// The eight step directions `(dx, dy)`: four straight, then four diagonal.
pub const DIRECTIONS: [(i32, i32); 8] = [
    (1, 0),
    (-1, 0),
    (0, 1),
    (0, -1),
    (1, 1),
    (1, -1),
    (-1, 1),
    (-1, -1),
];

/// Octile distance: the exact cost between two cells on an empty grid (an admissible and
/// consistent A* heuristic).
#[inline]
#[must_use]
pub fn octile(a: Cell, b: Cell) -> f64 {
    let dx = a.x.abs_diff(b.x);
    let dy = a.y.abs_diff(b.y);
    let (lo, hi) = if dx < dy { (dx, dy) } else { (dy, dx) };
    f64::from(hi - lo) + SQRT_2 * f64::from(lo)
}

/// Whether `(x, y)` is a free cell of `grid` (signed coordinates; off-grid is not free).
#[inline]
#[must_use]
pub fn free(grid: &BitGrid, x: i64, y: i64) -> bool {
    grid.is_free_signed(x, y)
}

/// Whether a single step from free cell `(x, y)` by `(dx, dy)` is legal.
#[inline]
#[must_use]
pub fn can_step(grid: &BitGrid, x: i64, y: i64, dx: i64, dy: i64) -> bool {
    if dx != 0 && dy != 0 {
        free(grid, x + dx, y) && free(grid, x, y + dy) && free(grid, x + dx, y + dy)
    } else {
        free(grid, x + dx, y + dy)
    }
}

/// Cost of the cell path `cells` (consecutive cells joined by straight or diagonal runs).
#[must_use]
pub fn path_cost(cells: &[Cell]) -> f64 {
    // A fold from +0.0: `sum()` of no steps is -0.0, which a one-cell path must not report.
    cells
        .windows(2)
        .map(|w| octile(w[0], w[1]))
        .fold(0.0, |a, b| a + b)
}

/// Why a path is not valid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum PathViolation {
    /// The path is empty.
    Empty,
    /// A cell is off the grid or blocked.
    BlockedCell(Cell),
    /// Two consecutive cells are not neighbours.
    NotAdjacent(Cell, Cell),
    /// A diagonal step cuts a blocked corner.
    CutsCorner(Cell, Cell),
}

/// Check a dense path (every cell listed): free cells, 8-connected steps, no corner cutting.
///
/// # Errors
/// The first [`PathViolation`] found.
pub fn validate_dense_path(grid: &BitGrid, cells: &[Cell]) -> Result<(), PathViolation> {
    if cells.is_empty() {
        return Err(PathViolation::Empty);
    }
    for &c in cells {
        if grid.is_blocked(c) {
            return Err(PathViolation::BlockedCell(c));
        }
    }
    for w in cells.windows(2) {
        let dx = i64::from(w[1].x) - i64::from(w[0].x);
        let dy = i64::from(w[1].y) - i64::from(w[0].y);
        if dx.abs() > 1 || dy.abs() > 1 || (dx == 0 && dy == 0) {
            return Err(PathViolation::NotAdjacent(w[0], w[1]));
        }
        if !can_step(grid, i64::from(w[0].x), i64::from(w[0].y), dx, dy) {
            return Err(PathViolation::CutsCorner(w[0], w[1]));
        }
    }
    Ok(())
}

/// Free bits of cells `x - 1`, `x`, `x + 1` of row `y` (bit 0 = `x - 1`); off-grid cells are
/// blocked.
// Hot path of the cell-by-cell searches: LLVM outlines it with plain `#[inline]` (measured).
#[allow(clippy::inline_always)]
#[inline(always)]
fn row_free3(grid: &BitGrid, x: u32, y: i64) -> u32 {
    if y < 0 || y >= i64::from(grid.height()) {
        return 0;
    }
    let y = y as u32;
    let blocked = if x >= 1 && (x - 1) % 64 <= 61 {
        // The three cells share a word (the usual case).
        grid.row_words(y)[((x - 1) / 64) as usize] >> ((x - 1) % 64)
    } else if x >= 1 {
        grid.word_at(x - 1, y)
    } else {
        (grid.word_at(0, y) << 1) | 1
    };
    (!blocked & 7) as u32
}

/// [`row_free3`] of the rows above, at and below cell `c`: its 3 x 3 neighbourhood.
#[allow(clippy::inline_always)]
#[inline(always)]
fn rows_free3(grid: &BitGrid, c: Cell) -> (u32, u32, u32) {
    let y = i64::from(c.y);
    (
        row_free3(grid, c.x, y + 1),
        row_free3(grid, c.x, y),
        row_free3(grid, c.x, y - 1),
    )
}

/// The legal steps (bits as in [`legal_steps`]) from the free bits of the rows above, at and
/// below the cell (bit 0 = west, as [`row_free3`] gives them).
#[allow(clippy::inline_always)]
#[inline(always)]
fn legal_from_rows(up: u32, mid: u32, down: u32) -> u8 {
    let e = mid >> 2 & 1;
    let w = mid & 1;
    let n = up >> 1 & 1;
    let s = down >> 1 & 1;
    let ne = e & n & (up >> 2);
    let se = e & s & (down >> 2);
    let nw = w & n & up;
    let sw = w & s & down;
    (e | w << 1 | n << 2 | s << 3 | ne << 4 | se << 5 | nw << 6 | sw << 7) as u8
}

/// The neighbours (bits as in [`legal_steps`], no corner rule) that are free in the rows above,
/// at and below the cell (as [`row_free3`] gives them).
#[allow(clippy::inline_always)]
#[inline(always)]
fn neighbours_from_rows(up: u32, mid: u32, down: u32) -> u8 {
    let bits = (mid >> 2 & 1)
        | (mid & 1) << 1
        | (up >> 1 & 1) << 2
        | (down >> 1 & 1) << 3
        | (up >> 2 & 1) << 4
        | (down >> 2 & 1) << 5
        | (up & 1) << 6
        | (down & 1) << 7;
    bits as u8
}

/// Bit `d` set when the step `DIRECTIONS[d]` from free cell `c` is legal (one word read per row
/// of the 3 x 3 neighbourhood instead of up to 20 cell reads).
// Hot path of the cell-by-cell searches: LLVM outlines it with plain `#[inline]` (measured).
#[allow(clippy::inline_always)]
#[inline(always)]
#[must_use]
pub fn legal_steps(grid: &BitGrid, c: Cell) -> u8 {
    let (up, mid, down) = rows_free3(grid, c);
    legal_from_rows(up, mid, down)
}

/// Bit `d` set when the neighbour `c + DIRECTIONS[d]` is a free cell of `grid` (no corner rule;
/// off-grid neighbours are not free).
// Hot path of the cell-by-cell searches (see `legal_steps`).
#[allow(clippy::inline_always)]
#[inline(always)]
pub(crate) fn free_neighbours(grid: &BitGrid, c: Cell) -> u8 {
    let (up, mid, down) = rows_free3(grid, c);
    neighbours_from_rows(up, mid, down)
}

/// The legal steps from free cell `c` (as [`legal_steps`]) into cells not set in `visited`, a grid
/// of the same size. Away from the edges (and unless the neighbourhood straddles a word) the six
/// words are read straight from the two grids' words, with one index computation.
// Hot path of the cell-by-cell searches (see `legal_steps`).
#[allow(clippy::inline_always)]
#[inline(always)]
pub(crate) fn legal_steps_avoiding(grid: &BitGrid, visited: &BitGrid, c: Cell) -> u8 {
    let (x, y) = (c.x, c.y);
    if x >= 1 && (x - 1) % 64 <= 61 && y >= 1 && y + 1 < grid.height() {
        let stride = grid.stride_words();
        let at = y as usize * stride + ((x - 1) / 64) as usize;
        let shift = (x - 1) % 64;
        let free3 = |words: &[u64], k: usize| (!(words[k] >> shift) & 7) as u32;
        let (g, v) = (grid.words(), visited.words());
        let legal = legal_from_rows(free3(g, at + stride), free3(g, at), free3(g, at - stride));
        let new = neighbours_from_rows(free3(v, at + stride), free3(v, at), free3(v, at - stride));
        return legal & new;
    }
    legal_steps(grid, c) & free_neighbours(visited, c)
}
