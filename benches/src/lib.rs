//! Shared helpers for the benches (data paths).
