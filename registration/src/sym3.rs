//! Eigen-decomposition of a symmetric 3x3 matrix in closed form: the LOAM matcher fits a line or
//! a plane to every correspondence's patch, and the iterative solver dominated its time.

use nalgebra::{Matrix3, SymmetricEigen, Vector3};

/// Eigenvalues in ascending order and the matching unit eigenvectors as columns.
pub(crate) struct Eigen3 {
    pub(crate) values: Vector3<f64>,
    pub(crate) vectors: Matrix3<f64>,
}

/// The iterative solver, sorted: used when the closed form is ill-conditioned.
fn iterative(a: &Matrix3<f64>) -> Eigen3 {
    let eig = SymmetricEigen::new(*a);
    let mut idx = [0, 1, 2];
    idx.sort_unstable_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    Eigen3 {
        values: Vector3::new(
            eig.eigenvalues[idx[0]],
            eig.eigenvalues[idx[1]],
            eig.eigenvalues[idx[2]],
        ),
        vectors: Matrix3::from_columns(&[
            eig.eigenvectors.column(idx[0]).into_owned(),
            eig.eigenvectors.column(idx[1]).into_owned(),
            eig.eigenvectors.column(idx[2]).into_owned(),
        ]),
    }
}

/// The unit null vector of the rank-2 matrix `a - lambda I`: the largest cross product of two
/// of its rows, or `None` when every cross product is too small to trust (a repeated eigenvalue).
fn null_vector(a: &Matrix3<f64>, lambda: f64, scale: f64) -> Option<Vector3<f64>> {
    let m = a - Matrix3::from_diagonal_element(lambda);
    let (r0, r1, r2) = (
        m.row(0).transpose(),
        m.row(1).transpose(),
        m.row(2).transpose(),
    );
    let c = [r0.cross(&r1), r0.cross(&r2), r1.cross(&r2)];
    let best = c
        .iter()
        .max_by(|x, y| x.norm_squared().total_cmp(&y.norm_squared()))?;
    let n2 = best.norm_squared();
    (n2 > 1e-12 * scale * scale * scale * scale).then(|| best / n2.sqrt())
}

/// Eigenvalues (ascending) and eigenvectors of symmetric `a` (only its lower triangle is read
/// as written; the caller passes a symmetric matrix).
pub(crate) fn symmetric_eigen3(a: &Matrix3<f64>) -> Eigen3 {
    // Trigonometric solution of the characteristic cubic (Smith 1961).
    let q = a.trace() / 3.0;
    let p1 = a[(0, 1)].powi(2) + a[(0, 2)].powi(2) + a[(1, 2)].powi(2);
    let p2 = (a[(0, 0)] - q).powi(2) + (a[(1, 1)] - q).powi(2) + (a[(2, 2)] - q).powi(2) + 2.0 * p1;
    let p = (p2 / 6.0).sqrt();
    if !(p > 0.0 && p.is_finite()) {
        return iterative(a);
    }
    let b = (a - Matrix3::from_diagonal_element(q)) / p;
    let r = (b.determinant() / 2.0).clamp(-1.0, 1.0);
    let phi = r.acos() / 3.0;
    let hi = q + 2.0 * p * phi.cos();
    let lo = q + 2.0 * p * (phi + 2.0 * std::f64::consts::FRAC_PI_3).cos();
    let mid = 3.0 * q - hi - lo;
    // Eigenvectors of the two outer eigenvalues from cross products; the middle one completes
    // the frame. Near-repeated eigenvalues make the cross products unreliable: fall back.
    let scale = p.max(q.abs());
    let (Some(v0), Some(v2)) = (null_vector(a, lo, scale), null_vector(a, hi, scale)) else {
        return iterative(a);
    };
    if v0.dot(&v2).abs() > 1e-6 || hi - mid < 1e-9 * scale || mid - lo < 1e-9 * scale {
        return iterative(a);
    }
    let v1 = v2.cross(&v0);
    Eigen3 {
        values: Vector3::new(lo, mid, hi),
        vectors: Matrix3::from_columns(&[v0, v1, v2]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(3000))]

        /// Against nalgebra's iterative solver on random covariances, including near-degenerate
        /// ones (points on a line, on a plane).
        #[test]
        fn matches_the_iterative_solver(
            raw in prop::array::uniform5((-0.5..0.5f64, -0.5..0.5f64, -0.5..0.5f64)),
            squash in prop::sample::select(vec![1.0, 1e-3, 1e-6]),
            flat_z in any::<bool>(),
        ) {
            let pts: Vec<Vector3<f64>> = raw
                .iter()
                .map(|&(x, y, z)| {
                    Vector3::new(x, y * squash, z * if flat_z { squash } else { 1.0 })
                })
                .collect();
            let mean = pts.iter().sum::<Vector3<f64>>() / 5.0;
            let cov = pts.iter().fold(Matrix3::zeros(), |m, p| {
                m + (p - mean) * (p - mean).transpose()
            });
            let fast = symmetric_eigen3(&cov);
            let slow = iterative(&cov);
            let norm = cov.norm();
            for k in 0..3 {
                prop_assert!(
                    (fast.values[k] - slow.values[k]).abs() <= 1e-9 * norm,
                    "{:?} vs {:?}",
                    fast.values,
                    slow.values
                );
                // Each column is an eigenvector: A v = lambda v.
                let v = fast.vectors.column(k);
                prop_assert!((v.norm() - 1.0).abs() < 1e-9);
                prop_assert!((cov * v - v * fast.values[k]).norm() <= 1e-7 * norm);
            }
        }
    }
}
