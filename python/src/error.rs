//! The exceptions: `SpotNavError` and one subclass per kind of Rust error, each raised with the
//! Rust error's message.

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

create_exception!(
    spot_nav,
    SpotNavError,
    PyException,
    "Base of every error spot_nav raises."
);
create_exception!(
    spot_nav,
    InvalidInputError,
    SpotNavError,
    "An argument of the wrong shape, type or range, or an unknown or invalid setting."
);
create_exception!(
    spot_nav,
    RegistrationError,
    SpotNavError,
    "A registration failed: too few points or correspondences, a degenerate fit."
);
create_exception!(
    spot_nav,
    OptimizationError,
    SpotNavError,
    "A pose-graph optimisation failed: no fixed node, a factorisation failure, bad values."
);
create_exception!(
    spot_nav,
    GraphFileError,
    SpotNavError,
    "A g2o or TORO file could not be read or written."
);
create_exception!(
    spot_nav,
    PlanningError,
    SpotNavError,
    "A start or goal off the grid or on a blocked cell, or a grid too large for a planner."
);
create_exception!(
    spot_nav,
    GridMapError,
    SpotNavError,
    "An occupancy grid could not be built (empty slice, too many cells, bad points)."
);
create_exception!(
    spot_nav,
    CloudError,
    SpotNavError,
    "A cloud operation failed (for example an invalid voxel size)."
);

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("SpotNavError", py.get_type::<SpotNavError>())?;
    m.add("InvalidInputError", py.get_type::<InvalidInputError>())?;
    m.add("RegistrationError", py.get_type::<RegistrationError>())?;
    m.add("OptimizationError", py.get_type::<OptimizationError>())?;
    m.add("GraphFileError", py.get_type::<GraphFileError>())?;
    m.add("PlanningError", py.get_type::<PlanningError>())?;
    m.add("GridMapError", py.get_type::<GridMapError>())?;
    m.add("CloudError", py.get_type::<CloudError>())?;
    Ok(())
}

/// `InvalidInputError` with `message`.
pub(crate) fn invalid(message: impl Into<String>) -> PyErr {
    InvalidInputError::new_err(message.into())
}

/// The Rust errors, each to its exception.
pub(crate) trait ToPyErr {
    /// The exception for this error, with its message.
    fn to_py(&self) -> PyErr;
}

macro_rules! to_py {
    ($($rust:ty => $python:ident),* $(,)?) => {
        $(impl ToPyErr for $rust {
            fn to_py(&self) -> PyErr {
                $python::new_err(self.to_string())
            }
        })*
    };
}

to_py! {
    slam_core::RegistrationError => RegistrationError,
    slam_core::OptimizeError => OptimizationError,
    slam_core::PlanError => PlanningError,
    slam_core::CloudError => CloudError,
    slam_core::KeyframeCloudError => CloudError,
    slam_core::GridError => GridMapError,
    slam_core::InvalidSetting => InvalidInputError,
    posegraph::GraphFileError => GraphFileError,
    gridmap::GridMapError => GridMapError,
    pathfind::PathfindError => PlanningError,
}

/// `result` with its error turned into the matching exception.
pub(crate) fn py_result<T, E: ToPyErr>(result: Result<T, E>) -> PyResult<T> {
    result.map_err(|e| e.to_py())
}
