//! What a [`Navigator`](crate::nav::Navigator) cycle is asked and what it answers: the
//! [`Goal`] to walk to and the [`NavigationStep`] it decided on.

use nalgebra::Vector2;

use crate::robot::VelocityCommand;

/// A goal: a plan-view position (map frame, metres) and, optionally, the heading to end with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Goal {
    /// Where the body should end (metres, map frame).
    pub position: Vector2<f64>,
    /// The heading it should end with (radians, map frame), if any.
    pub heading: Option<f64>,
}

impl From<Vector2<f64>> for Goal {
    fn from(position: Vector2<f64>) -> Self {
        Self {
            position,
            heading: None,
        }
    }
}

/// What the navigator decided this cycle.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum NavigationStep {
    /// Walk: hold this command until the next scan.
    Walk(VelocityCommand),
    /// Stand still this cycle (searching for the robot's place on the map).
    Hold,
    /// The body is within the goal tolerance (and faces the goal's heading): stop.
    Arrived,
    /// No collision-free path joins the robot and the goal on the map (an answer, not a
    /// failure): stop.
    NoPath,
    /// The robot made no progress though it tried to get free several times: stop.
    Blocked,
    /// Localisation failed and the wide searches did not find the robot on the map: stop.
    Lost,
}
