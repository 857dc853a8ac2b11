//! Relative errors: KITTI's RPE per 100 m (the devkit's segment error over 100 to 800 m, with
//! the ladder scaled down for paths shorter than 100 m), and the rotation error of every step
//! between consecutive poses (evo's `rpe -r angle_deg --delta 1 --delta_unit f`).

use slam_core::Pose3;

use crate::eval::EvalError;
use crate::eval::drift::{KITTI_SEGMENT_LENGTHS, check_lengths, kitti_segment_drift, path_length};

/// KITTI's relative pose error: the devkit's mean translation error over segment length.
#[derive(Clone, Debug, PartialEq)]
pub struct KittiRpe {
    /// Mean translation error over segment length, in percent (KITTI's "translation error";
    /// 1.0 is 1 m per 100 m).
    pub translation_percent: f64,
    /// Mean rotation error over segment length, degrees per 100 m.
    pub rotation_deg_per_100m: f64,
    /// The segment lengths evaluated (metres): those of the ladder of which one segment fits.
    pub lengths: Vec<f64>,
    /// The ladder's scale: 1 for KITTI's own 100 to 800 m; 0.1 (10 to 80 m), 0.01, ... when the
    /// path is no longer than 100 m (the largest power of ten whose 100 m step fits).
    pub scale: f64,
    /// Segments evaluated over all lengths.
    pub segments: usize,
}

impl KittiRpe {
    /// Whether these are KITTI's own segment lengths (the path is longer than 100 m).
    #[must_use]
    pub fn is_kitti_ladder(&self) -> bool {
        self.scale >= 1.0
    }
}

/// Largest divisor of the ladder tried: segments of 1 to 8 mm.
const MAX_DIVISOR: f64 = 1e5;

/// KITTI's RPE of `estimate` against `reference` (associated pose lists of equal length): the
/// devkit's [`kitti_segment_drift`] over [`KITTI_SEGMENT_LENGTHS`]; when the reference path is
/// no longer than 100 m, over the same ladder scaled by the largest power of ten (0.1, 0.01,
/// ...) whose first length the path exceeds. `None` when the lists differ in length, hold fewer
/// than 2 poses, or the path is too short for even 1 mm segments (a sensor that did not move).
#[must_use]
pub fn kitti_rpe(estimate: &[Pose3], reference: &[Pose3]) -> Option<KittiRpe> {
    let path = path_length(reference);
    // Lengths divided by an exact power of ten, so that 100 / 10 is 10 to the last bit.
    let mut divisor = 1.0;
    while KITTI_SEGMENT_LENGTHS[0] / divisor >= path {
        divisor *= 10.0;
        if divisor > MAX_DIVISOR {
            return None;
        }
    }
    let ladder: Vec<f64> = KITTI_SEGMENT_LENGTHS.iter().map(|l| l / divisor).collect();
    let drift = kitti_segment_drift(estimate, reference, &ladder).ok()?;
    Some(KittiRpe {
        translation_percent: 100.0 * drift.translation,
        rotation_deg_per_100m: 100.0 * drift.rotation.to_degrees(),
        lengths: drift.per_length.iter().map(|&(l, _, _)| l).collect(),
        scale: 1.0 / divisor,
        segments: drift.segments,
    })
}

/// The rotation error of every step between consecutive poses (radians): the angle of
/// `(est_i^-1 est_{i+1})^-1 (ref_i^-1 ref_{i+1})`, as evo's `rpe -r angle_deg --delta 1
/// --delta_unit f` (in radians). A step whose error passes a few degrees is one where the
/// tracker turned the wrong way: where it was lost.
///
/// # Errors
/// [`EvalError::TooFewPoses`] for lists of different lengths or shorter than 2.
pub fn step_rotation_errors(
    estimate: &[Pose3],
    reference: &[Pose3],
) -> Result<Vec<f64>, EvalError> {
    check_lengths(estimate, reference)?;
    Ok(estimate
        .windows(2)
        .zip(reference.windows(2))
        .map(|(e, r)| {
            let error = (e[0].inverse() * e[1]).inverse() * (r[0].inverse() * r[1]);
            error.rotation.angle()
        })
        .collect())
}
