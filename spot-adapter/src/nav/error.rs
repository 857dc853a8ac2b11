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
    /// An odometry pose given to the navigator is not finite.
    #[error("the odometry pose given to the navigator is not finite")]
    NonFiniteOdometry,
    /// The navigator's occupancy grid could not be built from the map.
    #[error("the navigation grid cannot be built from the map")]
    NavigationGrid(#[source] gridmap::GridMapError),
    /// The navigator's map cannot be prepared for registration.
    #[error("the map cannot be prepared for localisation")]
    LocalisationMap(#[source] slam_core::RegistrationError),
    /// The planner failed: it refused its arguments, or failed for a reason of its own
    /// ([`PlanError::Backend`](slam_core::PlanError::Backend), e.g. the cost-aware planner
    /// refusing the planning grid's step costs).
    #[error("the planner failed")]
    Planner(#[source] slam_core::PlanError),
    /// The planner's path cannot be walked: a cell blocked or off the grid, a step between cells
    /// that are not neighbours, or a diagonal step cutting a blocked corner (a plugged-in
    /// planner's fault; ours never return one).
    #[error("the planner's path cannot be walked: {violation:?}")]
    InvalidPath {
        /// The first fault found along the path (every cell listed).
        violation: pathfind::movement::PathViolation,
    },
    /// The planner's path does not run from the start to the goal it was given.
    #[error(
        "the planner's path runs from ({}, {}) to ({}, {}), not from ({}, {}) to ({}, {})",
        first.x, first.y, last.x, last.y, start.x, start.y, goal.x, goal.y
    )]
    PathEndpoints {
        /// The start given.
        start: slam_core::Cell,
        /// The goal given.
        goal: slam_core::Cell,
        /// The path's first cell.
        first: slam_core::Cell,
        /// The path's last cell.
        last: slam_core::Cell,
    },
    /// A floor number beyond the floors given.
    #[error("{what} is on floor {floor}, but there are {floors} floors (0 to {floors} - 1)")]
    NoSuchFloor {
        /// What was on it (`the goal`, `a stairs link's top`, ...).
        what: &'static str,
        /// The floor given.
        floor: usize,
        /// How many floors there are.
        floors: usize,
    },
    /// A cell off its floor's grid.
    #[error("{what} ({}, {}) is off floor {floor}'s grid", cell.x, cell.y)]
    OffFloorGrid {
        /// What it is (`the start`, `a stairs link's foot`, ...).
        what: &'static str,
        /// The floor.
        floor: usize,
        /// The cell given.
        cell: slam_core::Cell,
    },
    /// A point off its floor's map.
    #[error("{what} ({x}, {y}) is off floor {floor}'s map")]
    OffFloorMap {
        /// What it is (`the start`, `the goal`).
        what: &'static str,
        /// The floor.
        floor: usize,
        /// Its x (metres, the map frame).
        x: f64,
        /// Its y.
        y: f64,
    },
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

/// Why [`explore`](super::explore) stopped early; the robot was sent a stop first.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ExplorationError<E: std::error::Error + 'static> {
    /// The robot failed to deliver a sample or take a command.
    #[error("the robot failed")]
    Robot(#[source] E),
    /// Invalid settings, or the navigator or its map failed.
    #[error("navigation failed")]
    Navigation(#[source] NavError),
    /// The engine's map cloud could not be made for the navigator to localise against (or a
    /// keyframe's scan could not be read back from the engine's keyframe store).
    #[error("the map cloud cannot be made")]
    Map(#[source] slam_core::KeyframeCloudError),
    /// The engine kept none of the first `cycles` scans (every one skipped): there is no map
    /// to explore from.
    #[error("the engine kept none of the first {cycles} scans: no map to explore from")]
    NoMap {
        /// Scans taken.
        cycles: usize,
    },
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
