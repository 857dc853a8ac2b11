//! Least-squares rigid alignment of two point sets (Umeyama, "Least-squares estimation of
//! transformation parameters between two point patterns", IEEE TPAMI 1991; the closed form evo's
//! `ape -a` uses), without scale.

use nalgebra::{Matrix3, Point3, Translation3, UnitQuaternion, Vector3};
use slam_core::Pose3;

use crate::error::AdapterError;

/// The rigid transform `T` minimising `sum |b_i - T a_i|^2` (so `b ≈ T a`).
///
/// # Errors
/// [`AdapterError::TooFewPoses`] for fewer than 3 pairs or sets of different lengths (the
/// count of pairs is the shorter length).
pub fn align_rigid(a: &[Point3<f64>], b: &[Point3<f64>]) -> Result<Pose3, AdapterError> {
    let n = a.len().min(b.len());
    if n < 3 || a.len() != b.len() {
        return Err(AdapterError::TooFewPoses {
            found: n,
            required: 3,
        });
    }
    let mean = |p: &[Point3<f64>]| p.iter().fold(Vector3::zeros(), |s, q| s + q.coords) / n as f64;
    let (ma, mb) = (mean(a), mean(b));
    // Cross-covariance: sum (b - mb)(a - ma)^T.
    let mut sigma = Matrix3::zeros();
    for (p, q) in a.iter().zip(b) {
        sigma += (q.coords - mb) * (p.coords - ma).transpose();
    }
    let svd = sigma.svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return Ok(Pose3::from_parts(
            Translation3::from(mb - ma),
            UnitQuaternion::identity(),
        ));
    };
    // Reflection guard: flip the axis of the smallest singular value if det(U V^T) < 0.
    let mut s = Matrix3::identity();
    if (u * v_t).determinant() < 0.0 {
        // nalgebra sorts singular values in decreasing order, so the last is the smallest.
        s[(2, 2)] = -1.0;
    }
    let r = u * s * v_t;
    let rot = UnitQuaternion::from_matrix(&r);
    let t = mb - rot * ma;
    Ok(Pose3::from_parts(Translation3::from(t), rot))
}
