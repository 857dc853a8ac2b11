//! Navigation on a map: the [`Navigator`] (localise each scan against the map, plan on its
//! occupancy grid, turn the path into a velocity command) and [`drive`], the loop that runs it
//! on any [`Robot`](crate::robot::Robot); and exploration of an unknown building with no map:
//! [`explore`] runs the Graph-SLAM engine live and walks the navigator to the frontiers an
//! [`Explorer`] picks.
//!
//! Uses `robot` (samples, commands, limits), `gridmap`, `pathfind` and `slam-core`, never the
//! simulator: the same code drives a simulated Spot and a real one.

mod config;
mod controller;
mod detour;
mod drive;
mod error;
mod exploration;
mod explorer;
mod explorer_config;
mod floor_levelling;
mod frontier;
mod frontier_tour;
mod localiser;
mod navigation_map;
mod navigator;
mod path;
mod planner;
mod step;
mod stuck;
mod travel_costs;
mod unseen;

pub use config::{NavigationMapConfig, NavigatorConfig, PlannerKind};
pub use drive::{DriveCycle, DriveOutcome, DriveReport, drive};
pub use error::{DriveError, ExplorationError, NavError};
pub use exploration::{ExplorationCycle, ExplorationOutcome, ExplorationReport, explore};
pub use explorer::{Explorer, FrontierDecision, FrontierGoal, GiveUpReason, GivenUpFrontier};
pub use explorer_config::{ExplorerConfig, FrontierChoice};
pub use frontier::{Frontier, find_frontiers, is_frontier_cell};
pub use localiser::{LocalisationHealth, LocalisationStatus, LocaliserConfig};
pub use navigation_map::NavigationMap;
pub use navigator::Navigator;
pub use planner::{NavPlanner, PlannerMemory};
pub use step::{Goal, NavigationStep};
pub use stuck::StuckConfig;
pub use travel_costs::TravelCosts;
