//! What any robot source gives and takes, with nothing simulated in it: the [`Sample`] every
//! source delivers (a scan with the odometry and the LiDAR's mounting), the robot's
//! [`SpotGeometry`] and [`MotionLimits`], the commands it takes ([`VelocityCommand`],
//! [`Se2Trajectory`]) and the [`Robot`] trait a commanded source implements.
//!
//! Uses `slam-core` only: the simulator (`sim`), the recordings (`record`) and a real Spot's
//! client implement these types; the navigator (`nav`) consumes them, so it drives any of them
//! alike.

mod command;
mod description;
mod error;
mod geometry;
mod interface;
mod sample;

pub use command::{
    MobilityCommand, Se2Trajectory, Se2TrajectoryPoint, TrajectoryFrame, VelocityCommand,
};
pub use description::{MotionLimits, RobotDescription};
pub use error::RobotError;
pub use geometry::SpotGeometry;
pub use interface::Robot;
pub use sample::Sample;
