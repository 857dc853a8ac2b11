//! The types a robot program needs, in one import: `use spot_adapter::prelude::*;`.
//!
//! The engine and its configuration ([`GraphSlam`], [`GraphSlamConfig`], the assembled
//! [`pipelines`](crate::pipelines)), the backends and their settings (ICP, LOAM,
//! Gauss-Newton, Levenberg-Marquardt, graduated non-convexity, the grid planners), the three
//! backend traits to plug in one's own, occupancy and planning grids, the navigator
//! ([`Navigator`], [`NavigatorConfig`], [`NavPlanner`], [`drive`]), the robot interface
//! ([`Robot`], [`Sample`]), poses and clouds ([`Pose3`], [`PointCloud`]) and the nalgebra
//! types that appear in their signatures. With the `sim` feature, the simulated Spots; with
//! `record`, `open_recording`.
//!
//! Everything else stays in its crate, re-exported whole at the root of this one
//! ([`slam_core`], [`registration`], [`posegraph`], [`gridmap`], [`pathfind`], [`nalgebra`]),
//! so one dependency on `spot-adapter` pins every version.
//!
//! A planner of one's own, plugged into the navigator's planner trait and run on a room:
//!
//! ```
//! use spot_adapter::prelude::*;
//!
//! /// Dijkstra's algorithm, built afresh on each grid the navigator plans on.
//! #[derive(Debug)]
//! struct MyDijkstra;
//!
//! impl NavPlanner for MyDijkstra {
//!     type Memory = ();
//!
//!     fn plan(
//!         &mut self,
//!         grid: &PlanningGrid,
//!         _: &mut (),
//!         start: Cell,
//!         goal: Cell,
//!     ) -> Result<Option<GridPath>, PlanError> {
//!         Dijkstra::new(grid.blocked()).plan(start, goal)
//!     }
//! }
//!
//! // A 10 x 10 m room of free cells, 0.1 m each.
//! let cells = GridGeometry { resolution: 0.1, ..Default::default() };
//! let occupancy = OccupancyGrid::new(100, 100, cells, CellState::Free)?;
//! let grid = PlanningGrid::new(&occupancy, PlanningGridConfig::default())?;
//! let path = MyDijkstra.plan(&grid, &mut (), Cell::new(20, 20), Cell::new(80, 30))?;
//! assert!(path.is_some());
//!
//! // The engine as the examples run it, and a navigator's settings with one change.
//! let slam = point_to_plane_slam(slam_config())?;
//! assert_eq!(slam.graph().node_count(), 0);
//! let config = NavigatorConfig { planner: PlannerKind::AStar, ..NavigatorConfig::default() };
//! let goal: Goal = Vector2::new(8.0, 3.0).into();
//! assert!(goal.heading.is_none() && config.planner == PlannerKind::AStar);
//! let start = Pose3::identity();
//! assert_eq!(start.translation.vector, Vector3::zeros());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub use gridmap::{
    CellState, LiveLayerConfig, OccupancyGrid, OccupancyGridBuilder, OccupancyGridConfig,
    PlanningGrid, PlanningGridConfig,
};
pub use nalgebra::{Isometry3, Point2, Point3, Translation3, UnitQuaternion, Vector2, Vector3};
pub use pathfind::{AStar, CellCostAStar, Dijkstra, JumpPointSearch, JumpPointSearchPlus};
pub use posegraph::{
    GaussNewton, GncConfig, GraduatedNonConvexity, LevenbergMarquardt, SolverConfig,
};
pub use registration::{
    IcpConfig, IcpKernel, LoamConfig, LoamRegistrator, PointToPlaneIcp, PointToPointIcp,
};
pub use slam_core::io::StampedPose;
pub use slam_core::{
    Alignment, Cell, GraphSlam, GraphSlamConfig, GridGeometry, GridPath, InvalidSetting,
    MapRegistrator, OptimizationReport, OptimizeError, Optimizer, PlaceRecognizer, PlanError,
    Planner, PointCloud, Pose2, Pose3, PoseGraph, RegistrationError, Registrator, ScanInput,
    ScanOutcome, SlamReport, WholeMapRegistrator,
};

pub use crate::AdapterError;
pub use crate::eval::TrajectoryEvaluation;
pub use crate::nav::{
    DriveError, DriveOutcome, DriveReport, Goal, NavError, NavPlanner, NavigationMap,
    NavigationMapConfig, NavigationStep, Navigator, NavigatorConfig, PlannerKind, drive,
};
pub use crate::pipelines::{
    LoamSlam, PointToPlaneSlam, loam_slam, point_to_plane_localiser, point_to_plane_slam,
    point_to_plane_tracker, slam_config,
};
#[cfg(feature = "record")]
pub use crate::record::{OpenedSource, SourceConfig, open_recording};
pub use crate::robot::{MotionLimits, Robot, RobotDescription, Sample, VelocityCommand};
#[cfg(feature = "sim")]
pub use crate::sim::{CommandedSpot, SimulatedSpot, SimulationConfig};
