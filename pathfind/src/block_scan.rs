//! Word-at-a-time straight jumps (Harabor & Grastien 2014, "Improving Jump Point Search"): 64
//! cells of a row and of its two neighbouring rows are read as words, and `trailing_zeros` finds
//! the first blocked cell and the first forced cell at once. Columns are scanned as rows of the
//! transposed grid.

use slam_core::BitGrid;

/// Scan row `y` from column `x` east (`east`) or west. Returns the column of the first jump point
/// (a cell with a forced side) or of the goal column `goal` when it comes first; `None` when a
/// wall comes first.
#[inline]
pub(crate) fn scan_row(
    grid: &BitGrid,
    x: u32,
    y: u32,
    east: bool,
    goal: Option<u32>,
) -> Option<u32> {
    let h = grid.height();
    // Bit i of each word is the cell i steps from `s` in the travel direction.
    let word = |s: u32, r: u32| {
        if east {
            grid.word_at(s, r)
        } else {
            grid.word_ending_at(s, r).reverse_bits()
        }
    };
    let mut s = x;
    loop {
        let here = word(s, y);
        let above = if y + 1 < h { word(s, y + 1) } else { u64::MAX };
        let below = if y > 0 { word(s, y - 1) } else { u64::MAX };
        // A side is forced at step i when the side cell is free but the side cell of step i - 1
        // (the one behind in the travel direction) is blocked.
        let forced = ((!above & (above << 1)) | (!below & (below << 1))) & !1;
        let blocked = here & !1;
        let first_forced = forced.trailing_zeros();
        let first_blocked = blocked.trailing_zeros();
        if let Some(g) = goal {
            let steps = if east {
                g.checked_sub(s)
            } else {
                s.checked_sub(g)
            };
            if let Some(i) = steps
                && (1..64).contains(&i)
                && i < first_blocked
                && i <= first_forced
            {
                return Some(g);
            }
        }
        if first_forced < first_blocked {
            return Some(if east {
                s + first_forced
            } else {
                s - first_forced
            });
        }
        if first_blocked < 64 {
            return None;
        }
        // Steps 1..=63 are free and unforced: continue from the last one.
        s = if east { s + 63 } else { s - 63 };
    }
}
