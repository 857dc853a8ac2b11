//! A route walked against the clock: straight legs under a speed and an acceleration limit, a
//! turn at each corner under a yaw-rate and a yaw-acceleration limit, and the level pose at any
//! time, so a sweep can be cast column by column from the pose at each firing time.

use nalgebra::{Translation3, UnitQuaternion, Vector3};
use slam_core::Pose3;

use crate::sim::route::Route;
use crate::sim::speed_profile::TrapezoidMove;

/// Turns smaller than this (radians) are no corner: the walk goes straight on.
const STRAIGHT_ON: f64 = 1e-9;

/// The limits of a walk with turns at the corners; the caller checks that speeds, rates and
/// accelerations are finite and positive and `corner_speed` within `[0, speed]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct WalkLimits {
    /// Top speed along a leg (m/s).
    pub speed: f64,
    /// Speed along the route while turning at a corner (m/s); 0 turns on the spot.
    pub corner_speed: f64,
    /// Speeding up and slowing down (m/s²).
    pub acceleration: f64,
    /// Top yaw rate in a turn (rad/s).
    pub turn_rate: f64,
    /// Starting and stopping a turn (rad/s²).
    pub turn_acceleration: f64,
}

/// One stretch of the walk.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Phase {
    /// Along the route from arc length `from` (metres), facing `yaw`.
    Leg {
        from: f64,
        along: TrapezoidMove,
        yaw: f64,
    },
    /// Through a corner from arc length `from` at a steady `arc_speed` (m/s) while the heading
    /// turns from `yaw` by `sign * turn`.
    Turn {
        from: f64,
        arc_speed: f64,
        yaw: f64,
        sign: f64,
        turn: TrapezoidMove,
    },
}

/// A route walked from rest to rest: each leg speeds up to the top speed and slows down to the
/// corner speed; each corner is turned through at the corner speed (half of the distance before
/// the corner, half after, at most a quarter of either leg), the heading turning by the
/// corner's angle under the yaw limits. Along a leg the body faces along it.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct TimedWalk {
    route: Route,
    height: f64,
    /// Start time (seconds) of each phase, ascending.
    starts: Vec<f64>,
    phases: Vec<Phase>,
    duration: f64,
}

impl TimedWalk {
    /// `route` walked under `limits` with the body `height` metres above the floor.
    pub(crate) fn new(route: &Route, limits: &WalkLimits, height: f64) -> Self {
        let points = route.points();
        let mut arcs = vec![0.0];
        let mut headings = Vec::with_capacity(points.len());
        for w in points.windows(2) {
            let d = w[1] - w[0];
            arcs.push(arcs[arcs.len() - 1] + d.norm());
            headings.push(d.y.atan2(d.x));
        }
        // Corners: (arc length, signed turn) at each inner waypoint where the heading changes.
        let corners: Vec<(f64, f64)> = (1..headings.len())
            .map(|k| {
                let turn = (headings[k] - headings[k - 1] + std::f64::consts::PI)
                    .rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI;
                (arcs[k], turn)
            })
            .filter(|&(_, turn)| turn.abs() > STRAIGHT_ON)
            .collect();
        let length = route.length();
        let mut walk = Self {
            route: route.clone(),
            height,
            starts: Vec::new(),
            phases: Vec::new(),
            duration: 0.0,
        };
        let (mut s, mut speed_in) = (0.0, 0.0);
        let mut yaw = headings.first().copied().unwrap_or(0.0);
        for (k, &(arc, angle)) in corners.iter().enumerate() {
            let turn = TrapezoidMove::new(
                angle.abs(),
                0.0,
                0.0,
                limits.turn_rate,
                limits.turn_acceleration,
            );
            let before = arc - corners.get(k.wrapping_sub(1)).map_or(0.0, |c| c.0);
            let after = corners.get(k + 1).map_or(length, |c| c.0) - arc;
            let through = (limits.corner_speed * turn.duration()).min(0.5 * before.min(after));
            let arc_speed = if turn.duration() > 0.0 {
                through / turn.duration()
            } else {
                0.0
            };
            let enter = arc - 0.5 * through;
            walk.push(Phase::Leg {
                from: s,
                along: TrapezoidMove::new(
                    enter - s,
                    speed_in,
                    arc_speed,
                    limits.speed,
                    limits.acceleration,
                ),
                yaw,
            });
            walk.push(Phase::Turn {
                from: enter,
                arc_speed,
                yaw,
                sign: angle.signum(),
                turn,
            });
            yaw += angle;
            s = arc + 0.5 * through;
            speed_in = arc_speed;
        }
        walk.push(Phase::Leg {
            from: s,
            along: TrapezoidMove::new(
                (length - s).max(0.0),
                speed_in,
                0.0,
                limits.speed,
                limits.acceleration,
            ),
            yaw,
        });
        walk
    }

    fn push(&mut self, phase: Phase) {
        self.starts.push(self.duration);
        self.duration += match phase {
            Phase::Leg { along, .. } => along.duration(),
            Phase::Turn { turn, .. } => turn.duration(),
        };
        self.phases.push(phase);
    }

    /// Seconds from the start to the end of the route.
    pub(crate) fn duration(&self) -> f64 {
        self.duration
    }

    /// The level `world_T_body` at `t` seconds (clamped to the walk: standing at the start
    /// before it, at the end after it).
    pub(crate) fn pose_at(&self, t: f64) -> Pose3 {
        let t = t.clamp(0.0, self.duration);
        let k = self.starts.partition_point(|&s| s <= t).max(1) - 1;
        let tau = t - self.starts[k];
        let (s, yaw) = match self.phases[k] {
            Phase::Leg { from, along, yaw } => (from + along.position(tau), yaw),
            Phase::Turn {
                from,
                arc_speed,
                yaw,
                sign,
                turn,
            } => (
                from + arc_speed * tau.min(turn.duration()),
                yaw + sign * turn.position(tau),
            ),
        };
        let p = self.route.point_at(s);
        Pose3::from_parts(
            Translation3::new(p.x, p.y, self.height),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw),
        )
    }
}
