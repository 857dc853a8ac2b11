//! The Graph-SLAM engine (thesis chapter 4), generic over the backend traits.
//!
//! Per scan: validate the input, predict the LiDAR pose from the robot's odometry
//! (`X_t = X_k * (odom_T_lidar_k^-1 * odom_T_lidar_t)`, thesis eq. 4.1-4.2), and once the LiDAR
//! has moved [`GraphSlamConfig::keyframe_distance`] from the last keyframe, register the scan
//! against a local map of the last [`GraphSlamConfig::local_map_keyframes`] keyframes and add a
//! node. An odometry step far from the constant-velocity extrapolation of the last two scans
//! ([`TrackerConfig::arbitration_distance`](crate::tracking::TrackerConfig::arbitration_distance)) is registered from both guesses and the better
//! fit kept; [`SlamReport::odometry_faults`] counts the steps it overruled. New keyframes near old ones queue loop-closure candidates; a loop-closure step aligns the
//! new keyframe to the candidate's neighbourhood (coarse, then refined), adds an edge and
//! optimises the graph. Keyframe scans with a per-point `time` channel are deskewed first, with
//! the velocity the odometry showed since the previous scan. A scan registered where the map
//! already has a keyframe rides on it instead of making a new one
//! ([`GraphSlamConfig::revisit_radius`]), so a walk through a mapped building again adds
//! nothing to the graph.
//!
//! One file a stage: `prediction` (where the scan should be), `scan_preparation` (thinning and
//! deskewing), `scan_tracking` (registration against the local map, the sweep's own motion),
//! `local_map`, `revisit` (riding on old keyframes), `keyframes` (what is kept, the trajectories and the map), `cloud_store` (the keyframes' map clouds, in memory or in a file), `loop_closure` (the
//! candidate queue and the checks, each rejection counted by its [`LoopRejection`]),
//! `information` (edge information); `engine` holds the state and runs the stages in order.

mod cloud_store;
mod config;
mod deskew;
mod engine;
mod gravity;
mod information;
mod keyframes;
mod local_map;
mod loop_closure;
mod node_index;
mod prediction;
mod report;
mod revisit;
mod scan_preparation;
mod scan_tracking;

pub use cloud_store::KeyframeCloudError;
pub use config::{EdgeInformation, GraphSlamConfig, TurnPrediction};
pub use deskew::{SweepPath, deskew};
pub use engine::{GraphSlam, ScanInput};
pub use gravity::level_on_gravity;
pub use report::{LoopOutcome, LoopRejection, LoopRejections, ScanOutcome, SkipReason, SlamReport};
