//! # spot-adapter
//!
//! Everything between a robot and the SLAM engine and planners of spot-nav, in rooms:
//!
//! - [`robot`]: what any robot source gives and takes, nothing simulated: the
//!   [`Sample`](robot::Sample) every source delivers (stamp, `odom_T_body`, `body_T_lidar`,
//!   cloud), Spot's geometry and motion limits, the commands ([`VelocityCommand`](robot::VelocityCommand),
//!   [`Se2Trajectory`](robot::Se2Trajectory)) and the [`Robot`](robot::Robot) trait.
//! - [`sim`] (cargo feature `sim`, on by default): the test world: a procedurally generated
//!   building with obstacles that can be added later, a VLP-16 model, drifting leg odometry,
//!   routes, [`SimulatedSpot`](sim::SimulatedSpot) (walks a route) and
//!   [`CommandedSpot`](sim::CommandedSpot) (a `Robot` driven by commands).
//! - [`record`] (cargo feature `record`, on by default): recordings in, streamed one scan at a time: ROS 1 and ROS 2 (MCAP) bags,
//!   KITTI sequences, folders of PCD/PLY scans and the spot-nav recording format, each opened
//!   from its path by [`open_recording`](record::open_recording).
//! - [`eval`]: accuracy against ground truth: ATE, drift, loop end-point error.
//! - [`nav`]: the [`Navigator`](nav::Navigator) (localise, plan, command) and
//!   [`drive`](nav::drive), which runs it on any `Robot`.
//! - [`pipelines`]: the Graph-SLAM engine put together with this workspace's backends.
//! - [`prelude`]: the types a robot program needs, in one import
//!   (`use spot_adapter::prelude::*;`); the backend crates and nalgebra are re-exported whole
//!   at the root ([`slam_core`], [`registration`], [`posegraph`], [`gridmap`], [`pathfind`],
//!   [`nalgebra`]), so one dependency on spot-adapter is enough.
//!
//! `robot`, `record` and `eval` need `slam-core` only; `nav` adds `gridmap` and `pathfind`;
//! only `sim` uses random numbers and only `record` reads bags (mcap, rosbag, and the C
//! libraries of their compressions). Build with `default-features = false` for a robot: no
//! simulator, no recordings (`sim` needs `record`, which writes its runs).
//!
//! ```
//! use slam_core::io::StampedPose;
//! use spot_adapter::eval::{DEFAULT_MAX_STAMP_DIFFERENCE, absolute_trajectory_error, end_point_drift};
//! use spot_adapter::sim::{SimulatedSpot, SimulationConfig};
//!
//! // A simulated lap of building 7's corridor loop; keep the poses, skip the clouds' use here.
//! let config = SimulationConfig::with_seed(7);
//! let sim = SimulatedSpot::corridor_loop(&config)?;
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
//! When not to use the simulator: it is for testing SLAM and navigation logic at scale, not for
//! photorealistic sensor studies (no materials, no beam divergence, no mixed pixels).

mod error;
pub mod eval;
#[cfg(feature = "grpc")]
pub mod grpc;
pub mod nav;
pub mod pipelines;
pub mod prelude;
#[cfg(feature = "record")]
pub mod record;
pub mod robot;
#[cfg(feature = "sim")]
pub mod sim;

// The backend crates and nalgebra, whole: one dependency on spot-adapter pins them all.
pub use gridmap;
pub use pathfind;
pub use posegraph;
pub use registration;
pub use slam_core;
pub use slam_core::nalgebra;

pub use error::AdapterError;
pub use nav::DriveError;
#[cfg(feature = "record")]
pub use record::MessageError;
