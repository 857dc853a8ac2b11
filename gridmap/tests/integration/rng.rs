//! The tests' random source: a seeded stream of `u64`s.

use rand_pcg::Pcg64Mcg;
use rand_pcg::rand_core::{Rng, SeedableRng};

/// A stream of `u64`s from `seed` (PCG-64): reproducible test data, the same on every platform.
pub fn rng(seed: u64) -> impl FnMut() -> u64 {
    let mut g = Pcg64Mcg::seed_from_u64(seed);
    move || g.next_u64()
}
