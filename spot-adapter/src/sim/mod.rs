//! The test world (cargo feature `sim`, on by default): a procedurally generated building, ray
//! casting, a VLP-16 model, Spot's drifting leg odometry, routes, and two simulated Spots: one
//! that walks a route fixed in advance ([`SimulatedSpot`], an iterator of samples with ground
//! truth) and one driven by motion commands ([`CommandedSpot`], a [`Robot`](crate::robot::Robot)).
//!
//! Uses `robot` (the types it produces), `record` (to write a run), `slam-core`, and for routes
//! `gridmap` and `pathfind`; nothing outside this module uses it except tests, examples and
//! benches, so a build without the feature has no simulator and no random numbers.
//!
//! Simplifications, each documented where it lives: by default a scan is cast from one pose (no
//! motion distortion; [`SimulationConfig::motion_distortion`] turns it on), the body stays level
//! at a fixed height unless [`GaitSway`] is set, and surfaces reflect every ray (no intensity,
//! no multi-path).

mod building;
mod commanded_spot;
mod floor_plan;
mod gait_sway;
mod generator;
mod lidar;
mod odometry;
mod ray_cast;
mod rng;
mod route;
mod route_planning;
mod simulated_spot;
mod solid_box;

pub use building::{Building, Room};
pub use commanded_spot::CommandedSpot;
pub use floor_plan::OBSTACLE_HEIGHT;
pub use gait_sway::GaitSway;
pub use generator::BuildingConfig;
pub use lidar::{Vlp16, Vlp16Config};
pub use odometry::{OdometryDriftConfig, OdometryModel};
pub use ray_cast::{HitTarget, RayHit};
pub use rng::SimRng;
pub use route::Route;
pub use route_planning::RouteConfig;
pub use simulated_spot::{SimulatedSpot, SimulationConfig};
pub use solid_box::{BoxId, BoxKind, SolidBox};
