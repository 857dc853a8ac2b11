//! # spot-adapter
//!
//! Everything between a Spot robot and the SLAM engine: the [`Sample`] every source delivers
//! (stamp, `odom_T_body`, `body_T_lidar`, cloud), a simulated Spot that needs no hardware,
//! recordings on disk, a reader for KITTI-style folders, the evaluation of trajectories, and the
//! navigator that walks the robot to goals on the map.
//!
//! - [`Building`]: a procedurally generated office floor from a seed (ring corridor, rooms,
//!   doors, pilasters, pillars, furniture, floor and ceiling) as axis-aligned boxes with a
//!   ray-casting index, its ground-truth floor plan ([`Building::is_obstacle`],
//!   [`Building::occupancy_grid`]).
//! - [`Vlp16`]: a VLP-16 ray-cast against the building (16 rings, 1800 columns, range noise,
//!   dropouts; `ring` and `time` channels).
//! - [`OdometryModel`]: Spot's leg odometry, drifting 1.9 % of the distance walked.
//! - [`Route`]: the corridor loop or a planned route between two points, walked at 0.6 m/s.
//! - [`SimulatedSpot`]: all of the above as an iterator of [`Sample`]s with ground truth.
//! - [`CommandedSpot`]: the same robot driven by [`VelocityCommand`]s, for closed loops.
//! - [`Navigator`]: walks the robot to a goal on a map: localises each scan against the map,
//!   replans with Jump Point Search on the map's inflated occupancy grid, and turns or walks
//!   toward the next filtered waypoint.
//! - [`point_to_plane_slam`], [`loam_slam`]: the Graph-SLAM engine put together with this
//!   workspace's backends.
//! - [`RecordingWriter`], [`Recording`], [`KittiSequence`]: runs on disk.
//! - [`absolute_trajectory_error`], [`end_point_drift`], [`segment_drift`],
//!   [`loop_end_point_error`], all at once in [`TrajectoryEvaluation`]: accuracy against ground
//!   truth.
//!
//! ```
//! use spot_adapter::{
//!     DEFAULT_MAX_STAMP_DIFFERENCE, SimulatedSpot, SimulationConfig, absolute_trajectory_error,
//!     end_point_drift,
//! };
//! use slam_core::io::StampedPose;
//!
//! // A simulated lap of building 7's corridor loop; keep the poses, skip the clouds' use here.
//! let sim = SimulatedSpot::corridor_loop(7, &SimulationConfig::default())?;
//! let truth = sim.ground_truth();
//! let odometry: Vec<StampedPose> = sim
//!     .take(40)
//!     .map(|s| StampedPose { stamp: s.stamp, pose: s.odom_t_body })
//!     .collect();
//! let ate = absolute_trajectory_error(&odometry, &truth, DEFAULT_MAX_STAMP_DIFFERENCE)?;
//! assert_eq!(ate.pairs, 40);
//! let est: Vec<_> = odometry.iter().map(|p| p.pose).collect();
//! let gt: Vec<_> = truth[..40].iter().map(|p| p.pose).collect();
//! let drift = end_point_drift(&est, &gt)?;
//! assert!(drift.relative_drift < 0.05, "odometry drifts about 1.9 %");
//! # Ok::<(), spot_adapter::AdapterError>(())
//! ```
//!
//! Simplifications, each documented where it lives: by default a scan is cast from one pose (no
//! motion distortion, so no deskewing is needed; `SimulationConfig::motion_distortion` turns it
//! on), the body stays level at a fixed height unless
//! [`GaitSway`] is set, and surfaces reflect every ray (no intensity, no multi-path).
//!
//! When not to use it: the simulator is for testing SLAM and navigation logic at scale, not for
//! photorealistic sensor studies (no materials, no beam divergence, no mixed pixels).

mod alignment;
mod ate;
mod building;
mod commanded_spot;
mod drift;
mod error;
mod evaluation;
mod floor_plan;
mod frames;
mod kitti;
mod lidar;
mod navigator;
mod odometry;
mod ray_cast;
mod recording;
mod rng;
mod route;
mod route_planner;
mod sample;
mod simulator;
mod slam_backends;

pub use alignment::align_rigid;
pub use ate::{AteReport, DEFAULT_MAX_STAMP_DIFFERENCE, absolute_trajectory_error, associate};
pub use building::{BoxKind, Building, BuildingConfig, Room, SolidBox};
pub use commanded_spot::{CommandedSpot, MAX_YAW_RATE, VelocityCommand};
pub use drift::{
    EndPointDrift, INDOOR_SEGMENT_LENGTHS, KITTI_SEGMENT_LENGTHS, SegmentDrift, end_point_drift,
    loop_end_point_error, path_length, segment_drift,
};
pub use error::AdapterError;
pub use evaluation::{TrajectoryEvaluation, body_trajectory};
pub use floor_plan::OBSTACLE_HEIGHT;
pub use frames::{GaitSway, SpotGeometry};
pub use kitti::{KittiOdometry, KittiSequence};
pub use lidar::{Vlp16, Vlp16Config};
pub use navigator::{NavigationStep, Navigator, NavigatorConfig, navigation_grid};
pub use odometry::{OdometryDriftConfig, OdometryModel};
pub use ray_cast::{HitTarget, RayHit};
pub use recording::{Recording, RecordingSamples, RecordingWriter};
pub use rng::SimRng;
pub use route::Route;
pub use route_planner::RouteConfig;
pub use sample::Sample;
pub use simulator::{SimulatedSpot, SimulationConfig};
pub use slam_backends::{
    LoamSlam, PointToPlaneSlam, loam_slam, point_to_plane_slam, point_to_plane_tracker, slam_config,
};
