//! SE(3): hat/vee, exponential and logarithm, left Jacobian and adjoint. Tangent order
//! `[rho; phi]`.

use nalgebra::{Isometry3, Matrix3, Matrix4, Matrix6, Translation3, Vector3, Vector6};

use super::so3::{so3_exp, so3_hat, so3_left_jacobian, so3_left_jacobian_inverse, so3_log};

fn split(xi: &Vector6<f64>) -> (Vector3<f64>, Vector3<f64>) {
    (
        xi.fixed_rows::<3>(0).into_owned(),
        xi.fixed_rows::<3>(3).into_owned(),
    )
}

/// The 4x4 twist matrix of `xi = [rho; phi]`.
#[must_use]
pub fn se3_hat(xi: &Vector6<f64>) -> Matrix4<f64> {
    let (rho, phi) = split(xi);
    let mut m = Matrix4::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&so3_hat(&phi));
    m.fixed_view_mut::<3, 1>(0, 3).copy_from(&rho);
    m
}

/// The twist vector `[rho; phi]` of a 4x4 twist matrix (inverse of [`se3_hat`]).
#[must_use]
pub fn se3_vee(m: &Matrix4<f64>) -> Vector6<f64> {
    let phi = super::so3::so3_vee(&m.fixed_view::<3, 3>(0, 0).into_owned());
    let rho = m.fixed_view::<3, 1>(0, 3).into_owned();
    Vector6::new(rho.x, rho.y, rho.z, phi.x, phi.y, phi.z)
}

/// The rigid transform `exp(xi)`.
#[must_use]
pub fn se3_exp(xi: &Vector6<f64>) -> Isometry3<f64> {
    let (rho, phi) = split(xi);
    let t = so3_left_jacobian(&phi) * rho;
    Isometry3::from_parts(Translation3::from(t), so3_exp(&phi))
}

/// The twist `[rho; phi]` with `exp(xi) = t`, rotation angle in `[0, pi]`.
#[must_use]
pub fn se3_log(t: &Isometry3<f64>) -> Vector6<f64> {
    let phi = so3_log(&t.rotation);
    let rho = so3_left_jacobian_inverse(&phi) * t.translation.vector;
    Vector6::new(rho.x, rho.y, rho.z, phi.x, phi.y, phi.z)
}

/// The adjoint of `t`, with `t exp(xi) t^-1 = exp(Ad(t) xi)`.
#[must_use]
pub fn se3_adjoint(t: &Isometry3<f64>) -> Matrix6<f64> {
    let r = t.rotation.to_rotation_matrix().into_inner();
    let mut ad = Matrix6::zeros();
    ad.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
    ad.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&(so3_hat(&t.translation.vector) * r));
    ad.fixed_view_mut::<3, 3>(3, 3).copy_from(&r);
    ad
}

/// Barfoot's `Q(rho, phi)`, the upper-right block of the SE(3) left Jacobian.
fn q_block(rho: &Vector3<f64>, phi: &Vector3<f64>) -> Matrix3<f64> {
    let theta = phi.norm();
    let (p, r) = (so3_hat(phi), so3_hat(rho));
    let t2 = theta * theta;
    let (c1, c2, c3) = if theta < 1e-3 {
        (
            1.0 / 6.0 - t2 / 120.0,
            1.0 / 24.0 - t2 / 720.0,
            1.0 / 120.0 - t2 / 2520.0,
        )
    } else {
        let (s, c) = theta.sin_cos();
        (
            (theta - s) / (t2 * theta),
            (t2 + 2.0 * c - 2.0) / (2.0 * t2 * t2),
            (2.0 * theta - 3.0 * s + theta * c) / (2.0 * t2 * t2 * theta),
        )
    };
    let pr = p * r;
    let rp = r * p;
    let prp = pr * p;
    r * 0.5 + (pr + rp + prp) * c1 + (p * pr + rp * p - prp * 3.0) * c2 + (prp * p + p * prp) * c3
}

/// The left Jacobian of SE(3): `exp(xi + d) ~ exp(J(xi) d) exp(xi)` for small `d`.
#[must_use]
pub fn se3_left_jacobian(xi: &Vector6<f64>) -> Matrix6<f64> {
    let (rho, phi) = split(xi);
    let j = so3_left_jacobian(&phi);
    let mut out = Matrix6::zeros();
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&j);
    out.fixed_view_mut::<3, 3>(3, 3).copy_from(&j);
    out.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&q_block(&rho, &phi));
    out
}
