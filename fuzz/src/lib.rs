//! Fuzzing spot-nav's readers of user data (cargo-fuzz targets in `fuzz_targets/`, nightly) and
//! the same checks on stable (`tests/seeds.rs`). See README.md.

pub mod invariants;
pub mod round_trip;
mod same;
