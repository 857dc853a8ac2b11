//! # gridmap
//!
//! From a map cloud to the 2D grid a planner searches, and to files people and ROS tools read.
//!
//! - [`OccupancyGridBuilder`]: the slice of the map from 0.2 m below to 0.2 m above the LiDAR
//!   height, binned straight into cells (O(N); the thesis ran a k-d tree query per cell), with a
//!   `min_points` noise filter; or, from scans with their poses, ray casting that tells free from
//!   unknown ([`OccupancyGrid`] is tri-state).
//! - [`squared_distance_cells`], [`DistanceField`]: the exact Euclidean distance transform
//!   (Felzenszwalb & Huttenlocher), linear in cells; [`inflate`] uses it for an exact disc of the
//!   robot's radius whatever the radius.
//! - [`fuse_local_grid`]: merge a robot-centred local grid (Spot's `no_step` or
//!   `obstacle_distance` grids) into the global grid, adding obstacles and clearing what it sees
//!   free.
//! - [`write_ros_map`] / [`read_ros_map`]: ROS `map_server` YAML + trinary PGM; [`write_png`]:
//!   pictures with inflation, paths and waypoints.
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
//! let planning = inflate(&grid.to_planning_grid(UnknownCells::Free), 0.25);
//! let wall_cell = grid.occupied().cell_at([1.0, 2.0].into()).unwrap();
//! assert!(grid.occupied().is_blocked(wall_cell));
//! assert!(planning.is_blocked(Cell::new(wall_cell.x, wall_cell.y - 2)), "0.2 m from the wall");
//! assert!(!planning.is_blocked(Cell::new(wall_cell.x, wall_cell.y - 3)), "0.3 m from the wall");
//! # Ok::<(), gridmap::GridMapError>(())
//! ```
//!
//! When not to use it: for 3D navigation (stairs, ramps, overhangs) a 2D slice is not enough; use
//! an elevation map or a voxel map instead.

mod band;
mod builder;
mod config;
mod distance;
mod error;
mod floor;
mod fusion;
mod live;
mod occupancy;
mod picture;
mod planning;
mod rays;
mod ros_map;

pub use band::ObstacleBandConfig;
pub use builder::OccupancyGridBuilder;
pub use config::OccupancyGridConfig;
pub use distance::{DistanceField, inflate, squared_distance_cells};
pub use error::GridMapError;
pub use floor::{FloorConfig, FloorMap, floor_hints_below};
pub use fusion::{FusionReport, LocalCell, LocalGrid, fuse_local_grid};
pub use live::{LiveLayer, LiveLayerConfig, LiveUpdate};
pub use occupancy::{CellState, OccupancyGrid, UnknownCells};
pub use picture::{colours, render, write_png};
pub use planning::{
    CellRect, ClearanceCostConfig, PlanningGrid, PlanningGridConfig, clearance_step_costs,
};
pub use ros_map::{read_ros_map, write_ros_map};
