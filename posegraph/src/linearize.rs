//! Edge errors and their analytic Jacobians for left perturbations `X <- exp(d) X`.
//!
//! For `e = log(z^-1 a^-1 b)`: perturbing `b` gives `a^-1 exp(d) b = a^-1 b exp(Ad(b^-1) d)`, so
//! `de/db = Jr^-1(e) Ad(b^-1)` and `de/da = -de/db`, with `Jr^-1(e) = Jl^-1(-e)`.

use nalgebra::{Matrix3, Matrix6, SMatrix, SVector, Vector3, Vector6};
use slam_core::{
    GraphPose, Pose2, Pose3, se2_exp, se2_log, se3_adjoint, se3_exp, se3_left_jacobian,
};

/// A pose type the solvers can linearise, with `D` degrees of freedom.
pub trait Linearize<const D: usize>: GraphPose {
    /// The error of measurement `z` between `a` and `b` and its Jacobians with respect to left
    /// perturbations of `a` and of `b`.
    fn linearize(
        z: &Self,
        a: &Self,
        b: &Self,
    ) -> (SVector<f64, D>, SMatrix<f64, D, D>, SMatrix<f64, D, D>);
    /// `exp(d) * self`.
    #[must_use]
    fn retract(&self, d: &SVector<f64, D>) -> Self;
    /// The information matrix as a fixed-size matrix.
    fn info(information: &Self::Information) -> SMatrix<f64, D, D>;
}

impl Linearize<6> for Pose3 {
    fn linearize(z: &Self, a: &Self, b: &Self) -> (Vector6<f64>, Matrix6<f64>, Matrix6<f64>) {
        let e = Pose3::edge_error(z, a, b);
        let jl = se3_left_jacobian(&(-e));
        // J is well conditioned for |phi| < pi; fall back to the first-order identity otherwise.
        let jr_inv = jl.try_inverse().unwrap_or_else(Matrix6::identity);
        let jb = jr_inv * se3_adjoint(&b.inverse());
        (e, -jb, jb)
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

impl Linearize<3> for Pose2 {
    fn linearize(z: &Self, a: &Self, b: &Self) -> (Vector3<f64>, Matrix3<f64>, Matrix3<f64>) {
        let e = se2_log(&(z.inverse() * (a.inverse() * b)));
        let jb = se2_right_jacobian_inverse(&e) * se2_adjoint(&b.inverse());
        (e, -jb, jb)
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

    fn check<P: Linearize<D>, const D: usize>(z: P, a: P, b: P) {
        let (e0, ja, jb) = P::linearize(&z, &a, &b);
        let h = 1e-6;
        for k in 0..D {
            let mut d = SVector::<f64, D>::zeros();
            d[k] = h;
            let (ep, _, _) = P::linearize(&z, &a.retract(&d), &b);
            let (em, _, _) = P::linearize(&z, &a.retract(&(-d)), &b);
            let fd = (ep - em) / (2.0 * h);
            assert!(
                (fd - ja.column(k)).amax() < 1e-5,
                "a {k}: {fd} vs {}",
                ja.column(k)
            );
            let (ep, _, _) = P::linearize(&z, &a, &b.retract(&d));
            let (em, _, _) = P::linearize(&z, &a, &b.retract(&(-d)));
            let fd = (ep - em) / (2.0 * h);
            assert!(
                (fd - jb.column(k)).amax() < 1e-5,
                "b {k}: {fd} vs {}",
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
        check::<Pose3, 6>(z, a, b);
        let a2 = Pose2::new(nalgebra::Vector2::new(1.0, 2.0), 0.3);
        let b2 = Pose2::new(nalgebra::Vector2::new(-1.0, 4.0), 2.0);
        // SE(2) uses a second-order Jr^-1, exact near the optimum: test with a small error.
        let z2 = a2.inverse() * b2 * Pose2::new(nalgebra::Vector2::new(0.01, -0.02), 0.01);
        let (e, ja, jb) = Pose2::linearize(&z2, &a2, &b2);
        let h = 1e-6;
        for k in 0..3 {
            let mut d = Vector3::zeros();
            d[k] = h;
            let fd = (Pose2::linearize(&z2, &a2, &b2.retract(&d)).0
                - Pose2::linearize(&z2, &a2, &b2.retract(&(-d))).0)
                / (2.0 * h);
            assert!((fd - jb.column(k)).amax() < 1e-4, "{fd} {}", jb.column(k));
            let fd = (Pose2::linearize(&z2, &a2.retract(&d), &b2).0
                - Pose2::linearize(&z2, &a2.retract(&(-d)), &b2).0)
                / (2.0 * h);
            assert!((fd - ja.column(k)).amax() < 1e-4);
        }
        assert!(e.norm() < 0.05);
    }
}
