//! Accuracy of an estimated trajectory against ground truth: the absolute trajectory error after
//! rigid alignment ([`absolute_trajectory_error`], as evo's `ape -a`), end-point and KITTI-style
//! segment drift, the loop end-point error, and all of them at once
//! ([`TrajectoryEvaluation`]).
//!
//! Uses `slam-core` only (poses, the stamped-pose type and the rigid fit).

mod ate;
mod drift;
mod evaluation;

pub use ate::{AteReport, DEFAULT_MAX_STAMP_DIFFERENCE, absolute_trajectory_error, associate};
pub use drift::{
    EndPointDrift, INDOOR_SEGMENT_LENGTHS, KITTI_SEGMENT_LENGTHS, SegmentDrift, end_point_drift,
    loop_end_point_error, path_length, segment_drift,
};
pub use evaluation::{TrajectoryEvaluation, body_trajectory};
