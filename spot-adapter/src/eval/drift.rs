//! Relative drift: the end-point error over the path length, the height drift, segment drift and
//! the KITTI devkit's own (Geiger et al., "Are we ready for autonomous driving?", CVPR 2012,
//! devkit `evaluate_odometry`), and the loop end-point error. Inputs are associated pose lists of equal length (estimate[i] and
//! reference[i] at the same instant), e.g. from [`associate`](crate::eval::associate).

use slam_core::Pose3;

use crate::eval::EvalError;

/// KITTI's segment lengths (metres), for outdoor runs of kilometres.
pub const KITTI_SEGMENT_LENGTHS: [f64; 8] =
    [100.0, 200.0, 300.0, 400.0, 500.0, 600.0, 700.0, 800.0];

/// Segment lengths for indoor loops of 100 to 150 m (metres): KITTI's are longer than the loops.
pub const INDOOR_SEGMENT_LENGTHS: [f64; 5] = [10.0, 20.0, 30.0, 40.0, 50.0];

/// Length of the path through the positions of `poses` (metres).
#[must_use]
pub fn path_length(poses: &[Pose3]) -> f64 {
    poses
        .windows(2)
        .map(|w| (w[1].translation.vector - w[0].translation.vector).norm())
        .sum()
}

/// Associated lists must be of equal length, at least 2.
pub(crate) fn check_lengths(estimate: &[Pose3], reference: &[Pose3]) -> Result<(), EvalError> {
    if estimate.len() != reference.len() || estimate.len() < 2 {
        return Err(EvalError::TooFewPoses {
            found: estimate.len().min(reference.len()),
            required: 2,
        });
    }
    Ok(())
}

/// End-point error and relative drift of a whole run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EndPointDrift {
    /// Distance between where the estimate and the reference end, each taken relative to its
    /// own first pose (metres).
    pub end_point_error: f64,
    /// Length of the reference path (metres).
    pub path_length: f64,
    /// `end_point_error / path_length` (a fraction: 0.019 is 1.9 %).
    pub relative_drift: f64,
}

/// End-point error over path length: both trajectories are expressed relative to their first
/// pose, and their last positions compared.
///
/// # Errors
/// [`EvalError::TooFewPoses`] for lists of different lengths or shorter than 2.
pub fn end_point_drift(
    estimate: &[Pose3],
    reference: &[Pose3],
) -> Result<EndPointDrift, EvalError> {
    check_lengths(estimate, reference)?;
    let n = estimate.len() - 1;
    let e = estimate[0].inverse() * estimate[n];
    let r = reference[0].inverse() * reference[n];
    let end_point_error = (e.translation.vector - r.translation.vector).norm();
    let path_length = path_length(reference);
    Ok(EndPointDrift {
        end_point_error,
        path_length,
        relative_drift: if path_length > 0.0 {
            end_point_error / path_length
        } else {
            0.0
        },
    })
}

/// For a run that returns to its start: the distance between the estimate's first and last
/// positions (metres). Zero for a perfect estimate.
#[must_use]
pub fn loop_end_point_error(estimate: &[Pose3]) -> f64 {
    match (estimate.first(), estimate.last()) {
        (Some(a), Some(b)) => (b.translation.vector - a.translation.vector).norm(),
        _ => 0.0,
    }
}

/// KITTI-style segment drift, averaged over every segment evaluated.
#[derive(Clone, Debug, PartialEq)]
pub struct SegmentDrift {
    /// Mean translation error over segment length (a fraction: 0.01 is 1 %).
    pub translation: f64,
    /// Mean rotation error over segment length (radians per metre).
    pub rotation: f64,
    /// Segments evaluated.
    pub segments: usize,
    /// Per segment length: (length, mean translation fraction, segments).
    pub per_length: Vec<(f64, f64, usize)>,
}

/// Segment drift: from every `step`-th pose, for each length `L` in `lengths`, the first pose
/// at least `L` metres further along the reference path ends a segment; the segment's error is
/// `(est_i^-1 est_j)^-1 (ref_i^-1 ref_j)`, its translation and rotation divided by `L`. Lengths
/// no segment reaches are left out. [`kitti_segment_drift`] is the KITTI devkit's exact rule.
///
/// # Errors
/// [`EvalError::TooFewPoses`] for lists of different lengths or shorter than 2, or when no
/// segment of any length fits.
pub fn segment_drift(
    estimate: &[Pose3],
    reference: &[Pose3],
    lengths: &[f64],
    step: usize,
) -> Result<SegmentDrift, EvalError> {
    segments(estimate, reference, lengths, step, |d, end| d >= end)
}

/// The KITTI odometry devkit's segment drift (`evaluate_odometry.cpp`, `calcSequenceErrors`):
/// segments from every 10th pose, each ending at the first pose *more* than its length further
/// along the reference path, the mean over every segment of every length (not a mean of the
/// lengths' means). With [`KITTI_SEGMENT_LENGTHS`] its `translation` times 100 is KITTI's
/// "translation error" in %.
///
/// # Errors
/// As [`segment_drift`].
pub fn kitti_segment_drift(
    estimate: &[Pose3],
    reference: &[Pose3],
    lengths: &[f64],
) -> Result<SegmentDrift, EvalError> {
    segments(estimate, reference, lengths, KITTI_STEP, |d, end| d > end)
}

/// Poses between the starts of two KITTI segments (the devkit's `step_size`: 1 s at 10 Hz).
pub const KITTI_STEP: usize = 10;

/// [`segment_drift`] with the rule `ends(distance, start + length)` for a segment's last pose.
fn segments(
    estimate: &[Pose3],
    reference: &[Pose3],
    lengths: &[f64],
    step: usize,
    ends: impl Fn(f64, f64) -> bool,
) -> Result<SegmentDrift, EvalError> {
    check_lengths(estimate, reference)?;
    let mut dist = vec![0.0];
    for w in reference.windows(2) {
        dist.push(
            dist[dist.len() - 1] + (w[1].translation.vector - w[0].translation.vector).norm(),
        );
    }
    let (mut t_sum, mut r_sum, mut count) = (0.0, 0.0, 0usize);
    let mut per_length = Vec::new();
    for &len in lengths {
        let (mut lt, mut ln) = (0.0, 0usize);
        for i in (0..reference.len()).step_by(step.max(1)) {
            let Some(j) = (i..reference.len()).find(|&j| ends(dist[j], dist[i] + len)) else {
                break;
            };
            let e = estimate[i].inverse() * estimate[j];
            let r = reference[i].inverse() * reference[j];
            let err = e.inverse() * r;
            let t = err.translation.vector.norm() / len;
            t_sum += t;
            r_sum += err.rotation.angle() / len;
            lt += t;
            ln += 1;
        }
        if ln > 0 {
            per_length.push((len, lt / ln as f64, ln));
            count += ln;
        }
    }
    if count == 0 {
        return Err(EvalError::TooFewPoses {
            found: reference.len(),
            required: 2,
        });
    }
    Ok(SegmentDrift {
        translation: t_sum / count as f64,
        rotation: r_sum / count as f64,
        segments: count,
        per_length,
    })
}

/// How much higher the estimate ends than the truth once their first poses are aligned: the
/// estimate moved rigidly so that its first pose is the reference's first pose (`ref_0 est_0^-1
/// est_i`), then the z of its last position minus the z of the reference's last position, in
/// the reference's world frame (metres; positive when the estimate ends higher). Both start at
/// the same point, so this is the estimate's climb from start to end minus the truth's. It
/// needs a reference whose z is up (REP-103).
///
/// # Errors
/// [`EvalError::TooFewPoses`] for lists of different lengths or shorter than 2.
pub fn height_drift(estimate: &[Pose3], reference: &[Pose3]) -> Result<f64, EvalError> {
    check_lengths(estimate, reference)?;
    let n = estimate.len() - 1;
    let end = reference[0] * estimate[0].inverse() * estimate[n];
    Ok(end.translation.z - reference[n].translation.z)
}
