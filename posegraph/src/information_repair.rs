//! What a reader does with an information matrix that is not positive definite: refuse it (the
//! default), or replace it by the nearest positive-definite matrix and say so.
//!
//! Some public benchmark graphs carry such matrices (large cross terms between the z translation
//! and roll or pitch make a third of one SE(3) set's edges indefinite); an optimiser cannot weigh
//! an edge by them, and silently altering a user's file is not an option, so repair is explicit.
//! The repair is Higham's nearest symmetric positive semi-definite matrix in the Frobenius norm
//! ("Computing a nearest symmetric positive semidefinite matrix", Linear Algebra Appl. 103,
//! 1988): symmetrise, then clip the eigenvalues, here to a small positive floor instead of zero so
//! that the result is definite.

use nalgebra::{Matrix3, Matrix6, SMatrix, SVector};
use slam_core::{GraphPose, Pose2, Pose3};

use crate::error::GraphFileError;

/// The eigenvalue floor of a repaired matrix relative to its largest eigenvalue
/// ([`InformationRepair::NearestPositiveDefinite`]'s default): a condition number of at most
/// 1e6, so the repaired edge stays well within f64's reach in the normal equations.
pub const DEFAULT_MIN_EIGENVALUE_RATIO: f64 = 1e-6;

/// What a reader does with an edge whose information matrix is not positive definite.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(tag = "kind", deny_unknown_fields)
)]
pub enum InformationRepair {
    /// Refuse the file ([`GraphFileError::InformationNotPositiveDefinite`], which names the
    /// repair option).
    #[default]
    Refuse,
    /// Replace it by the nearest positive-definite matrix: the symmetric part with every
    /// eigenvalue below `min_eigenvalue_ratio` times the largest raised to that floor (the
    /// eigenvectors kept). A matrix with no positive eigenvalue cannot be repaired and is refused.
    NearestPositiveDefinite {
        /// The floor relative to the largest eigenvalue; in (0, 1), usually
        /// [`DEFAULT_MIN_EIGENVALUE_RATIO`].
        min_eigenvalue_ratio: f64,
    },
}

impl InformationRepair {
    /// [`InformationRepair::NearestPositiveDefinite`] with [`DEFAULT_MIN_EIGENVALUE_RATIO`].
    #[must_use]
    pub fn nearest_positive_definite() -> Self {
        Self::NearestPositiveDefinite {
            min_eigenvalue_ratio: DEFAULT_MIN_EIGENVALUE_RATIO,
        }
    }
}

/// An edge whose information matrix a reader replaced.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct RepairedEdge {
    /// 1-based line of the file.
    pub line: usize,
    /// Index of the edge in the graph.
    pub edge: usize,
    /// The smallest eigenvalue of the matrix as written (of its symmetric part).
    pub smallest_eigenvalue: f64,
    /// The Frobenius norm of the change, relative to the matrix's.
    pub relative_change: f64,
}

/// An information matrix type the readers can repair: SE(2)'s 3x3 and SE(3)'s 6x6.
pub trait RepairableInformation: Copy + Sized {
    /// Whether the graph accepts it as it is.
    fn is_valid(&self) -> bool;
    /// The nearest positive-definite matrix with eigenvalues at least `ratio` times the largest,
    /// and the smallest eigenvalue before; `None` without a positive eigenvalue or when the
    /// result is still refused.
    fn nearest_positive_definite(&self, ratio: f64) -> Option<(Self, f64)>;
    /// Frobenius norm.
    fn norm(&self) -> f64;
    /// Frobenius norm of `self - other`.
    fn distance(&self, other: &Self) -> f64;
}

/// `V diag(max(lambda, floor)) V^T` for the eigen-decomposition `(values, vectors)`, with the
/// floor at `ratio` times the largest eigenvalue; `None` when none is positive.
fn clip<const N: usize>(
    values: &SVector<f64, N>,
    vectors: &SMatrix<f64, N, N>,
    ratio: f64,
) -> Option<(SMatrix<f64, N, N>, f64)> {
    let largest = values.max();
    let smallest = values.min();
    if !(largest.is_finite() && largest > 0.0 && ratio > 0.0 && ratio < 1.0) {
        return None;
    }
    let floor = largest * ratio;
    let clipped = SMatrix::<f64, N, N>::from_diagonal(&values.map(|v| v.max(floor)));
    let m = vectors * clipped * vectors.transpose();
    Some(((m + m.transpose()) * 0.5, smallest))
}

/// The two implementations differ only in their types (nalgebra's eigen-decomposition needs a
/// concrete dimension).
macro_rules! repairable {
    ($matrix:ty, $pose:ty) => {
        impl RepairableInformation for $matrix {
            fn is_valid(&self) -> bool {
                <$pose>::information_is_valid(self)
            }
            fn nearest_positive_definite(&self, ratio: f64) -> Option<(Self, f64)> {
                let e = ((self + self.transpose()) * 0.5).symmetric_eigen();
                clip(&e.eigenvalues, &e.eigenvectors, ratio).filter(|(m, _)| m.is_valid())
            }
            fn norm(&self) -> f64 {
                nalgebra::Matrix::norm(self)
            }
            fn distance(&self, other: &Self) -> f64 {
                nalgebra::Matrix::norm(&(self - other))
            }
        }
    };
}

repairable!(Matrix6<f64>, Pose3);
repairable!(Matrix3<f64>, Pose2);

impl InformationRepair {
    /// The information edge `edge` (file line `line`) enters the graph with: `info` itself when
    /// valid; under [`InformationRepair::NearestPositiveDefinite`] the repaired matrix, recorded
    /// in `repaired`.
    ///
    /// # Errors
    /// [`GraphFileError::InformationNotPositiveDefinite`] when refused, or when it cannot be
    /// repaired (no positive eigenvalue).
    pub fn apply<M: RepairableInformation>(
        &self,
        info: M,
        line: usize,
        edge: usize,
        repaired: &mut Vec<RepairedEdge>,
    ) -> Result<M, GraphFileError> {
        if info.is_valid() {
            return Ok(info);
        }
        let refused = GraphFileError::InformationNotPositiveDefinite { line, edge };
        let Self::NearestPositiveDefinite {
            min_eigenvalue_ratio,
        } = *self
        else {
            return Err(refused);
        };
        let (fixed, smallest_eigenvalue) = info
            .nearest_positive_definite(min_eigenvalue_ratio)
            .ok_or(refused)?;
        repaired.push(RepairedEdge {
            line,
            edge,
            smallest_eigenvalue,
            relative_change: fixed.distance(&info) / info.norm().max(f64::MIN_POSITIVE),
        });
        Ok(fixed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Independent oracle for positive definiteness: Sylvester's criterion (every leading
    /// principal minor positive), by determinants rather than an eigen-decomposition.
    fn sylvester(m: &Matrix6<f64>) -> bool {
        (1..=6).all(|k| m.view((0, 0), (k, k)).into_owned().determinant() > 0.0)
    }

    #[test]
    fn an_indefinite_matrix_is_refused_or_repaired_and_recorded() {
        // Diagonal 100 with a z-roll cross term of 150: eigenvalues -50 and 250 in that plane.
        let mut info = Matrix6::identity() * 100.0;
        info[(2, 3)] = 150.0;
        info[(3, 2)] = 150.0;
        assert!(!info.is_valid() && !sylvester(&info));
        let mut repaired = Vec::new();
        assert!(matches!(
            InformationRepair::Refuse.apply(info, 7, 3, &mut repaired),
            Err(GraphFileError::InformationNotPositiveDefinite { line: 7, edge: 3 })
        ));
        assert!(repaired.is_empty());
        let fixed = InformationRepair::nearest_positive_definite()
            .apply(info, 7, 3, &mut repaired)
            .unwrap();
        assert!(fixed.is_valid() && sylvester(&fixed));
        assert_eq!(repaired.len(), 1);
        assert!((repaired[0].smallest_eigenvalue + 50.0).abs() < 1e-9);
        // Only the indefinite plane changed: the other entries are as written.
        for (r, c) in [(0, 0), (1, 1), (4, 4), (5, 5), (0, 1), (4, 5)] {
            assert!((fixed[(r, c)] - info[(r, c)]).abs() < 1e-9, "({r}, {c})");
        }
        // Higham's result in that plane, by hand: eigenvalues 250 along (1, 1) and -50 along
        // (1, -1); the -50 raised to the floor f = 250e-6 gives 125 + f / 2 on the diagonal and
        // 125 - f / 2 off it.
        let floor = 250.0 * DEFAULT_MIN_EIGENVALUE_RATIO;
        assert!((fixed[(2, 2)] - (125.0 + floor / 2.0)).abs() < 1e-9);
        assert!((fixed[(3, 3)] - (125.0 + floor / 2.0)).abs() < 1e-9);
        assert!((fixed[(2, 3)] - (125.0 - floor / 2.0)).abs() < 1e-9);
        // A valid matrix passes untouched and unrecorded.
        let good = Matrix6::identity() * 3.0;
        assert_eq!(
            InformationRepair::nearest_positive_definite()
                .apply(good, 1, 0, &mut repaired)
                .unwrap(),
            good
        );
        assert_eq!(repaired.len(), 1);
        // No positive eigenvalue: nothing to repair towards.
        let negative = -Matrix3::<f64>::identity();
        assert!(
            InformationRepair::nearest_positive_definite()
                .apply(negative, 2, 1, &mut repaired)
                .is_err()
        );
    }
}
