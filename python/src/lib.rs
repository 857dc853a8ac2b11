//! # spot-nav-python
//!
//! The Python module `spot_nav` (`spot_nav._native`, re-exported by `spot_nav/__init__.py`):
//! PyO3 bindings of the workspace's backends, built by maturin as an abi3 wheel for CPython 3.9
//! and later. NumPy arrays in and out: clouds are `N x 3` `float32` or `float64` arrays, poses
//! `4 x 4` `float64` arrays (`a_T_b`, mapping points in b into a), grids `H x W` boolean arrays
//! indexed `grid[y, x]` (true: blocked).
//!
//! - `registration`: `align` (point-to-plane or point-to-point ICP, LOAM) returning an
//!   `Alignment` with the report the Rust backends give.
//! - `slam`: the `Slam` object, the Graph-SLAM engine as spot-adapter's pipelines set it up.
//! - `graph`: g2o and TORO files, `optimize` with Gauss-Newton, Levenberg-Marquardt or
//!   graduated non-convexity.
//! - `planning`: `plan` with the four grid planners, the line-of-sight filter, and occupancy
//!   grids built from a cloud.
//!
//! Every call that runs longer than reading its arguments releases the GIL
//! ([`Python::detach`](pyo3::Python::detach)). Errors are Python exceptions under
//! `spot_nav.SpotNavError`, one subclass per kind (module `error`), with the Rust error's message.
//!
//! When not to use it: from Rust, use the crates themselves; this crate holds no algorithm.
//! Its tests are Python (`tests/*.py`), run by `tests/pytest_suite.rs`.

// The doc comments of Python-facing items are also their Python docstrings (`__doc__`), written
// for Python readers: setting names and string values stay unquoted there.
#![allow(clippy::doc_markdown)]

use pyo3::prelude::*;

mod arrays;
mod config;
mod error;
mod graph;
mod planning;
mod registration;
mod slam;

/// The extension module, `spot_nav._native`.
#[pymodule]
#[pyo3(name = "_native")]
fn native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    error::register(m)?;
    registration::register(m)?;
    slam::register(m)?;
    graph::register(m)?;
    planning::register(m)?;
    Ok(())
}
