//! Fuzzing spot-nav's readers of user data (cargo-fuzz targets in `fuzz_targets/`, nightly) and
//! the same round trips on stable (`tests/seeds.rs`). See README.md.

pub mod round_trip;
mod same;
