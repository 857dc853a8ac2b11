//! The motion commands a robot takes, in the shapes of Spot's mobility API: a body velocity held
//! for a while, or an SE(2) trajectory in a world-fixed frame.

use slam_core::Pose2;

use crate::robot::RobotError;

/// A body-frame velocity (Spot's `SE2VelocityCommand` in the `body` frame), held until the next
/// command or, on a real robot, until its end time.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VelocityCommand {
    /// Forward speed, m/s (negative walks backwards).
    pub forward: f64,
    /// Sideways speed, m/s (positive walks left); 0 for a planar path follower.
    pub lateral: f64,
    /// Turn rate about the vertical, rad/s (positive turns left).
    pub yaw_rate: f64,
}

impl VelocityCommand {
    /// Walk forward at `forward` m/s while turning at `yaw_rate` rad/s, no sideways motion.
    #[must_use]
    pub fn new(forward: f64, yaw_rate: f64) -> Self {
        Self {
            forward,
            lateral: 0.0,
            yaw_rate,
        }
    }

    /// Whether every component is finite.
    #[must_use]
    pub fn is_finite(&self) -> bool {
        self.forward.is_finite() && self.lateral.is_finite() && self.yaw_rate.is_finite()
    }
}

/// The world-fixed frame an [`Se2Trajectory`] is expressed in (Spot's frame names).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum TrajectoryFrame {
    /// The odometry frame (`odom`): where the robot's leg odometry puts it.
    #[default]
    Odom,
    /// The visual-odometry frame (`vision`) of a real Spot.
    Vision,
}

impl TrajectoryFrame {
    /// The frame's name on the wire (`"odom"`, `"vision"`).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Odom => "odom",
            Self::Vision => "vision",
        }
    }
}

/// One pose of an [`Se2Trajectory`]: where the body should be `time` seconds after the
/// trajectory's reference time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Se2TrajectoryPoint {
    /// Seconds after the trajectory's reference time (its start).
    pub time: f64,
    /// Plan-view body pose in the trajectory's frame.
    pub pose: Pose2,
}

/// A timed sequence of plan-view body poses in a world-fixed frame (Spot's
/// `SE2TrajectoryCommand`): the robot tracks the pose interpolated at each instant and holds the
/// last one at the end.
#[derive(Clone, Debug, PartialEq)]
pub struct Se2Trajectory {
    frame: TrajectoryFrame,
    points: Vec<Se2TrajectoryPoint>,
}

impl Se2Trajectory {
    /// A trajectory through `points` in `frame`.
    ///
    /// # Errors
    /// [`RobotError::InvalidTrajectory`] for no points, a non-finite time or pose, or times
    /// that do not increase.
    pub fn new(
        frame: TrajectoryFrame,
        points: Vec<Se2TrajectoryPoint>,
    ) -> Result<Self, RobotError> {
        let bad =
            |point: usize, problem: &'static str| RobotError::InvalidTrajectory { point, problem };
        if points.is_empty() {
            return Err(bad(0, "a trajectory needs at least one point"));
        }
        for (k, p) in points.iter().enumerate() {
            let t = p.pose.translation.vector;
            let finite = p.time.is_finite()
                && t.x.is_finite()
                && t.y.is_finite()
                && p.pose.rotation.angle().is_finite();
            if !finite {
                return Err(bad(k, "time and pose must be finite"));
            }
            if p.time < 0.0 {
                return Err(bad(k, "times are seconds after the start, not negative"));
            }
            if k > 0 && p.time <= points[k - 1].time {
                return Err(bad(k, "times must increase"));
            }
        }
        Ok(Self { frame, points })
    }

    /// The frame the poses are in.
    #[must_use]
    pub fn frame(&self) -> TrajectoryFrame {
        self.frame
    }

    /// The poses in time order.
    #[must_use]
    pub fn points(&self) -> &[Se2TrajectoryPoint] {
        &self.points
    }

    /// Seconds from the reference time to the last point.
    #[must_use]
    pub fn duration(&self) -> f64 {
        self.points.last().map_or(0.0, |p| p.time)
    }

    /// The pose at `time` seconds after the start: linear in position and along the shorter
    /// arc in heading between the two points around it; the first pose before the start and
    /// the last one after the end.
    #[must_use]
    pub fn pose_at(&self, time: f64) -> Pose2 {
        let k = self.points.partition_point(|p| p.time <= time);
        match (k.checked_sub(1).map(|i| self.points[i]), self.points.get(k)) {
            (Some(a), Some(b)) => {
                let s = (time - a.time) / (b.time - a.time);
                let ta = a.pose.translation.vector;
                let tb = b.pose.translation.vector;
                let (ya, yb) = (a.pose.rotation.angle(), b.pose.rotation.angle());
                let turn = (yb - ya + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI;
                Pose2::new(ta + (tb - ta) * s, ya + turn * s)
            }
            (Some(last), None) => last.pose,
            (None, Some(first)) => first.pose,
            // `new` refuses empty trajectories.
            (None, None) => Pose2::identity(),
        }
    }
}

/// A command for a [`Robot`](crate::robot::Robot).
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum MobilityCommand {
    /// Hold a body velocity.
    Velocity(VelocityCommand),
    /// Hold a body velocity with the stairs mode on (Spot's `MobilityParams.stairs_mode =
    /// STAIRS_MODE_ON`): walk up or down the flight ahead, facing along it.
    Stairs(VelocityCommand),
    /// Track a trajectory whose reference time is when the command is sent.
    Trajectory(Se2Trajectory),
}

impl From<VelocityCommand> for MobilityCommand {
    fn from(command: VelocityCommand) -> Self {
        Self::Velocity(command)
    }
}

impl From<Se2Trajectory> for MobilityCommand {
    fn from(trajectory: Se2Trajectory) -> Self {
        Self::Trajectory(trajectory)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    fn point(time: f64, x: f64, yaw: f64) -> Se2TrajectoryPoint {
        Se2TrajectoryPoint {
            time,
            pose: Pose2::new(Vector2::new(x, 0.0), yaw),
        }
    }

    #[test]
    fn a_trajectory_interpolates_position_and_the_shorter_heading_arc() {
        use std::f64::consts::PI;
        let t = Se2Trajectory::new(
            TrajectoryFrame::Odom,
            vec![point(0.0, 0.0, 0.9 * PI), point(2.0, 1.0, -0.9 * PI)],
        )
        .unwrap();
        let mid = t.pose_at(1.0);
        assert!((mid.translation.x - 0.5).abs() < 1e-12);
        // From +162 degrees to -162 degrees the short way passes through 180 degrees.
        assert!(
            (mid.rotation.angle().abs() - PI).abs() < 1e-9,
            "{}",
            mid.rotation.angle()
        );
        assert_eq!(t.pose_at(-1.0), t.points()[0].pose);
        assert_eq!(t.pose_at(5.0), t.points()[1].pose);
        assert!((t.duration() - 2.0).abs() < 1e-12);
    }

    #[test]
    fn malformed_trajectories_are_refused_naming_the_point() {
        let empty = Se2Trajectory::new(TrajectoryFrame::Odom, vec![]);
        assert!(matches!(
            empty,
            Err(RobotError::InvalidTrajectory { point: 0, .. })
        ));
        let backwards = Se2Trajectory::new(
            TrajectoryFrame::Odom,
            vec![
                point(0.0, 0.0, 0.0),
                point(1.0, 1.0, 0.0),
                point(1.0, 2.0, 0.0),
            ],
        );
        assert!(matches!(
            backwards,
            Err(RobotError::InvalidTrajectory { point: 2, .. })
        ));
        let nan = Se2Trajectory::new(TrajectoryFrame::Odom, vec![point(0.0, f64::NAN, 0.0)]);
        assert!(matches!(
            nan,
            Err(RobotError::InvalidTrajectory { point: 0, .. })
        ));
    }
}
