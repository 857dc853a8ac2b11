//! slam-core's integration tests in one binary: one link instead of one per file, and one
//! harness that runs every test across the cores (`cargo test -p spot-nav-slam-core --release --test
//! integration [MODULE::]NAME`).

mod bounded_memory;
mod io_formats;
mod rigid_fit;
mod slam_engine;
