//! Line of sight between cell centres under the no-corner-cutting rule.

use slam_core::{BitGrid, Cell};

/// Whether the straight segment between the centres of `a` and `b` crosses only free cells.
///
/// Every cell the segment touches is checked (a supercover walk, not Bresenham, which skips cells
/// the segment clips and so walks through thin walls). Where the segment passes exactly through a
/// cell corner, both cells beside the corner must be free, as a diagonal step requires.
#[must_use]
pub fn line_of_sight(grid: &BitGrid, a: Cell, b: Cell) -> bool {
    walk(a, b, |x, y| grid.is_free_signed(x, y))
}

/// Every cell the segment touches, in order (for drawing and for tests).
#[must_use]
pub fn supercover_cells(a: Cell, b: Cell) -> Vec<(i64, i64)> {
    let mut out = Vec::new();
    walk(a, b, |x, y| {
        out.push((x, y));
        true
    });
    out
}

/// Visit every cell the segment between the centres of `a` and `b` touches, both side cells at an
/// exact corner crossing, until `visit` returns false; returns whether every visit returned true.
fn walk(a: Cell, b: Cell, mut visit: impl FnMut(i64, i64) -> bool) -> bool {
    let (mut x, mut y) = (i64::from(a.x), i64::from(a.y));
    let (dx, dy) = (i64::from(b.x) - x, i64::from(b.y) - y);
    let (sx, sy) = (dx.signum(), dy.signum());
    let (nx, ny) = (dx.abs(), dy.abs());
    if !visit(x, y) {
        return false;
    }
    let (mut ix, mut iy) = (0i64, 0i64);
    while ix < nx || iy < ny {
        // Which cell boundary the segment crosses next: vertical at (0.5 + ix) / nx of the way,
        // horizontal at (0.5 + iy) / ny; compared without division.
        let decision = (1 + 2 * ix) * ny - (1 + 2 * iy) * nx;
        match decision.cmp(&0) {
            std::cmp::Ordering::Equal => {
                if !visit(x + sx, y) || !visit(x, y + sy) {
                    return false;
                }
                x += sx;
                y += sy;
                ix += 1;
                iy += 1;
            }
            std::cmp::Ordering::Less => {
                x += sx;
                ix += 1;
            }
            std::cmp::Ordering::Greater => {
                y += sy;
                iy += 1;
            }
        }
        if !visit(x, y) {
            return false;
        }
    }
    true
}
