//! The error of spot-adapter as a whole: each room has its own error, and [`AdapterError`]
//! takes any of them, for callers that use several rooms with `?`.

use slam_core::InvalidSetting;
use thiserror::Error;

use crate::eval::EvalError;
use crate::nav::NavError;
#[cfg(feature = "record")]
use crate::record::RecordError;
use crate::robot::RobotError;
#[cfg(feature = "sim")]
use crate::sim::SimError;

/// An error of any room of spot-adapter; its message is the room error's.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum AdapterError {
    /// A setting is out of its valid range (a robot's motion limits).
    #[error(transparent)]
    InvalidConfig(#[from] InvalidSetting),
    /// From the robot interface.
    #[error(transparent)]
    Robot(#[from] RobotError),
    /// From the simulator.
    #[cfg(feature = "sim")]
    #[error(transparent)]
    Sim(#[from] SimError),
    /// From a recording's reader or writer.
    #[cfg(feature = "record")]
    #[error(transparent)]
    Record(#[from] RecordError),
    /// From the evaluation against ground truth.
    #[error(transparent)]
    Eval(#[from] EvalError),
    /// From the navigator.
    #[error(transparent)]
    Nav(#[from] NavError),
}

impl AdapterError {
    /// The bad setting, whichever room refused it; `None` for any other error.
    #[must_use]
    pub fn invalid_setting(&self) -> Option<&InvalidSetting> {
        match self {
            Self::InvalidConfig(s) | Self::Nav(NavError::InvalidConfig(s)) => Some(s),
            #[cfg(feature = "sim")]
            Self::Sim(SimError::InvalidConfig(s)) => Some(s),
            _ => None,
        }
    }
}
