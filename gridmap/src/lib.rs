//! # gridmap
//!
//! From a map cloud to the 2D grid a planner searches, and to files people and ROS tools read.
//!
//! - [`OccupancyGridBuilder`]: the slice of the map from 0.2 m below to 0.2 m above the LiDAR
//!   height, binned straight into cells (O(N); the thesis ran a k-d tree query per cell), with a
//!   `min_points` noise filter; or, from scans with their poses, ray casting that tells free from
//!   unknown ([`OccupancyGrid`] is tri-state).
//! - Obstacles from the floor up: [`FloorMap::estimate`] finds the floor per tile of about 1 m,
//!   growing from floor hints under the robot's poses ([`floor_hints_below`]) and taking the
//!   lowest dense band of points near the neighbours' floor; then
//!   [`OccupancyGridBuilder::build_floor_band`] (a map cloud) or
//!   [`OccupancyGridBuilder::build_floor_band_from_scans`] (scans, with free space from their
//!   beams and never-observed cells unknown) keep the obstacles between
//!   [`ObstacleBandConfig::above_floor`] (0.08 m) and [`ObstacleBandConfig::up_to`] (0.94 m,
//!   Spot's height plus 0.10 m) above the floor: a 0.5 m crate and a 0.72 m desk are obstacles,
//!   door lintels and the ceiling are not.
//! - [`squared_distance_cells`], [`DistanceField`]: the exact Euclidean distance transform
//!   (Felzenszwalb & Huttenlocher), linear in cells; [`inflate`] uses it for an exact disc of the
//!   robot's radius whatever the radius.
//! - [`PlanningGrid`]: what a planner searches. Unknown cells blocked by default, a hard
//!   inflation by Spot's half width plus a margin (0.30 m) only, and a clearance cost per cell
//!   from the distance field ([`ClearanceCostConfig`]: entering a cell costs its length times
//!   `1 + w p(d)`, the penalty `p` falling from 1 at 0.30 m to 0 at 1 m), the thesis' future work
//!   f = g + h + o with the octile heuristic still admissible; pathfind's `CellCostAStar` is the
//!   planner that is optimal for it. [`PlanningGrid::refresh`] updates a changed rectangle at a
//!   cost bounded by the rectangle. [`clearance_step_costs`] gives the same multipliers for any
//!   distance field.
//! - [`LiveLayer`]: each scan's obstacle band as a robot-centred 8 m x 8 m window (the shape of
//!   Spot's own local grids) with free cells from its beams, fused over the static map; changes
//!   not observed for 5 s decay back to the map. Per update the work is bounded by the scan and
//!   the window, not the map.
//! - [`fuse_local_grid`]: merge a robot-centred local grid (Spot's `no_step` or
//!   `obstacle_distance` grids) into the global grid, adding obstacles and clearing what it sees
//!   free.
//! - [`stairs_cells`]: the cells of a flight of stairs, from the walk over it and the map's
//!   points (treads near the height the robot's feet passed at, with room above them);
//!   [`OccupancyGrid::mark_stairs`] marks them [`CellState::Stairs`] on both floors' grids:
//!   neither a wall (the lower floor's band sees the steps) nor free (the upper floor's
//!   stairwell), and blocked to a planner on the floor.
//! - [`write_ros_map`] / [`read_ros_map`]: ROS `map_server` YAML + trinary PGM (unknown cells as
//!   205); [`write_png`]: pictures with inflation, paths and waypoints.
//!
//! ```
//! use nalgebra::Point3;
//! use gridmap::{OccupancyGridBuilder, OccupancyGridConfig, UnknownCells, inflate};
//! use slam_core::{Cell, PointCloud};
//!
//! // A 4 m wall along y = 2 m, seen at the LiDAR's height of 0.5 m.
//! let wall: Vec<Point3<f32>> = (0..400).map(|i| Point3::new(i as f32 * 0.01, 2.0, 0.5)).collect();
//! let builder = OccupancyGridBuilder::new(OccupancyGridConfig::default())?;
//! let grid = builder.build(&PointCloud::from_points(wall), 0.5)?;
//! let planning = inflate(&grid.to_planning_grid(UnknownCells::Free), 0.25)?;
//! let wall_cell = grid.occupied().cell_at([1.0, 2.0].into()).unwrap();
//! assert!(grid.occupied().is_blocked(wall_cell));
//! assert!(planning.is_blocked(Cell::new(wall_cell.x, wall_cell.y - 2)), "0.2 m from the wall");
//! assert!(!planning.is_blocked(Cell::new(wall_cell.x, wall_cell.y - 3)), "0.3 m from the wall");
//! # Ok::<(), gridmap::GridMapError>(())
//! ```
//!
//! Obstacles from the floor up, and the planning layer with its clearance cost:
//!
//! ```
//! use nalgebra::Point3;
//! use gridmap::{
//!     FloorConfig, FloorMap, ObstacleBandConfig, OccupancyGridBuilder, OccupancyGridConfig,
//!     PlanningGrid, PlanningGridConfig,
//! };
//! use slam_core::PointCloud;
//!
//! // A floor 0.8 m below the map's origin (the first LiDAR pose), the top of a 0.4 m tall
//! // post at (2.05, 2.05) m and a ceiling 1.7 m above the floor.
//! let mut points = Vec::new();
//! for i in 0..100 {
//!     for j in 0..100 {
//!         let (x, y) = (i as f32 * 0.04, j as f32 * 0.04);
//!         points.push(Point3::new(x, y, -0.8));
//!         points.push(Point3::new(x, y, 0.9));
//!     }
//!     points.push(Point3::new(2.05, 2.05, -0.4 - i as f32 * 0.001));
//! }
//! let cloud = PointCloud::from_points(points);
//! let hints = [Point3::new(0.5, 0.5, -0.8)]; // the robot's feet
//! let floor = FloorMap::estimate(&cloud, &hints, &FloorConfig::default())?;
//! let builder = OccupancyGridBuilder::new(OccupancyGridConfig::default())?;
//! let grid = builder.build_floor_band(&cloud, &floor, &ObstacleBandConfig::default())?;
//! // Only the post is an obstacle (the floor is below the band, the ceiling above it).
//! assert_eq!(grid.counts().1, 1);
//! let layer = PlanningGrid::new(&grid, PlanningGridConfig::default())?;
//! assert!(layer.blocked().count_blocked() > 1, "hard-inflated by 0.30 m");
//! assert!(layer.step_costs().iter().all(|&m| (1.0..=3.0).contains(&m)));
//! # Ok::<(), gridmap::GridMapError>(())
//! ```
//!
//! When not to use it: for 3D navigation (stairs, ramps, multi-storey overhangs) a 2D grid is
//! not enough; use an elevation map or a voxel map instead. The floor band detects nothing below
//! the floor (drop-offs, stairs down).

mod band;
mod band_accumulator;
mod builder;
mod config;
mod distance;
mod error;
mod extent;
mod floor;
mod floor_levels;
mod fusion;
mod live;
mod occupancy;
mod picture;
mod planning;
mod rays;
mod ros_map;
mod stairs;
mod walked;

pub use band::ObstacleBandConfig;
pub use band_accumulator::FloorBandAccumulator;
pub use builder::OccupancyGridBuilder;
pub use config::OccupancyGridConfig;
pub use distance::{DistanceField, inflate, squared_distance_cells};
pub use error::GridMapError;
pub use extent::CellExtent;
pub use floor::{FloorConfig, FloorMap, floor_hints_below};
pub use floor_levels::{FloorLevel, FloorLevels, FloorLevelsConfig, LevelChange};
pub use fusion::{FusionReport, LocalCell, LocalGrid, fuse_local_grid};
pub use live::{LiveLayer, LiveLayerConfig, LiveUpdate};
pub use occupancy::{CellState, OccupancyGrid, UnknownCells};
pub use picture::{colours, render, write_png};
pub use planning::{
    CellRect, ClearanceCostConfig, PlanningGrid, PlanningGridConfig, clearance_step_costs,
};
pub use ros_map::{RosMapYaml, read_ros_map, ros_map_pgm, ros_map_yaml, write_ros_map};
pub use stairs::{Climb, StairsConfig, stairs_cells};
pub use walked::walked_cells;
