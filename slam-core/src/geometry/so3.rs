//! SO(3): hat/vee, exponential and logarithm, and the left Jacobian.

use nalgebra::{Matrix3, UnitQuaternion, Vector3};

/// Below this angle (radians) the closed forms lose precision and Taylor series are used.
const SMALL_ANGLE: f64 = 1e-4;

/// The skew-symmetric matrix `[w]x` with `[w]x v = w x v`.
#[must_use]
pub fn so3_hat(w: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -w.z, w.y, w.z, 0.0, -w.x, -w.y, w.x, 0.0)
}

/// The vector of a skew-symmetric matrix (the inverse of [`so3_hat`]; the symmetric part is
/// ignored).
#[must_use]
pub fn so3_vee(m: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(
        m[(2, 1)] - m[(1, 2)],
        m[(0, 2)] - m[(2, 0)],
        m[(1, 0)] - m[(0, 1)],
    ) * 0.5
}

/// Rotation of angle `|w|` about `w` (Rodrigues).
#[must_use]
pub fn so3_exp(w: &Vector3<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::from_scaled_axis(*w)
}

/// Rotation vector of `q`, with angle in `[0, pi]`. Computed from the quaternion with `atan2`, so
/// it stays accurate near both identity and pi.
#[must_use]
pub fn so3_log(q: &UnitQuaternion<f64>) -> Vector3<f64> {
    let (w, v) = (q.w, q.imag());
    // q and -q are the same rotation: pick w >= 0 so the angle is at most pi.
    let (w, v) = if w < 0.0 { (-w, -v) } else { (w, v) };
    let s = v.norm();
    if s < 1e-12 {
        // angle = 2 atan2(s, w) ~ 2 s / w, and the axis is v / s.
        return v * (2.0 / w);
    }
    let angle = 2.0 * s.atan2(w);
    v * (angle / s)
}

/// Coefficients `(a, b)` with `J = I + a W + b W^2` for `W = [w]x`.
fn left_jacobian_coefficients(theta: f64) -> (f64, f64) {
    if theta < SMALL_ANGLE {
        let t2 = theta * theta;
        (0.5 - t2 / 24.0, 1.0 / 6.0 - t2 / 120.0)
    } else {
        let t2 = theta * theta;
        (
            (1.0 - theta.cos()) / t2,
            (theta - theta.sin()) / (t2 * theta),
        )
    }
}

/// The left Jacobian of SO(3): `exp(w + d) ~ exp(J(w) d) exp(w)` for small `d`.
#[must_use]
pub fn so3_left_jacobian(w: &Vector3<f64>) -> Matrix3<f64> {
    let (a, b) = left_jacobian_coefficients(w.norm());
    let h = so3_hat(w);
    Matrix3::identity() + h * a + h * h * b
}

/// The inverse of [`so3_left_jacobian`] (singular at angles of 2 pi; fine on `[0, pi]`).
#[must_use]
pub fn so3_left_jacobian_inverse(w: &Vector3<f64>) -> Matrix3<f64> {
    let theta = w.norm();
    let h = so3_hat(w);
    let c = if theta < SMALL_ANGLE {
        1.0 / 12.0 + theta * theta / 720.0
    } else {
        let half = 0.5 * theta;
        (1.0 - half * half.cos() / half.sin()) / (theta * theta)
    };
    Matrix3::identity() - h * 0.5 + h * h * c
}
