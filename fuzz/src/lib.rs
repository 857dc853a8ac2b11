//! Fuzzing spot-nav's readers of user data (cargo-fuzz targets in `fuzz_targets/`, nightly) and
//! the same checks on stable (`tests/seeds.rs`). See README.md.

// A broken invariant panics: that is how libFuzzer records a counterexample, and how the seed
// replay on stable fails.
#![allow(clippy::expect_used, clippy::panic, clippy::missing_panics_doc)]

pub mod invariants;
pub mod round_trip;
mod same;
