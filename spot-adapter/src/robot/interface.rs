//! The `Robot` trait: a source of samples that also takes motion commands.

use crate::robot::command::MobilityCommand;
use crate::robot::description::RobotDescription;
use crate::robot::sample::Sample;

/// A robot the navigator can drive: it delivers one [`Sample`] per LiDAR scan and takes motion
/// commands. The simulated Spot implements it, and so does a client of a real Spot.
///
/// The driving loop is: [`Robot::next_sample`], decide, [`Robot::send`] (or [`Robot::stop`]),
/// repeat. A command stays in force until the next one, a stop, or (on a real robot) its own
/// end time, so a robot never keeps walking on a command its driver has stopped renewing.
pub trait Robot {
    /// Why the robot could not deliver a sample or take a command.
    type Error: std::error::Error + Send + Sync + 'static;

    /// The robot's geometry and motion limits.
    fn description(&self) -> &RobotDescription;

    /// The next scan with the odometry at its stamp; it waits for the scan, while the command
    /// in force keeps running.
    ///
    /// # Errors
    /// When the robot cannot deliver a scan (a lost connection, a malformed cloud).
    fn next_sample(&mut self) -> Result<Sample, Self::Error>;

    /// Replace the command in force by `command`.
    ///
    /// # Errors
    /// When the robot refuses the command (a frame it does not know, a lost lease).
    fn send(&mut self, command: &MobilityCommand) -> Result<(), Self::Error>;

    /// Stop moving (stand in place).
    ///
    /// # Errors
    /// When the stop cannot be delivered.
    fn stop(&mut self) -> Result<(), Self::Error>;
}
