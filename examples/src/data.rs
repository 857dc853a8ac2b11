//! The bundled data the examples read by default, by path from this crate's folder (so they run
//! from any working directory of a checkout). Provenance and licences: each `tests/data/README.md`.

use std::path::{Path, PathBuf};

/// `relative` (to the workspace root) as a path from this crate's folder, e.g.
/// `bundled("slam-core/tests/data/x.pcd")` is `<checkout>/examples/../slam-core/tests/data/x.pcd`.
#[must_use]
pub fn bundled(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative)
}

/// One HDL-32E scan of the parking-garage sequence (libwave, MIT): `scan_stats`'s default.
#[must_use]
pub fn garage_scan() -> PathBuf {
    bundled("slam-core/tests/data/hdl32e_garage_1503604882.703390000.pcd")
}

/// Source of `small_gicp`'s HDL-32E pair (MIT): `register`'s default source.
#[must_use]
pub fn pair_source() -> PathBuf {
    bundled("registration/tests/data/source.ply")
}

/// Target of the same pair: `register`'s default target.
#[must_use]
pub fn pair_target() -> PathBuf {
    bundled("slam-core/tests/data/hdl32e_pair_target.ply")
}

/// The pair's reference `target_T_source` (4x4, row-major): `register`'s default reference.
#[must_use]
pub fn pair_reference() -> PathBuf {
    bundled("registration/tests/data/T_target_source.txt")
}
