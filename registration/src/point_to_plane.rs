//! Point-to-plane ICP: Gauss-Newton on SE(3) with target normals from PCA.

use nalgebra::{Matrix6, Vector6};
use slam_core::{Degeneracy, PointCloud, Pose3, RegistrationError, SweepAlignment};

use crate::config::IcpConfig;
use crate::icp::{IcpStep, Pair};
use crate::icp_backend::icp_backend;
use crate::target::PreparedTarget;

/// Point-to-plane ICP: residual `n . (T p - q)` against the target point's normal (PCA over its
/// nearest neighbours), minimised by Gauss-Newton steps on SE(3) with robust weights.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PointToPlaneIcp {
    /// Settings.
    pub config: IcpConfig,
}

struct GaussNewtonPlane;

/// `(J^T W J, J^T W r)` of the pairs with a non-zero weight.
fn normal_equations(pairs: &[Pair], weights: &[f64]) -> (Matrix6<f64>, Vector6<f64>) {
    let mut h = Matrix6::zeros();
    let mut b = Vector6::zeros();
    for (p, w) in pairs.iter().zip(weights) {
        if *w == 0.0 {
            continue;
        }
        let j = row(p);
        // Lower triangle only, in place.
        h.syger(*w, &j, &j, 1.0);
        b.axpy(GaussNewtonPlane::residual(p) * w, &j, 1.0);
    }
    h.fill_upper_triangle_with_lower_triangle();
    (h, b)
}

/// `J = [n^T, (p x n)^T]` for a left perturbation of the moved point `p`.
fn row(pair: &Pair) -> Vector6<f64> {
    let n = pair.n.unwrap_or_default();
    let c = pair.p.coords.cross(&n);
    Vector6::new(n.x, n.y, n.z, c.x, c.y, c.z)
}

impl IcpStep for GaussNewtonPlane {
    const TARGET_NORMALS: bool = true;

    fn pair_points(_config: &IcpConfig) -> usize {
        1
    }

    fn residual(pair: &Pair) -> f64 {
        pair.n.map_or(f64::INFINITY, |n| n.dot(&(pair.p - pair.q)))
    }

    fn step(pairs: &[Pair], weights: &[f64]) -> Result<Vector6<f64>, RegistrationError> {
        let (h, b) = normal_equations(pairs, weights);
        h.cholesky()
            .map(|c| -c.solve(&b))
            .ok_or(RegistrationError::Degenerate {
                cause: Degeneracy::SingularNormalEquations,
            })
    }

    fn normal_equations(pairs: &[Pair], weights: &[f64]) -> Option<(Matrix6<f64>, Vector6<f64>)> {
        Some(normal_equations(pairs, weights))
    }

    fn information(pairs: &[Pair], weights: &[f64]) -> Matrix6<f64> {
        normal_equations(pairs, weights).0
    }

    /// Point-to-plane registration of the sweep together with the correction to the velocity
    /// it was deskewed with (see the crate docs' sweep section).
    fn align_sweep(
        config: &IcpConfig,
        sweep: &PointCloud,
        target: &PreparedTarget,
        initial: &Pose3,
    ) -> Option<Result<SweepAlignment, RegistrationError>> {
        Some(crate::sweep::align_sweep(config, sweep, target, initial))
    }
}

icp_backend!(PointToPlaneIcp, GaussNewtonPlane);
