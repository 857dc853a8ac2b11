//! A client of a real Spot over gRPC (cargo feature `grpc`), wire-compatible with Boston
//! Dynamics' SDK: [`SpotClient`] logs in, finds services through the robot's directory, syncs
//! time, holds the body lease, reads the frame tree, point clouds and local grids, and sends
//! velocity and trajectory commands. It implements [`Robot`](crate::robot::Robot), so
//! [`drive`](crate::nav::drive) walks a real Spot as it walks the simulated one.
//!
//! What it does on the wire, as the SDK does:
//! - TLS to `host:443`, trusting only the CA the user gives; one channel per authority, with
//!   the authority as both the TLS name and the HTTP/2 `:authority` (the robot routes by it).
//!   `auth.spot.robot`, `api.spot.robot` (directory) and `id.spot.robot` are fixed; every other
//!   authority comes from `ListServiceEntries`.
//! - `authorization: Bearer <token>` on every call after `GetAuthToken`; the token is renewed
//!   in the background.
//! - `TimeSyncUpdate` rounds until the robot's skew estimate converges; motion commands carry
//!   end times in robot time and the robot's clock name, and are refused here (nothing sent)
//!   without a converged estimate younger than [`TimeSyncConfig::max_age`].
//! - The `body` lease acquired at connection, retained every 2 s, attached to every command,
//!   returned on drop. Once the robot says the lease is not ours (another client took it),
//!   every command is refused with [`SpotError::LeaseLost`].
//!
//! - With [`SpotConfig::software_estop`], a software E-stop endpoint of our own (bench setups
//!   without an E-stop controller): registered at connection, checked in every third of its
//!   timeout with the challenge answered, and set to `ESTOP_LEVEL_SETTLE_THEN_CUT` on drop.
//!
//! The `.proto` files in `proto/` are spot-nav's own subset, written from the wire facts; the
//! tests prove it against the official `bosdyn-api` package acting as the robot.
//!
//! ```no_run
//! use spot_adapter::grpc::{Credentials, SpotClient, SpotConfig};
//! use spot_adapter::robot::{MobilityCommand, VelocityCommand};
//!
//! let password = std::env::var("SPOT_PASSWORD")?;
//! let ca = std::fs::read("robot-ca.pem")?;
//! let config = SpotConfig::new("192.168.80.3", ca, Credentials::new("user", password));
//! let spot = SpotClient::connect(config)?;
//! let odom_t_body = spot.frame_tree()?.a_t_b("odom", "body")?;
//! println!("{} at {:?}", spot.identity().nickname, odom_t_body.translation);
//! spot.command(&MobilityCommand::Velocity(VelocityCommand::new(0.2, 0.0)))?;
//! spot.stand_still()?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod api;
mod auth;
mod clock;
mod config;
mod decode_problem;
mod directory;
mod error;
mod estop;
mod frame_tree;
mod lease;
mod local_grid;
mod point_cloud;
mod posture;
mod power;
mod robot_command;
mod robot_state;
mod session;
mod spot_client;
mod time_sync;

pub use config::{Credentials, SpotConfig, TimeSyncConfig};
pub use decode_problem::{CloudProblem, ConfigProblem, GridProblem};
pub use directory::RobotIdentity;
pub use error::SpotError;
pub use frame_tree::{FrameError, FrameTree};
pub use local_grid::LocalGrid;
pub use point_cloud::SpotCloud;
pub use robot_state::{EStop, MotorPower, RobotStatus};
pub use spot_client::SpotClient;
/// gRPC status codes, as [`SpotError::Rpc`] reports them.
pub use tonic::Code as RpcCode;
