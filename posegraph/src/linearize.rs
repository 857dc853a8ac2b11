//! Edge errors and their analytic Jacobians for left perturbations `X <- exp(d) X`, in two
//! conventions ([`ErrorModel`]).
//!
//! Both are functions of `D = z^-1 a^-1 b`. Perturbing `b` gives `a^-1 exp(d) b = a^-1 b
//! exp(Ad(b^-1) d)`, so `D <- D exp(delta)` with `delta = Ad(b^-1) d`, and perturbing `a` gives
//! `delta = -Ad(b^-1) d`. Hence `de/db = M(D) Ad(b^-1)` and `de/da = -de/db`, where `M = de/ddelta`:
//! for the log map `e = log(D)`, `M = Jr^-1(e) = Jl^-1(-e)`; for g2o's `e = [t(D); v(D)]` (`v`
//! the quaternion's vector part with `w >= 0` in 3D, the angle in 2D), `D exp(delta)` moves `t` by
//! `R(D) rho` and `v` by `(w I + [v]x) phi / 2` in 3D (by `phi` in 2D), so `M` is block-diagonal.

use nalgebra::{Matrix3, Matrix6, SMatrix, SVector, Vector3, Vector6};
use slam_core::{
    GraphPose, Pose2, Pose3, se2_exp, se2_log, se3_adjoint, se3_exp, se3_left_jacobian, so3_hat,
    so3_left_jacobian_inverse,
};

/// Which edge error the optimisers minimise (`sum e^T Omega e`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum ErrorModel {
    /// `e = log(z^-1 a^-1 b)`, GTSAM's `BetweenFactor` convention (and the one of
    /// [`PoseGraph::cost`](slam_core::PoseGraph::cost)).
    #[default]
    LogMap,
    /// g2o's convention: `e = [t; q_xyz]` of `z^-1 a^-1 b` in 3D (unit quaternion with `w >= 0`),
    /// `[x, y, theta]` in 2D; the cost is then [`g2o_chi2`](crate::g2o::g2o_chi2). The two agree
    /// to first order, but not where an information matrix is nearly singular (a 1e12 weight on
    /// a translation makes the `1e-4` relative difference between the conventions matter).
    G2o,
}

/// A pose type the solvers can linearise, with `D` degrees of freedom.
pub trait Linearize<const D: usize>: GraphPose {
    /// The error of measurement `z` between `a` and `b` in convention `model`.
    fn error(model: ErrorModel, z: &Self, a: &Self, b: &Self) -> SVector<f64, D>;
    /// The error of measurement `z` between `a` and `b` and its Jacobian with respect to a left
    /// perturbation of `b` (the Jacobian for `a` is its negative).
    fn linearize(
        model: ErrorModel,
        z: &Self,
        a: &Self,
        b: &Self,
    ) -> (SVector<f64, D>, SMatrix<f64, D, D>);
    /// `exp(d) * self`.
    #[must_use]
    fn retract(&self, d: &SVector<f64, D>) -> Self;
    /// The information matrix as a fixed-size matrix.
    fn info(information: &Self::Information) -> SMatrix<f64, D, D>;
}

/// The inverse of SE(3)'s left Jacobian in closed form: with `J = [[Js, Q], [0, Js]]`,
/// `J^-1 = [[Js^-1, -Js^-1 Q Js^-1], [0, Js^-1]]` (`Js` the SO(3) Jacobian; `|phi| <= pi` for a
/// log-map error, where `Js` is invertible).
fn se3_left_jacobian_inverse(xi: &Vector6<f64>) -> Matrix6<f64> {
    let j = se3_left_jacobian(xi);
    let q = j.fixed_view::<3, 3>(0, 3).into_owned();
    let js_inv = so3_left_jacobian_inverse(&xi.fixed_rows::<3>(3).into_owned());
    let mut out = Matrix6::zeros();
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&js_inv);
    out.fixed_view_mut::<3, 3>(3, 3).copy_from(&js_inv);
    out.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&(-js_inv * q * js_inv));
    out
}

/// g2o's SE(3) error of `d` and `M = de/ddelta` for `d <- d exp(delta)`.
fn se3_g2o(d: &Pose3) -> (Vector6<f64>, Matrix6<f64>) {
    let q = d.rotation.quaternion();
    let s = if q.w < 0.0 { -1.0 } else { 1.0 };
    let v = q.imag() * s;
    let t = d.translation.vector;
    let mut m = Matrix6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(d.rotation.to_rotation_matrix().matrix());
    m.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&((Matrix3::identity() * (s * q.w) + so3_hat(&v)) * 0.5));
    (Vector6::new(t.x, t.y, t.z, v.x, v.y, v.z), m)
}

impl Linearize<6> for Pose3 {
    fn error(model: ErrorModel, z: &Self, a: &Self, b: &Self) -> Vector6<f64> {
        match model {
            ErrorModel::LogMap => Pose3::edge_error(z, a, b),
            ErrorModel::G2o => se3_g2o(&(z.inverse() * (a.inverse() * b))).0,
        }
    }
    fn linearize(model: ErrorModel, z: &Self, a: &Self, b: &Self) -> (Vector6<f64>, Matrix6<f64>) {
        let (e, m) = match model {
            ErrorModel::LogMap => {
                let e = Pose3::edge_error(z, a, b);
                (e, se3_left_jacobian_inverse(&(-e)))
            }
            ErrorModel::G2o => se3_g2o(&(z.inverse() * (a.inverse() * b))),
        };
        (e, m * se3_adjoint(&b.inverse()))
    }
    fn retract(&self, d: &Vector6<f64>) -> Self {
        se3_exp(d) * self
    }
    fn info(information: &Matrix6<f64>) -> Matrix6<f64> {
        *information
    }
}

/// The SE(2) adjoint for tangent `[x, y, theta]`.
fn se2_adjoint(t: &Pose2) -> Matrix3<f64> {
    let (c, s) = (t.rotation.cos_angle(), t.rotation.sin_angle());
    let p = t.translation.vector;
    Matrix3::new(c, -s, p.y, s, c, -p.x, 0.0, 0.0, 1.0)
}

/// `Jr^-1` of SE(2) to second order: `I + ad(e) / 2 + ad(e)^2 / 12`.
fn se2_right_jacobian_inverse(e: &Vector3<f64>) -> Matrix3<f64> {
    let ad = Matrix3::new(0.0, -e.z, e.y, e.z, 0.0, -e.x, 0.0, 0.0, 0.0);
    Matrix3::identity() + ad * 0.5 + ad * ad / 12.0
}

/// g2o's SE(2) error of `d` and `M = de/ddelta`.
fn se2_g2o(d: &Pose2) -> (Vector3<f64>, Matrix3<f64>) {
    let (c, s) = (d.rotation.cos_angle(), d.rotation.sin_angle());
    let t = d.translation.vector;
    (
        Vector3::new(t.x, t.y, d.rotation.angle()),
        Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0),
    )
}

impl Linearize<3> for Pose2 {
    fn error(model: ErrorModel, z: &Self, a: &Self, b: &Self) -> Vector3<f64> {
        let d = z.inverse() * (a.inverse() * b);
        match model {
            ErrorModel::LogMap => se2_log(&d),
            ErrorModel::G2o => se2_g2o(&d).0,
        }
    }
    fn linearize(model: ErrorModel, z: &Self, a: &Self, b: &Self) -> (Vector3<f64>, Matrix3<f64>) {
        let d = z.inverse() * (a.inverse() * b);
        let (e, m) = match model {
            ErrorModel::LogMap => {
                let e = se2_log(&d);
                (e, se2_right_jacobian_inverse(&e))
            }
            ErrorModel::G2o => se2_g2o(&d),
        };
        (e, m * se2_adjoint(&b.inverse()))
    }
    fn retract(&self, d: &Vector3<f64>) -> Self {
        se2_exp(d) * self
    }
    fn info(information: &Matrix3<f64>) -> Matrix3<f64> {
        *information
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use slam_core::pose3_from_xyz_rpy;

    /// Central differences of `error` against the analytic Jacobians.
    fn check<P: Linearize<D>, const D: usize>(model: ErrorModel, z: P, a: P, b: P, tol: f64) {
        let (e0, jb) = P::linearize(model, &z, &a, &b);
        let ja = -jb;
        assert!((e0 - P::error(model, &z, &a, &b)).amax() == 0.0);
        let h = 1e-6;
        for k in 0..D {
            let mut d = SVector::<f64, D>::zeros();
            d[k] = h;
            let fd = (P::error(model, &z, &a.retract(&d), &b)
                - P::error(model, &z, &a.retract(&(-d)), &b))
                / (2.0 * h);
            assert!(
                (fd - ja.column(k)).amax() < tol,
                "{model:?} a {k}: {fd} vs {}",
                ja.column(k)
            );
            let fd = (P::error(model, &z, &a, &b.retract(&d))
                - P::error(model, &z, &a, &b.retract(&(-d))))
                / (2.0 * h);
            assert!(
                (fd - jb.column(k)).amax() < tol,
                "{model:?} b {k}: {fd} vs {}",
                jb.column(k)
            );
        }
        assert!(e0.iter().all(|v| v.is_finite()));
    }

    #[test]
    fn jacobians_match_finite_differences() {
        let a = pose3_from_xyz_rpy(1.0, -2.0, 0.5, 0.2, -0.3, 1.0);
        let b = pose3_from_xyz_rpy(2.0, 1.0, -0.5, -0.1, 0.4, 2.5);
        let z = pose3_from_xyz_rpy(0.7, 2.6, -1.2, -0.2, 0.5, 1.2);
        check::<Pose3, 6>(ErrorModel::LogMap, z, a, b, 1e-5);
        let j = se3_left_jacobian(&Vector6::new(0.3, -0.2, 0.5, 1.0, -2.0, 0.4));
        let inv = se3_left_jacobian_inverse(&Vector6::new(0.3, -0.2, 0.5, 1.0, -2.0, 0.4));
        assert!((j * inv - Matrix6::identity()).amax() < 1e-12);
        check::<Pose3, 6>(ErrorModel::G2o, z, a, b, 1e-5);
        // g2o's error with a quaternion whose w is negative before the sign flip.
        let far = pose3_from_xyz_rpy(0.7, 2.6, -1.2, 2.9, 0.5, 1.2);
        check::<Pose3, 6>(ErrorModel::G2o, far, a, b, 1e-5);
        let a2 = Pose2::new(nalgebra::Vector2::new(1.0, 2.0), 0.3);
        let b2 = Pose2::new(nalgebra::Vector2::new(-1.0, 4.0), 2.0);
        // SE(2)'s log-map Jr^-1 is second order, exact near the optimum: test with a small error.
        let z2 = a2.inverse() * b2 * Pose2::new(nalgebra::Vector2::new(0.01, -0.02), 0.01);
        check::<Pose2, 3>(ErrorModel::LogMap, z2, a2, b2, 1e-4);
        assert!(Pose2::error(ErrorModel::LogMap, &z2, &a2, &b2).norm() < 0.05);
        // g2o's SE(2) Jacobian is exact everywhere.
        let z3 = Pose2::new(nalgebra::Vector2::new(0.5, -3.0), -1.0);
        check::<Pose2, 3>(ErrorModel::G2o, z3, a2, b2, 1e-6);
    }
}
