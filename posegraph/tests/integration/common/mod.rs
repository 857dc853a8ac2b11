//! Helpers shared by the pose-graph tests: a seeded generator and the shared data folder.
#![allow(dead_code)]

use std::path::PathBuf;

use rand_pcg::Pcg64Mcg;
use rand_pcg::rand_core::{Rng, SeedableRng};

/// A stream of `u64`s from `seed` (PCG-64): reproducible test data, the same on every platform.
pub fn rng_u64(seed: u64) -> impl FnMut() -> u64 {
    let mut g = Pcg64Mcg::seed_from_u64(seed);
    move || g.next_u64()
}

/// Uniform numbers in `[0, 1)` from `seed`: the top 53 bits of [`rng_u64`]'s.
pub fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut r = rng_u64(seed);
    move || (r() >> 11) as f64 / (1u64 << 53) as f64
}

/// Uniform numbers in `[-0.5, 0.5)` from `seed`.
pub fn rng(seed: u64) -> impl FnMut() -> f64 {
    let mut u = uniform(seed);
    move || u() - 0.5
}

/// A file of the shared pose-graph data set (`SPOT_NAV_DATA`, default `../shared/data`), when
/// present.
pub fn shared(name: &str) -> Option<PathBuf> {
    let root = std::env::var_os("SPOT_NAV_DATA").map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/data"),
        PathBuf::from,
    );
    let p = root.join("posegraph").join(name);
    p.exists().then_some(p)
}
