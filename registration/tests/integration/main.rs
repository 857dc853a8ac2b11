//! registration's integration tests in one binary: one link instead of one per file, and one
//! harness that runs every test across the cores (`cargo test -p spot-nav-registration --release --test
//! integration [MODULE::]NAME`).

mod common;

mod degeneracy;

mod loam;
mod real_scans;
mod stored_sources;
mod voxel_hash_map;
