//! The velocity controller: from the waypoints ahead (or the goal close by) to a command within
//! the robot's motion limits.

use nalgebra::Vector2;
use pathfind::line_of_sight;
use slam_core::{BitGrid, Pose3, wrap_angle};

use crate::nav::config::NavigatorConfig;
use crate::robot::{MotionLimits, VelocityCommand};

/// The navigator's steering settings and the robot's limits, borrowed for one command.
pub(crate) struct Controller<'a> {
    pub(crate) config: &'a NavigatorConfig,
    pub(crate) limits: &'a MotionLimits,
}

impl Controller<'_> {
    /// Turn in place to take out `heading_error` (radians): the goal is reached, its heading not.
    pub(crate) fn turn(&self, heading_error: f64) -> VelocityCommand {
        VelocityCommand::new(0.0, self.yaw_rate(heading_error))
    }

    /// The final approach: straight at the goal in the body frame (forward and sideways, no
    /// turn), at a speed proportional to the distance left.
    pub(crate) fn approach(&self, pose: &Pose3, target: Vector2<f64>) -> VelocityCommand {
        let to = target - pose.translation.vector.xy();
        let yaw = pose.rotation.euler_angles().2;
        let (c, s) = (yaw.cos(), yaw.sin());
        let body = Vector2::new(c * to.x + s * to.y, -s * to.x + c * to.y);
        let distance = body.norm();
        let speed = (self.config.approach_gain * distance)
            .min(self.config.approach_speed)
            .min(self.limits.max_lateral_speed);
        let v = body / distance.max(1e-9) * speed;
        VelocityCommand {
            forward: v.x,
            lateral: v.y,
            yaw_rate: 0.0,
        }
    }

    /// The command from `position` (facing `yaw`) toward the first of `waypoints` that is not
    /// already underfoot, looking ahead along `grid` (the hard-inflated planning grid).
    pub(crate) fn follow(
        &self,
        grid: &BitGrid,
        waypoints: &[Vector2<f64>],
        position: Vector2<f64>,
        yaw: f64,
    ) -> VelocityCommand {
        let near = 0.5 * self.config.goal_tolerance;
        let next = waypoints
            .iter()
            .position(|w| (*w - position).norm() > near)
            .unwrap_or(waypoints.len().saturating_sub(1));
        // Look ahead along closely spaced waypoints (a path through a narrow place) to the
        // farthest one within reach that a straight, hard-inflation-free line joins: steering at
        // a cell 0.1 m ahead would turn the robot in place at every small offset.
        let here = grid.cell_at(position);
        let mut target = waypoints.get(next).copied().unwrap_or(position);
        for w in waypoints.iter().skip(next + 1) {
            if (w - position).norm() > self.config.lookahead {
                break;
            }
            let visible = here
                .zip(grid.cell_at(*w))
                .is_some_and(|(a, b)| line_of_sight(grid, a, b));
            if !visible {
                break;
            }
            target = *w;
        }
        let to = target - position;
        let error = wrap_angle(to.y.atan2(to.x) - yaw);
        let yaw_rate = self.yaw_rate(error);
        if error.abs() > self.config.turn_in_place_above {
            return VelocityCommand::new(0.0, yaw_rate);
        }
        // Slow down for the last metre so that one 0.2 s step cannot overshoot the tolerance.
        let remaining: f64 = waypoints.last().map_or(0.0, |g| (g - position).norm());
        let speed = self.config.speed.min(self.limits.max_forward_speed);
        VelocityCommand::new(speed.min(remaining) * error.cos(), yaw_rate)
    }

    /// Turn rate for a heading error (radians), proportional and capped at the robot's limit.
    fn yaw_rate(&self, error: f64) -> f64 {
        let max = self.limits.max_yaw_rate;
        (self.config.heading_gain * error).clamp(-max, max)
    }
}
