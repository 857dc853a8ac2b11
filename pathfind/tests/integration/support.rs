//! Helpers the integration tests share: a seeded generator, random grids and a free-cell picker.
#![allow(clippy::unwrap_used)]

use rand_pcg::Pcg64Mcg;
use rand_pcg::rand_core::{Rng, SeedableRng};
use slam_core::{BitGrid, Cell};

/// A stream of `u64`s from `seed` (PCG-64): reproducible test data, the same on every platform.
pub(crate) fn rng(seed: u64) -> impl FnMut() -> u64 {
    let mut g = Pcg64Mcg::seed_from_u64(seed);
    move || g.next_u64()
}

/// A `w` x `h` grid with each cell blocked with probability `density` percent, drawn from `seed`.
pub(crate) fn random_grid(w: u32, h: u32, density: u32, seed: u64) -> BitGrid {
    let mut r = rng(seed);
    BitGrid::from_fn(w, h, |_, _| (r() % 100) < u64::from(density)).unwrap()
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
