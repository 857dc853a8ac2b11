//! Accuracy of an estimated trajectory against ground truth: the absolute trajectory error after
//! rigid alignment ([`absolute_trajectory_error`], as evo's `ape -a`), end-point, height and
//! segment drift, KITTI's RPE per 100 m ([`kitti_rpe`], the devkit's rule), each step's rotation
//! error ([`step_rotation_errors`], as evo's `rpe --delta 1`), the loop end-point error, and all
//! of them at once ([`TrajectoryEvaluation`]). `tests/data/evo` holds a trajectory pair with the
//! figures evo and the KITTI devkit computed for it, which the tests match.
//!
//! Uses `slam-core` only (poses, the stamped-pose type and the rigid fit).

mod ate;
mod drift;
mod error;
mod evaluation;
mod relative;

pub use ate::{AteReport, DEFAULT_MAX_STAMP_DIFFERENCE, absolute_trajectory_error, associate};
pub use drift::{
    EndPointDrift, INDOOR_SEGMENT_LENGTHS, KITTI_SEGMENT_LENGTHS, KITTI_STEP, SegmentDrift,
    end_point_drift, height_drift, kitti_segment_drift, loop_end_point_error, path_length,
    segment_drift,
};
pub use error::EvalError;
pub use evaluation::{TrajectoryEvaluation, body_trajectory};
pub use relative::{KittiRpe, kitti_rpe, step_rotation_errors};
