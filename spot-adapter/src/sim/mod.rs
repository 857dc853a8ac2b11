//! The test world (cargo feature `sim`, on by default): a procedurally generated building, ray
//! casting, a spinning LiDAR model (a VLP-16 by default, an Ouster OS1-128 or any ring layout),
//! Spot's drifting leg odometry, routes, and two simulated Spots: one that moves along a route
//! fixed in advance ([`SimulatedSpot`], an iterator of samples with ground truth; Spot's
//! walk, Spot turning at corners at its full yaw rate, or a person carrying the LiDAR, see
//! [`MotionProfile`]) and one driven by motion commands ([`CommandedSpot`], a
//! [`Robot`](crate::robot::Robot)). [`CloudFolderWriter`] writes a run as a folder of scans
//! with its ground truth, for tools outside spot-nav.
//!
//! Uses `robot` (the types it produces), `record` (to write a run), `slam-core`, and for routes
//! `gridmap` and `pathfind`; nothing outside this module uses it except tests, examples and
//! benches, so a build without the feature has no simulator and no random numbers.
//!
//! Simplifications, each documented where it lives: by default a scan is cast from one pose (no
//! motion distortion; [`SimulationConfig::motion_distortion`] turns it on), Spot's body stays
//! level at a fixed height unless [`GaitSway`] is set (a handheld LiDAR shakes by its
//! [`HandShake`]) or it climbs stairs ([`FloorsTour`]), each floor is flat, and surfaces reflect every ray (no intensity, no
//! multi-path).

mod building;
mod building_config;
mod cloud_folder_writer;
mod commanded_spot;
mod error;
mod floor_coverage;
mod floor_plan;
mod floor_stacking;
mod floors_tour;
mod gait_sway;
mod generator;
mod hand_shake;
mod lidar;
mod motion_profile;
mod odometry;
mod ray_cast;
mod rng;
mod route;
mod route_planning;
mod setting_checks;
mod simulated_spot;
mod solid_box;
mod speed_profile;
mod staircase;
mod stairs_gait;
mod timed_walk;

pub use building::{Building, Room};
pub use building_config::{BuildingConfig, MAX_FLOORS};
pub use cloud_folder_writer::{
    CLOUD_FOLDER_GROUND_TRUTH, CLOUD_FOLDER_ODOMETRY, CloudFolderWriter, CloudFormat,
};
pub use commanded_spot::CommandedSpot;
pub use error::SimError;
pub use floor_coverage::{FloorCoverage, floor_coverage};
pub use floor_plan::OBSTACLE_HEIGHT;
pub use floor_stacking::SLAB_THICKNESS;
pub use floors_tour::{FloorsTour, STAIRS_SPEED};
pub use gait_sway::GaitSway;
pub use hand_shake::HandShake;
pub use lidar::{LidarConfig, SpinningLidar};
pub use motion_profile::{FastTurnsConfig, HandheldConfig, MotionProfile};
pub use odometry::{OdometryDriftConfig, OdometryModel};
pub use ray_cast::{HitTarget, RayHit};
pub use rng::SimRng;
pub use route::Route;
pub use route_planning::{RouteConfig, shortest_length};
pub use simulated_spot::{STAIRS_SLIP, SimulatedSpot, SimulationConfig};
pub use solid_box::{BoxId, BoxKind, SolidBox};
pub use staircase::{Landing, MAX_RISES_WITHOUT_LANDING, Staircase};
pub use stairs_gait::{STAIRS_JOLT, STAIRS_NOD};
