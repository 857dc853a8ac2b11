//! SE(2): exponential and logarithm. Tangent order `[x, y, theta]`.

use nalgebra::{Isometry2, Vector2, Vector3};

/// `(sin t / t, (1 - cos t) / t)` with series near zero.
fn v_coefficients(theta: f64) -> (f64, f64) {
    if theta.abs() < 1e-4 {
        let t2 = theta * theta;
        (1.0 - t2 / 6.0, theta / 2.0 - theta * t2 / 24.0)
    } else {
        (theta.sin() / theta, (1.0 - theta.cos()) / theta)
    }
}

/// The planar rigid transform `exp([x, y, theta])`.
#[must_use]
pub fn se2_exp(xi: &Vector3<f64>) -> Isometry2<f64> {
    let (a, b) = v_coefficients(xi.z);
    let t = Vector2::new(a * xi.x - b * xi.y, b * xi.x + a * xi.y);
    Isometry2::new(t, xi.z)
}

/// `angle` (radians) wrapped to `(-pi, pi]`: a heading error or a turn, the short way round.
///
/// ```
/// use std::f64::consts::PI;
/// use slam_core::wrap_angle;
///
/// assert!((wrap_angle(1.5 * PI) + 0.5 * PI).abs() < 1e-12);
/// assert_eq!(wrap_angle(-PI), PI);
/// ```
#[must_use]
pub fn wrap_angle(angle: f64) -> f64 {
    let a = angle.rem_euclid(std::f64::consts::TAU);
    if a > std::f64::consts::PI {
        a - std::f64::consts::TAU
    } else {
        a
    }
}

/// The twist `[x, y, theta]` with `exp(xi) = t`, `theta` in `(-pi, pi]`.
#[must_use]
pub fn se2_log(t: &Isometry2<f64>) -> Vector3<f64> {
    let theta = t.rotation.angle();
    let (a, b) = v_coefficients(theta);
    let det = a * a + b * b;
    let v = t.translation.vector;
    // Inverse of [[a, -b], [b, a]].
    Vector3::new((a * v.x + b * v.y) / det, (-b * v.x + a * v.y) / det, theta)
}
