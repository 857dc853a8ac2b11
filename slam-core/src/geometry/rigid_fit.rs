//! The least-squares rigid transform between paired points, in closed form: centroids, the
//! cross-covariance and its SVD (Arun, Huang & Blostein, "Least-squares fitting of two 3-D point
//! sets", IEEE TPAMI 1987; Kabsch 1976), with Umeyama's guard that turns a reflection into the
//! best proper rotation (Umeyama, "Least-squares estimation of transformation parameters between
//! two point patterns", IEEE TPAMI 1991, eq. 39), without scale.

use nalgebra::{Matrix3, Point3, Rotation3, UnitQuaternion, Vector3};

use super::pose::Pose3;
use crate::error::RigidFitError;

/// Pairs a fit needs at the least: fewer leave a rotation undetermined.
const MIN_PAIRS: usize = 3;

/// One correspondence of [`fit_weighted_rigid_transform`]: `from` should land on `to`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WeightedPair {
    /// The point to move.
    pub from: Point3<f64>,
    /// Where it should land.
    pub to: Point3<f64>,
    /// Its weight: finite and not negative (0 leaves the pair out).
    pub weight: f64,
}

/// The rigid transform `to_T_from` minimising `sum |to_i - T from_i|^2`, so that
/// `to[i] ≈ T * from[i]`.
///
/// Collinear points leave the rotation about their line undetermined (the fit then returns one
/// of the minimisers), and nearly collinear ones determine it poorly: for three exact pairs
/// whose second principal spread is a tenth of the first the pose comes back within about
/// 1e-11, at a hundredth within about 1e-7. Check the spread of the points when that matters.
///
/// ```
/// use nalgebra::Point3;
/// use slam_core::{fit_rigid_transform, pose3_from_xyz_rpy};
///
/// let to_t_from = pose3_from_xyz_rpy(1.0, -2.0, 0.5, 0.1, 0.2, -0.3);
/// let from = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]]
///     .map(Point3::from);
/// let to = from.map(|p| to_t_from * p);
/// let fit = fit_rigid_transform(&from, &to)?;
/// assert!((fit.to_homogeneous() - to_t_from.to_homogeneous()).amax() < 1e-12);
/// # Ok::<(), slam_core::RigidFitError>(())
/// ```
///
/// # Errors
/// [`RigidFitError::LengthMismatch`] for slices of different lengths,
/// [`RigidFitError::TooFewPairs`] for fewer than 3 pairs, [`RigidFitError::NonFinitePoint`] for a
/// NaN or infinite coordinate.
pub fn fit_rigid_transform(
    from: &[Point3<f64>],
    to: &[Point3<f64>],
) -> Result<Pose3, RigidFitError> {
    if from.len() != to.len() {
        return Err(RigidFitError::LengthMismatch {
            from: from.len(),
            to: to.len(),
        });
    }
    fit_weighted_rigid_transform(from.iter().zip(to).map(|(&from, &to)| WeightedPair {
        from,
        to,
        weight: 1.0,
    }))
}

/// The rigid transform `to_T_from` minimising `sum w_i |to_i - T from_i|^2` over `pairs`
/// (walked twice: once for the weighted centroids, once for the cross-covariance).
///
/// # Errors
/// [`RigidFitError::NonFinitePoint`] for a NaN or infinite coordinate,
/// [`RigidFitError::InvalidWeight`] for a negative or non-finite weight,
/// [`RigidFitError::TooFewPairs`] for fewer than 3 pairs of positive weight.
pub fn fit_weighted_rigid_transform<I>(pairs: I) -> Result<Pose3, RigidFitError>
where
    I: IntoIterator<Item = WeightedPair>,
    I::IntoIter: Clone,
{
    let pairs = pairs.into_iter();
    let (mut weight_sum, mut weighted, mut from_sum, mut to_sum) =
        (0.0, 0, Vector3::zeros(), Vector3::zeros());
    for (index, p) in pairs.clone().enumerate() {
        if !(p.from.iter().all(|v| v.is_finite()) && p.to.iter().all(|v| v.is_finite())) {
            return Err(RigidFitError::NonFinitePoint { index });
        }
        let w = p.weight;
        if !(w.is_finite() && w >= 0.0) {
            return Err(RigidFitError::InvalidWeight { index, weight: w });
        }
        weighted += usize::from(w > 0.0);
        weight_sum += w;
        from_sum += p.from.coords * w;
        to_sum += p.to.coords * w;
    }
    if weighted < MIN_PAIRS {
        return Err(RigidFitError::TooFewPairs {
            pairs: weighted,
            required: MIN_PAIRS,
        });
    }
    let (from_mean, to_mean) = (from_sum / weight_sum, to_sum / weight_sum);
    // Cross-covariance H = sum w (from - from_mean)(to - to_mean)^T = U S V^T; R = V D U^T.
    let mut h = Matrix3::zeros();
    for p in pairs {
        h += (p.from.coords - from_mean) * (p.to.coords - to_mean).transpose() * p.weight;
    }
    let svd = h.svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        unreachable!("an SVD asked for U and V^T has both")
    };
    // D = diag(1, 1, det(V U^T)): a reflection becomes the best proper rotation by flipping the
    // axis of the smallest singular value (nalgebra sorts them in decreasing order).
    let mut d = Matrix3::identity();
    d[(2, 2)] = (v_t.transpose() * u.transpose()).determinant().signum();
    let r = v_t.transpose() * d * u.transpose();
    let rotation = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
    Ok(Pose3::from_parts(
        (to_mean - rotation * from_mean).into(),
        rotation,
    ))
}
