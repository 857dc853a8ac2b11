//! Navigation on a map: the [`Navigator`] (localise each scan against the map, plan on its
//! occupancy grid, turn the path into a velocity command) and [`drive`], the loop that runs it
//! on any [`Robot`](crate::robot::Robot).
//!
//! Uses `robot` (samples, commands, limits), `gridmap`, `pathfind` and `slam-core`, never the
//! simulator: the same code drives a simulated Spot and a real one.

mod config;
mod controller;
mod detour;
mod drive;
mod error;
mod floor_levelling;
mod localiser;
mod navigation_map;
mod navigator;
mod path;
mod planner;
mod step;
mod stuck;
mod unseen;

pub use config::{NavigationMapConfig, NavigatorConfig, PlannerKind};
pub use drive::{DriveCycle, DriveOutcome, DriveReport, drive};
pub use error::{DriveError, NavError};
pub use localiser::{LocalisationHealth, LocalisationStatus, LocaliserConfig};
pub use navigation_map::NavigationMap;
pub use navigator::Navigator;
pub use planner::{NavPlanner, PlannerMemory};
pub use step::{Goal, NavigationStep};
pub use stuck::StuckConfig;
