//! Every accuracy figure of a run at once: ATE, end-point drift, segment drift and loop error of
//! an estimated trajectory against the ground truth, associated by stamp.

use slam_core::Pose3;
use slam_core::io::StampedPose;

use crate::ate::{AteReport, absolute_trajectory_error, associate};
use crate::drift::{
    EndPointDrift, SegmentDrift, end_point_drift, loop_end_point_error, segment_drift,
};
use crate::error::AdapterError;

/// Accuracy of an estimated trajectory against the ground truth.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct TrajectoryEvaluation {
    /// Absolute trajectory error after rigid alignment.
    pub ate: AteReport,
    /// End-point error over the path length.
    pub end_point: EndPointDrift,
    /// Segment drift over the given lengths, `None` when the path is shorter than all of them.
    pub segments: Option<SegmentDrift>,
    /// Distance between the estimate's first and last positions minus the reference's (metres,
    /// never negative): for a run that returns to its start, the loop end-point error.
    pub loop_end_point_error: f64,
}

impl TrajectoryEvaluation {
    /// Evaluate `estimate` against `reference`, associating poses whose stamps differ by at most
    /// `max_dt` seconds; segment drift uses `segment_lengths` (metres) from every 10th pose.
    ///
    /// Both trajectories must be of the same frame (e.g. both `world_T_body`); the ATE aligns
    /// their world frames, the drifts compare motion relative to each one's first pose.
    ///
    /// # Errors
    /// [`AdapterError::TooFewPoses`] when fewer than 3 poses can be associated.
    pub fn compute(
        estimate: &[StampedPose],
        reference: &[StampedPose],
        max_dt: f64,
        segment_lengths: &[f64],
    ) -> Result<Self, AdapterError> {
        let ate = absolute_trajectory_error(estimate, reference, max_dt)?;
        let pairs = associate(estimate, reference, max_dt);
        let est: Vec<Pose3> = pairs.iter().map(|&(i, _)| estimate[i].pose).collect();
        let gt: Vec<Pose3> = pairs.iter().map(|&(_, j)| reference[j].pose).collect();
        let end_point = end_point_drift(&est, &gt)?;
        let segments = segment_drift(&est, &gt, segment_lengths, 10).ok();
        let loop_end_point_error =
            (loop_end_point_error(&est) - loop_end_point_error(&gt)).max(0.0);
        Ok(Self {
            ate,
            end_point,
            segments,
            loop_end_point_error,
        })
    }
}
