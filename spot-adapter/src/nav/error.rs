//! The errors of the navigator and of the driving loop.

use slam_core::InvalidSetting;
use thiserror::Error;

/// Why the navigator cannot be built or cannot take a step.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum NavError {
    /// A setting is out of its valid range.
    #[error(transparent)]
    InvalidConfig(#[from] InvalidSetting),
    /// A goal is not a finite point.
    #[error("goal ({x}, {y}) is not a finite point")]
    NonFiniteGoal {
        /// Goal x (metres).
        x: f64,
        /// Goal y (metres).
        y: f64,
    },
    /// The navigator's occupancy grid could not be built from the map.
    #[error("the navigation grid cannot be built from the map")]
    NavigationGrid(#[source] gridmap::GridMapError),
    /// The navigator's map cannot be prepared for registration.
    #[error("the map cannot be prepared for localisation")]
    LocalisationMap(#[source] slam_core::RegistrationError),
    /// A planner refused its arguments (a start or goal off the grid or blocked).
    #[error("the planner refused its arguments")]
    Planner(#[source] slam_core::PlanError),
    /// The cost-aware planner refused the planning grid's per-cell step costs (a count that is
    /// not one per cell, a multiplier below 1 or not finite, or costs too large).
    #[error("the planner refused the planning grid's step costs")]
    PlanningCosts(#[source] pathfind::PathfindError),
}

/// Why [`drive`](super::drive) stopped early; the robot was sent a stop first.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum DriveError<E: std::error::Error + 'static> {
    /// The robot failed to deliver a sample or take a command.
    #[error("the robot failed")]
    Robot(#[source] E),
    /// The navigator failed.
    #[error("the navigator failed")]
    Navigation(#[source] NavError),
}

impl NavError {
    /// A [`NavError::InvalidConfig`] for `setting` = `value`.
    pub(crate) fn invalid(setting: &'static str, value: f64, expected: &'static str) -> Self {
        Self::InvalidConfig(InvalidSetting {
            setting,
            value,
            expected,
        })
    }
}
