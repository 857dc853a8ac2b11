//! pathfind's integration tests in one binary: one link instead of one per file, and one
//! harness that runs every test across the cores (`cargo test -p spot-nav-pathfind --release --test
//! integration [MODULE::]NAME`).

mod bounded_memory;
mod cell_costs;
mod movingai_golden;
mod planner_memory;
mod planners;
mod support;
