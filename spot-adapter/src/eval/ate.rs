//! Absolute trajectory error after rigid alignment, as evo's `ape -a` computes it for the
//! translation part: associate poses by stamp, align the estimate onto the reference with
//! [`slam_core::fit_rigid_transform`], and report statistics of the remaining position errors.

use nalgebra::Point3;
use slam_core::io::StampedPose;
use slam_core::{Pose3, RigidFitError, fit_rigid_transform};

use crate::eval::EvalError;

/// Largest stamp difference (seconds) for two poses to be associated, 0.01 s (evo's default).
pub const DEFAULT_MAX_STAMP_DIFFERENCE: f64 = 0.01;

/// Absolute trajectory error statistics (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AteReport {
    /// Root mean square of the position errors.
    pub rmse: f64,
    /// Mean position error.
    pub mean: f64,
    /// Median position error.
    pub median: f64,
    /// Largest position error.
    pub max: f64,
    /// Poses associated and compared.
    pub pairs: usize,
    /// The alignment applied to the estimate: `reference ≈ alignment * estimate`.
    pub alignment: Pose3,
}

/// Pairs of (estimate, reference) indices whose stamps differ by at most `max_dt`, each
/// reference pose used once, in order (the nearest reference stamp for each estimate stamp).
#[must_use]
pub fn associate(
    estimate: &[StampedPose],
    reference: &[StampedPose],
    max_dt: f64,
) -> Vec<(usize, usize)> {
    let mut pairs = Vec::new();
    let mut j = 0;
    let mut last_used = None;
    for (i, e) in estimate.iter().enumerate() {
        while j + 1 < reference.len()
            && (reference[j + 1].stamp - e.stamp).abs() <= (reference[j].stamp - e.stamp).abs()
        {
            j += 1;
        }
        if reference
            .get(j)
            .is_some_and(|r| (r.stamp - e.stamp).abs() <= max_dt)
            && last_used != Some(j)
        {
            pairs.push((i, j));
            last_used = Some(j);
        }
    }
    pairs
}

/// The absolute trajectory error of `estimate` against `reference` after the best rigid
/// alignment (translation errors; stamps associated within `max_dt` seconds).
///
/// # Errors
/// [`EvalError::TooFewPoses`] when fewer than 3 poses can be associated,
/// [`EvalError::Alignment`] when a pose is not finite.
pub fn absolute_trajectory_error(
    estimate: &[StampedPose],
    reference: &[StampedPose],
    max_dt: f64,
) -> Result<AteReport, EvalError> {
    let pairs = associate(estimate, reference, max_dt);
    let est: Vec<Point3<f64>> = pairs
        .iter()
        .map(|&(i, _)| Point3::from(estimate[i].pose.translation.vector))
        .collect();
    let refs: Vec<Point3<f64>> = pairs
        .iter()
        .map(|&(_, j)| Point3::from(reference[j].pose.translation.vector))
        .collect();
    let alignment = fit_rigid_transform(&est, &refs).map_err(|e| match e {
        RigidFitError::TooFewPairs { pairs, required } => EvalError::TooFewPoses {
            found: pairs,
            required,
        },
        other => EvalError::Alignment(other),
    })?;
    let mut errors: Vec<f64> = est
        .iter()
        .zip(&refs)
        .map(|(e, r)| (alignment * e - r).norm())
        .collect();
    let n = errors.len() as f64;
    let rmse = (errors.iter().map(|e| e * e).sum::<f64>() / n).sqrt();
    let mean = errors.iter().sum::<f64>() / n;
    let max = errors.iter().copied().fold(0.0, f64::max);
    errors.sort_by(f64::total_cmp);
    let m = errors.len();
    let median = if m % 2 == 1 {
        errors[m / 2]
    } else {
        0.5 * (errors[m / 2 - 1] + errors[m / 2])
    };
    Ok(AteReport {
        rmse,
        mean,
        median,
        max,
        pairs: m,
        alignment,
    })
}
