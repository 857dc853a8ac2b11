//! Helpers shared by the pose-graph tests: a seeded generator and the shared data folder.
#![allow(dead_code)]

use std::path::PathBuf;

/// Uniform numbers in `[-0.5, 0.5)` from a xorshift generator seeded with `seed`.
pub fn rng(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed | 1;
    move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        let v = (s >> 11) as f64 / (1u64 << 53) as f64;
        v - 0.5
    }
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
