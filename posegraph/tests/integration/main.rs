//! posegraph's integration tests in one binary: one link instead of one per file, and one
//! harness that runs every test across the cores (`cargo test -p spot-nav-posegraph --release --test
//! integration [MODULE::]NAME`).

mod common;

mod chordal;
mod datasets;
mod gnc;
mod incremental;
mod information_repair;
mod robust;
mod solver_faults;
