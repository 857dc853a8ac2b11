//! Every accuracy figure of a run at once: ATE, end-point and height drift, segment drift,
//! KITTI's RPE, each step's rotation error and the loop error of an estimated trajectory against
//! the ground truth, associated by stamp.

use slam_core::Pose3;
use slam_core::io::StampedPose;

use crate::eval::EvalError;
use crate::eval::ate::{
    AteReport, DEFAULT_MAX_STAMP_DIFFERENCE, absolute_trajectory_error, associate,
};
use crate::eval::drift::{
    EndPointDrift, INDOOR_SEGMENT_LENGTHS, SegmentDrift, end_point_drift, height_drift,
    loop_end_point_error, segment_drift,
};
use crate::eval::relative::{KittiRpe, kitti_rpe, step_rotation_errors};

/// A trajectory of LiDAR poses (`map_T_lidar` per stamp) as body poses (`map_T_body`).
#[must_use]
pub fn body_trajectory(
    lidar_trajectory: Vec<StampedPose>,
    body_t_lidar: &Pose3,
) -> Vec<StampedPose> {
    let lidar_t_body = body_t_lidar.inverse();
    lidar_trajectory
        .into_iter()
        .map(|s| StampedPose {
            stamp: s.stamp,
            pose: s.pose * lidar_t_body,
        })
        .collect()
}

/// Accuracy of an estimated trajectory against the ground truth.
#[derive(Clone, Debug, PartialEq)]
pub struct TrajectoryEvaluation {
    /// Absolute trajectory error after rigid alignment.
    pub ate: AteReport,
    /// End-point error over the path length.
    pub end_point: EndPointDrift,
    /// Segment drift over the given lengths, `None` when the path is shorter than all of them.
    pub segments: Option<SegmentDrift>,
    /// KITTI's RPE per 100 m ([`kitti_rpe`]: 100 to 800 m segments, or the ladder scaled down
    /// for a shorter path), `None` when the reference did not move.
    pub rpe: Option<KittiRpe>,
    /// How much higher the estimate ends than the truth with their first poses aligned
    /// ([`height_drift`](crate::eval::height_drift), metres, signed).
    pub height_drift: f64,
    /// The rotation error of each step between consecutive associated poses (radians,
    /// [`step_rotation_errors`]).
    pub step_rotation_errors: Vec<f64>,
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
    /// [`EvalError::TooFewPoses`] when fewer than 3 poses can be associated.
    pub fn compute(
        estimate: &[StampedPose],
        reference: &[StampedPose],
        max_dt: f64,
        segment_lengths: &[f64],
    ) -> Result<Self, EvalError> {
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
            rpe: kitti_rpe(&est, &gt),
            height_drift: height_drift(&est, &gt)?,
            step_rotation_errors: step_rotation_errors(&est, &gt)?,
            loop_end_point_error,
        })
    }

    /// Steps whose rotation error is larger than `degrees`.
    #[must_use]
    pub fn steps_over(&self, degrees: f64) -> usize {
        let limit = degrees.to_radians();
        self.step_rotation_errors
            .iter()
            .filter(|&&e| e > limit)
            .count()
    }

    /// The largest step rotation error (degrees; 0 without steps).
    #[must_use]
    pub fn max_step_rotation_error_deg(&self) -> f64 {
        self.step_rotation_errors
            .iter()
            .copied()
            .fold(0.0, f64::max)
            .to_degrees()
    }

    /// Evaluate a SLAM run's trajectory of LiDAR poses (`map_T_lidar` per stamp, as
    /// `GraphSlam::scan_trajectory` gives it) as body poses against the ground truth
    /// (`world_T_body`), with [`DEFAULT_MAX_STAMP_DIFFERENCE`] and [`INDOOR_SEGMENT_LENGTHS`].
    /// Returns the body trajectory too, for writing out.
    ///
    /// # Errors
    /// As [`TrajectoryEvaluation::compute`].
    pub fn of_lidar_trajectory(
        lidar_trajectory: Vec<StampedPose>,
        body_t_lidar: &Pose3,
        truth: &[StampedPose],
    ) -> Result<(Self, Vec<StampedPose>), EvalError> {
        let estimate = body_trajectory(lidar_trajectory, body_t_lidar);
        let e = Self::compute(
            &estimate,
            truth,
            DEFAULT_MAX_STAMP_DIFFERENCE,
            &INDOOR_SEGMENT_LENGTHS,
        )?;
        Ok((e, estimate))
    }
}
