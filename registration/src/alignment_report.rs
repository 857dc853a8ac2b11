//! The report every backend ends an alignment with: what its loop reached, the fit at the final
//! pose, and the ratios derived from them the same way for every backend.

use nalgebra::{Matrix6, SymmetricEigen};
use slam_core::{Alignment, Pose3};

/// The [`Alignment`] of a loop that ended at `pose` after `iterations` (`converged` when its
/// update fell below the tolerances first), where `inliers` of the `source_points` it aligned
/// kept a correspondence with RMS residual `rmse` and `information` is `J^T W J` there.
pub(crate) fn alignment_report(
    pose: Pose3,
    converged: bool,
    iterations: usize,
    inliers: usize,
    source_points: usize,
    rmse: f64,
    information: &Matrix6<f64>,
) -> Alignment {
    Alignment {
        pose,
        converged,
        iterations,
        inliers,
        inlier_ratio: inliers as f64 / source_points.max(1) as f64,
        rmse,
        min_eigenvalue_ratio: min_eigenvalue_ratio(information),
        information: *information,
    }
}

/// Smallest eigenvalue of an information matrix over its largest (0 when it is not positive).
fn min_eigenvalue_ratio(information: &Matrix6<f64>) -> f64 {
    let eig = SymmetricEigen::new(*information).eigenvalues;
    let (lo, hi) = (eig.min(), eig.max());
    if hi > 0.0 { (lo / hi).max(0.0) } else { 0.0 }
}
