//! The error of the robot interface.

use thiserror::Error;

/// Why a command for a robot cannot be built. A bad motion limit is a
/// [`slam_core::InvalidSetting`], returned by [`MotionLimits::validate`](super::MotionLimits::validate).
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum RobotError {
    /// A trajectory command is malformed.
    #[error("trajectory point {point}: {problem}")]
    InvalidTrajectory {
        /// Index of the first bad point.
        point: usize,
        /// What is wrong.
        problem: &'static str,
    },
}
