//! The error of the simulator.

use slam_core::InvalidSetting;
use thiserror::Error;

use crate::record::RecordError;

/// Why a simulated building, route, LiDAR or Spot cannot be built or run.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum SimError {
    /// A setting is out of its valid range.
    #[error(transparent)]
    InvalidConfig(#[from] InvalidSetting),
    /// A command names a frame this robot does not have.
    #[error("this robot has no frame {frame:?}")]
    UnsupportedFrame {
        /// The frame's name.
        frame: &'static str,
    },
    /// A route's start or goal lies inside an obstacle or outside the building.
    #[error("{which} ({x:.2}, {y:.2}) m is not free floor")]
    BlockedEndpoint {
        /// "start" or "goal".
        which: &'static str,
        /// World x (metres).
        x: f64,
        /// World y (metres).
        y: f64,
    },
    /// No collision-free route joins the two points.
    #[error("no route from the start to the goal")]
    NoRoute,
    /// A box to add to a building is not a finite, non-empty box.
    #[error("a box needs finite corners with min below max on every axis")]
    InvalidBox,
    /// No room of the generated layout is deep and wide enough for the staircases a
    /// building of several floors needs.
    #[error(
        "{floors} floors need {needed} rooms deep enough for a staircase; the layout has {found}"
    )]
    NoRoomForStairs {
        /// Floors asked for.
        floors: usize,
        /// Staircases needed (one per floor above the ground floor).
        needed: usize,
        /// Core rooms deep and wide enough.
        found: usize,
    },
    /// A grid could not be built.
    #[error(transparent)]
    Grid(#[from] slam_core::GridError),
    /// The occupancy grid a route is planned on could not be built.
    #[error("the navigation grid cannot be built from the map")]
    NavigationGrid(#[source] gridmap::GridMapError),
    /// A planner refused its arguments (a start or goal off the grid or blocked).
    #[error("the planner refused its arguments")]
    Planner(#[source] slam_core::PlanError),
    /// A run cannot be written as a recording or a folder of scans (a stamp out of order,
    /// ground truth for only some samples, a file the system refuses).
    #[error(transparent)]
    Record(#[from] RecordError),
}

impl SimError {
    /// A [`SimError::InvalidConfig`] for `setting` = `value`.
    pub(crate) fn invalid(setting: &'static str, value: f64, expected: &'static str) -> Self {
        Self::InvalidConfig(InvalidSetting {
            setting,
            value,
            expected,
        })
    }
}
