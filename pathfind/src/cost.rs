//! Path costs in fixed point for the searches: integer additions and comparisons instead of
//! floating point, and no float-to-integer conversion when a cost becomes an open-list key.
//!
//! A straight step costs `2^29`, a diagonal step `round(sqrt(2) 2^29)`, which is
//! `sqrt(2) 2^29 + 0.006` (29 bits happen to round `sqrt(2)` about as well as 35 would). The
//! searches are exact on these integer costs (the octile distance in the same units is consistent,
//! so no rounding enters anywhere), and a path that is shortest in them is shortest in the true
//! costs: the fixed-point costs of two paths whose diagonal step counts differ by `db` are off from
//! `2^29` times their true costs by amounts at most `0.006 db` apart, while distinct true costs
//! `a + b sqrt(2)` differ by at least about `1 / (2.9 db)` (`sqrt(2)` is badly approximable), so
//! the order cannot flip while `db` stays below 170,000. Reported lengths are summed step by step
//! along the path in floating point ([`path_cost`](crate::movement::path_cost)).
//!
//! A `u64` holds costs up to `2^35` cells, beyond any `g + h` on a grid that a `u32` cell index can
//! address (`2^32` cells).

use slam_core::Cell;

/// A path cost in units of `2^-29` cells.
pub(crate) type Cost = u64;

/// Fractional bits of a [`Cost`].
pub(crate) const FRACTION_BITS: u32 = 29;

/// Cost of a straight step.
pub(crate) const STRAIGHT: Cost = 1 << FRACTION_BITS;

/// Cost of a diagonal step: `sqrt(2) 2^29` rounded to the nearest integer.
pub(crate) const DIAGONAL: Cost = 759_250_125;

/// Step cost in each of the [`DIRECTIONS`](crate::movement::DIRECTIONS): four straight, then four
/// diagonal.
pub(crate) const STEP: [Cost; 8] = [
    STRAIGHT, STRAIGHT, STRAIGHT, STRAIGHT, DIAGONAL, DIAGONAL, DIAGONAL, DIAGONAL,
];

/// Octile distance in fixed point (the exact cost between two cells on an empty grid).
#[inline]
pub(crate) fn octile(a: Cell, b: Cell) -> Cost {
    let dx = a.x.abs_diff(b.x);
    let dy = a.y.abs_diff(b.y);
    let (lo, hi) = if dx < dy { (dx, dy) } else { (dy, dx) };
    Cost::from(hi - lo) * STRAIGHT + Cost::from(lo) * DIAGONAL
}

/// Whole cells of `cost`, rounded down (the tie-break between equal priorities).
#[inline]
pub(crate) fn whole_cells(cost: Cost) -> u32 {
    u32::try_from(cost >> FRACTION_BITS).unwrap_or(u32::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn diagonal_is_sqrt2_rounded() {
        let exact = std::f64::consts::SQRT_2 * STRAIGHT as f64;
        assert!((DIAGONAL as f64 - exact).abs() <= 0.5 + 1e-6 * exact);
        assert!((DIAGONAL as f64 - exact - 0.006).abs() < 0.001);
    }

    #[test]
    fn octile_matches_the_float_one() {
        let (a, b) = (Cell::new(3, 40), Cell::new(1000, 7));
        let fixed = octile(a, b) as f64 / STRAIGHT as f64;
        assert!((fixed - crate::movement::octile(a, b)).abs() < 1e-9);
    }
}
