//! Helpers the integration tests share: a seeded xorshift and a free-cell picker.

use slam_core::{BitGrid, Cell};

/// Marsaglia's xorshift64 from `seed` (0 is made odd): fast, reproducible test data.
pub(crate) fn xorshift(seed: u64) -> impl FnMut() -> u64 {
    let mut s = seed | 1;
    move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    }
}

/// A free cell of `grid` chosen by `pick` (cells visited from `pick` in steps of 7,919, a prime,
/// so that any pick reaches every cell), or `None` when every cell is blocked.
pub(crate) fn free_cell(grid: &BitGrid, pick: u64) -> Option<Cell> {
    let n = u64::from(grid.width()) * u64::from(grid.height());
    (0..n)
        .map(|k| (pick + k * 7919) % n)
        .map(|i| {
            Cell::new(
                (i % u64::from(grid.width())) as u32,
                (i / u64::from(grid.width())) as u32,
            )
        })
        .find(|&c| !grid.is_blocked(c))
}
