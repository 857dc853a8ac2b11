//! gridmap's integration tests in one binary: one link instead of one per file, and one
//! harness that runs every test across the cores (`cargo test -p spot-nav-gridmap --release --test
//! integration [MODULE::]NAME`).

mod common;

mod floor_band;
mod gridmap;
mod live_layer;
mod narrow_gap;
mod planning_grid;
mod rng;
mod stairs;
mod walked;
