//! NumPy arrays to and from clouds, poses and matrices.
//!
//! Clouds come in as `N x 3` `float32` or `float64` arrays and are read in place (any strides,
//! no intermediate copy) straight into the [`PointCloud`] the backends take; clouds go out as
//! `N x 3` `float32` arrays that own the buffer Rust filled (moved, not copied).

use nalgebra::{Isometry3, Matrix3, Matrix4, Matrix6, Rotation3, Translation3, UnitQuaternion};
use numpy::{
    PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use slam_core::{PointCloud, Pose3};

use crate::error::invalid;

/// An `N x 3` array's points, read where they lie (float32 or float64, any layout).
pub(crate) fn cloud_from(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<PointCloud> {
    if let Ok(a) = obj.extract::<PyReadonlyArray2<'_, f32>>() {
        let view = a.as_array();
        check_columns(view.ncols(), what)?;
        return Ok(PointCloud::from_points(
            view.rows()
                .into_iter()
                .map(|r| nalgebra::Point3::new(r[0], r[1], r[2]))
                .collect(),
        ));
    }
    if let Ok(a) = obj.extract::<PyReadonlyArray2<'_, f64>>() {
        let view = a.as_array();
        check_columns(view.ncols(), what)?;
        return Ok(PointCloud::from_points(
            view.rows()
                .into_iter()
                .map(|r| nalgebra::Point3::new(r[0] as f32, r[1] as f32, r[2] as f32))
                .collect(),
        ));
    }
    Err(invalid(format!(
        "{what} must be an N x 3 numpy array of float32 or float64, got {}",
        describe(obj)
    )))
}

/// Per-point times (seconds) from a 1-D float32 or float64 array, read where they lie (a dense
/// scan's 131,072 times converted element by element from Python cost about 4 ms a scan), or
/// from any sequence of numbers.
pub(crate) fn times_from(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f32>> {
    if let Ok(a) = obj.extract::<PyReadonlyArray1<'_, f32>>() {
        return Ok(a.as_array().iter().copied().collect());
    }
    if let Ok(a) = obj.extract::<PyReadonlyArray1<'_, f64>>() {
        // Seconds within a sweep: f32 holds them to well under a microsecond.
        return Ok(a.as_array().iter().map(|&t| t as f32).collect());
    }
    obj.extract::<Vec<f32>>().map_err(|_| {
        invalid(format!(
            "{what} must be a 1-D numpy array of float32 or float64 or a sequence of numbers, got {}",
            describe(obj)
        ))
    })
}

fn check_columns(columns: usize, what: &str) -> PyResult<()> {
    if columns == 3 {
        Ok(())
    } else {
        Err(invalid(format!(
            "{what} must have 3 columns (x, y, z), got {columns}"
        )))
    }
}

/// The type and, for an array, dtype and shape of `obj`, for error messages.
fn describe(obj: &Bound<'_, PyAny>) -> String {
    let kind = obj
        .get_type()
        .name()
        .map_or_else(|_| "?".to_owned(), |n| n.to_string());
    match (obj.getattr("dtype"), obj.getattr("shape")) {
        (Ok(d), Ok(s)) => format!("{kind} of dtype {d} and shape {s}"),
        _ => kind,
    }
}

/// A float64 matrix of `rows x cols` from any array-like (lists too).
fn matrix_from(obj: &Bound<'_, PyAny>, rows: usize, cols: usize, what: &str) -> PyResult<Vec<f64>> {
    let numpy = obj.py().import("numpy")?;
    let array = numpy
        .call_method1("asarray", (obj, "float64"))
        .map_err(|_| invalid(format!("{what} must be a {rows} x {cols} array of numbers")))?;
    let a = array
        .extract::<PyReadonlyArray2<'_, f64>>()
        .map_err(|_| invalid(format!("{what} must be a {rows} x {cols} array")))?;
    if a.shape() != [rows, cols] {
        return Err(invalid(format!(
            "{what} must be a {rows} x {cols} array, got shape {:?}",
            a.shape()
        )));
    }
    Ok(a.as_array().iter().copied().collect())
}

/// A rigid transform from a 4 x 4 homogeneous matrix: the rotation block must be orthonormal
/// with determinant +1 (within 1e-6) and the last row `[0, 0, 0, 1]`.
pub(crate) fn pose_from(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Pose3> {
    let v = matrix_from(obj, 4, 4, what)?;
    let m = Matrix4::from_row_slice(&v);
    if v.iter().any(|x| !x.is_finite()) {
        return Err(invalid(format!("{what} has a non-finite value")));
    }
    let bottom = m.fixed_view::<1, 4>(3, 0);
    if (bottom - nalgebra::RowVector4::new(0.0, 0.0, 0.0, 1.0)).amax() > 1e-9 {
        return Err(invalid(format!("{what}'s last row must be [0, 0, 0, 1]")));
    }
    let r: Matrix3<f64> = m.fixed_view::<3, 3>(0, 0).into_owned();
    if (r.transpose() * r - Matrix3::identity()).amax() > 1e-6 || r.determinant() < 0.0 {
        return Err(invalid(format!(
            "{what}'s upper-left 3 x 3 block is not a rotation (orthonormal, determinant +1)"
        )));
    }
    let rotation = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
    Ok(Isometry3::from_parts(
        Translation3::new(m[(0, 3)], m[(1, 3)], m[(2, 3)]),
        rotation,
    ))
}

/// `pose` as a 4 x 4 float64 array.
pub(crate) fn pose_to<'py>(py: Python<'py>, pose: &Pose3) -> Bound<'py, PyArray2<f64>> {
    let m = pose.to_homogeneous();
    row_major(py, m.transpose().as_slice(), 4, 4)
}

/// Poses as an `N x 4 x 4` float64 array.
pub(crate) fn poses_to(
    py: Python<'_>,
    poses: impl ExactSizeIterator<Item = Pose3>,
) -> PyResult<Bound<'_, PyAny>> {
    let n = poses.len();
    let mut flat = Vec::with_capacity(n * 16);
    for p in poses {
        flat.extend_from_slice(p.to_homogeneous().transpose().as_slice());
    }
    Ok(PyArray1::from_vec(py, flat).reshape([n, 4, 4])?.into_any())
}

/// A 6 x 6 matrix as a float64 array.
pub(crate) fn matrix6_to<'py>(py: Python<'py>, m: &Matrix6<f64>) -> Bound<'py, PyArray2<f64>> {
    row_major(py, m.transpose().as_slice(), 6, 6)
}

/// `values` (row-major) as a `rows x cols` array.
pub(crate) fn row_major<'py>(
    py: Python<'py>,
    values: &[f64],
    rows: usize,
    cols: usize,
) -> Bound<'py, PyArray2<f64>> {
    let a = PyArray1::from_slice(py, values);
    // The length is rows * cols by construction.
    a.reshape([rows, cols])
        .unwrap_or_else(|_| PyArray2::zeros(py, [rows, cols], false))
}

/// A cloud as an `N x 3` float32 array owning the values (no second copy).
pub(crate) fn cloud_to<'py>(py: Python<'py>, cloud: &PointCloud) -> PyResult<Bound<'py, PyAny>> {
    let n = cloud.len();
    let mut flat = Vec::with_capacity(n * 3);
    for p in cloud.points() {
        flat.extend_from_slice(&[p.x, p.y, p.z]);
    }
    Ok(PyArray1::from_vec(py, flat).reshape([n, 3])?.into_any())
}
