//! The driving loop: a [`Robot`]'s samples into a [`Navigator`], its commands back out, until
//! the goal is reached, no path is left, or the cycles run out; the robot is stopped on every
//! way out, errors included.

use std::time::Instant;

use nalgebra::Vector2;
use slam_core::{Pose3, Registrator};

use crate::nav::DriveError;
use crate::nav::navigator::Navigator;
use crate::nav::planner::NavPlanner;
use crate::nav::step::{Goal, NavigationStep};
use crate::robot::{MobilityCommand, Robot, Sample};

/// How a drive ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum DriveOutcome {
    /// The navigator estimates the body within its goal tolerance.
    Arrived,
    /// No collision-free path joins the robot and the goal on the map.
    NoPath,
    /// The robot made no progress after several attempts to get free.
    Blocked,
    /// The robot could not be found on the map.
    Lost,
    /// The cycle budget ran out first.
    GaveUp,
}

impl DriveOutcome {
    /// A short name for reports: `arrived`, `no_path`, `blocked`, `lost`, `gave_up`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Arrived => "arrived",
            Self::NoPath => "no_path",
            Self::Blocked => "blocked",
            Self::Lost => "lost",
            Self::GaveUp => "gave_up",
        }
    }
}

/// What a drive did: how it ended and the cycles it took.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DriveReport {
    /// How it ended.
    pub outcome: DriveOutcome,
    /// Samples taken (navigator cycles).
    pub cycles: usize,
}

/// One cycle of a drive, as [`drive`] shows it to its observer.
#[derive(Clone, Copy, Debug)]
pub struct DriveCycle<'a> {
    /// The sample the cycle ran on.
    pub sample: &'a Sample,
    /// What the navigator decided.
    pub step: &'a NavigationStep,
    /// The navigator's estimate of the body pose after localising (map frame).
    pub estimate: Pose3,
    /// The waypoints still ahead after this cycle (map frame, metres, ending at the goal;
    /// empty without a plan).
    pub waypoints: &'a [Vector2<f64>],
    /// Milliseconds the navigator took for the cycle (localise, fuse, plan, command), without
    /// the robot's own time.
    pub navigator_ms: f64,
}

/// Drive `robot` with `navigator` toward `goal` (map frame, metres, optionally with a heading) for at most `max_cycles`
/// samples. `observe` sees every cycle: the sample, the navigator's decision and its estimate
/// (for logging and evaluation). The robot is sent a stop however the drive ends.
///
/// # Errors
/// [`DriveError::Robot`] when the robot fails to deliver a sample or take a command, and
/// [`DriveError::Navigation`] when the navigator fails (a non-finite goal); the robot was
/// sent a stop first (if that fails too, the first error is the one returned).
pub fn drive<R: Robot, G: Registrator, P: NavPlanner>(
    robot: &mut R,
    navigator: &mut Navigator<G, P>,
    goal: impl Into<Goal>,
    max_cycles: usize,
    mut observe: impl FnMut(&DriveCycle<'_>),
) -> Result<DriveReport, DriveError<R::Error>> {
    let goal = goal.into();
    let result = (|| {
        for cycle in 1..=max_cycles {
            let sample = robot.next_sample().map_err(DriveError::Robot)?;
            let started = Instant::now();
            let step = navigator
                .step(&sample, goal)
                .map_err(DriveError::Navigation)?;
            let navigator_ms = started.elapsed().as_secs_f64() * 1e3;
            observe(&DriveCycle {
                sample: &sample,
                step: &step,
                estimate: navigator.pose(),
                waypoints: navigator.waypoints(),
                navigator_ms,
            });
            let outcome = match step {
                NavigationStep::Walk(command) => {
                    robot
                        .send(&MobilityCommand::Velocity(command))
                        .map_err(DriveError::Robot)?;
                    continue;
                }
                NavigationStep::Hold => {
                    robot.stop().map_err(DriveError::Robot)?;
                    continue;
                }
                NavigationStep::Arrived => DriveOutcome::Arrived,
                NavigationStep::NoPath => DriveOutcome::NoPath,
                NavigationStep::Blocked => DriveOutcome::Blocked,
                NavigationStep::Lost => DriveOutcome::Lost,
            };
            return Ok(DriveReport {
                outcome,
                cycles: cycle,
            });
        }
        Ok(DriveReport {
            outcome: DriveOutcome::GaveUp,
            cycles: max_cycles,
        })
    })();
    let stopped = robot.stop().map_err(DriveError::Robot);
    let report = result?;
    stopped?;
    Ok(report)
}
