//! Navigation on a map: the [`Navigator`] (localise each scan against the map, plan on its
//! occupancy grid, turn the path into a velocity command) and [`drive`], the loop that runs it
//! on any [`Robot`](crate::robot::Robot); and exploration of an unknown building with no map:
//! [`explore`] runs the Graph-SLAM engine live and walks the navigator to the frontiers an
//! [`Explorer`] picks.
//!
//! Uses `robot` (samples, commands, limits), `gridmap`, `pathfind` and `slam-core`, never the
//! simulator: the same code drives a simulated Spot and a real one.
//!
//! A simulated Spot walked 4 m down a corridor it has a map of (here built from the first
//! scans of a lap at their true poses, so that the map frame is the world's):
//!
//! ```
//! use spot_adapter::nav::{DriveOutcome, NavigationMap, Navigator, NavigatorConfig, drive};
//! use spot_adapter::pipelines::point_to_plane_localiser;
//! use spot_adapter::robot::Robot;
//! use spot_adapter::sim::{CommandedSpot, SimulatedSpot, SimulationConfig};
//! use spot_adapter::slam_core::{PointCloud, Pose3};
//!
//! let config = SimulationConfig::with_seed(3);
//! let lap = SimulatedSpot::corridor_loop(&config)?;
//! let building = lap.building().clone();
//! let truth = lap.ground_truth(); // world_T_body per scan
//! // Scans in the LiDAR frame, placed by world_T_lidar = world_T_body * body_T_lidar.
//! let posed: Vec<(Pose3, PointCloud)> = lap
//!     .take(40)
//!     .zip(&truth)
//!     .map(|(sample, t)| (t.pose * sample.body_t_lidar, sample.cloud))
//!     .collect();
//! let scans: Vec<(Pose3, &PointCloud)> = posed.iter().map(|(p, c)| (*p, c)).collect();
//! let mut map = PointCloud::default();
//! for (pose, cloud) in &scans {
//!     map.extend_from(&cloud.transformed(pose))?;
//! }
//! let lidar_height = config.spot.body_height + config.spot.body_t_lidar.translation.z;
//! let nav_config = NavigatorConfig::default();
//! let navigation = NavigationMap::from_scans(&scans, lidar_height, &nav_config.map_config())?;
//!
//! // Spot stands where the lap started and walks to a point 4 m further along it.
//! let start = truth[0].pose;
//! let goal = truth[0].pose.translation.vector.xy() + (truth[39].pose.translation.vector.xy()
//!     - truth[0].pose.translation.vector.xy()).normalize() * 4.0;
//! let yaw = start.rotation.euler_angles().2;
//! let mut spot = CommandedSpot::new(building, start.translation.vector.xy(), yaw, &config)?;
//! let mut navigator = Navigator::new(
//!     point_to_plane_localiser(),
//!     &map,
//!     &navigation,
//!     start,
//!     spot.description(),
//!     nav_config,
//! )?;
//! let walk = drive(&mut spot, &mut navigator, goal, 300, |_| {})?;
//! assert_eq!(walk.outcome, DriveOutcome::Arrived);
//! assert!((spot.position() - goal).norm() < 0.1, "the true body ends within 10 cm");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod config;
mod controller;
mod detour;
mod drive;
mod error;
mod exploration;
mod explorer;
mod explorer_config;
mod floor_levelling;
mod floor_maps;
mod floor_route;
mod floors_drive;
mod frontier;
mod frontier_tour;
mod growing_map;
mod keyframe_batches;
mod localiser;
mod navigation_map;
mod navigator;
mod path;
mod planner;
mod scan_blocks;
mod stairs_climb;
mod stairs_links;
mod step;
mod stuck;
#[cfg(test)]
mod test_lcg;
mod travel_costs;
mod unseen;

pub use config::{NavigationMapConfig, NavigatorConfig, PlannerKind};
pub use drive::{DriveCycle, DriveOutcome, DriveReport, drive};
pub use error::{DriveError, ExplorationError, NavError};
pub use exploration::{
    DecisionStages, ExplorationCycle, ExplorationOutcome, ExplorationReport, explore,
};
pub use explorer::{Explorer, FrontierDecision, FrontierGoal, GiveUpReason, GivenUpFrontier};
pub use explorer_config::{ExplorerConfig, FrontierChoice};
pub use floor_maps::{Flight, FloorMaps};
pub use floor_route::{FloorCell, FloorGraph, FloorRoute, RouteLeg, StairsLink};
pub use floors_drive::{FloorPoint, FloorsDriveReport, drive_across_floors};
pub use frontier::{Frontier, find_frontiers, is_frontier_cell};
pub use localiser::{LocalisationHealth, LocalisationStatus, LocaliserConfig};
pub use navigation_map::NavigationMap;
pub use navigator::Navigator;
pub use planner::{NavPlanner, PlannerMemory};
pub use stairs_climb::{ClimbStep, StairsClimb, StairsClimbConfig};
pub use stairs_links::{SAME_FLIGHT, stairs_links};
pub use step::{Goal, NavigationStep};
pub use stuck::StuckConfig;
pub use travel_costs::TravelCosts;
