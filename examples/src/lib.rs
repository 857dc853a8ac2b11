//! Shared helpers for the examples (data paths).
