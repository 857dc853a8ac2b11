//! Routes through the building and how the robot walks them: a polyline followed at constant
//! speed, with a heading that turns smoothly through corners.

use nalgebra::{Translation3, UnitQuaternion, Vector2, Vector3};
use slam_core::io::StampedPose;
use slam_core::{Pose2, Pose3};

use crate::sim::SimError;
use crate::sim::building::Building;

/// Half the length of the chord whose direction gives the heading (metres): the robot starts
/// turning this far before a corner and finishes this far after it.
const HEADING_CHORD: f64 = 0.6;

/// A route: a polyline of plan-view waypoints (metres); a closed route ends where it starts.
#[derive(Clone, Debug, PartialEq)]
pub struct Route {
    points: Vec<Vector2<f64>>,
    /// Arc length at each waypoint.
    cumulative: Vec<f64>,
    closed: bool,
}

impl Route {
    /// A route through `points` in order. With `closed`, the route returns to the first point.
    ///
    /// # Errors
    /// [`SimError::InvalidConfig`] for fewer than two points, non-finite points, or a route
    /// of zero length.
    pub fn new(mut points: Vec<Vector2<f64>>, closed: bool) -> Result<Self, SimError> {
        if points.len() < 2 || !points.iter().all(|p| p.x.is_finite() && p.y.is_finite()) {
            return Err(SimError::invalid(
                "points",
                points.len() as f64,
                "at least two, all finite",
            ));
        }
        points.dedup_by(|a, b| (*a - *b).norm() < 1e-9);
        if closed && points.len() > 1 && (points[0] - points[points.len() - 1]).norm() > 1e-9 {
            points.push(points[0]);
        }
        let mut cumulative = vec![0.0];
        for w in points.windows(2) {
            cumulative.push(cumulative[cumulative.len() - 1] + (w[1] - w[0]).norm());
        }
        if cumulative[cumulative.len() - 1] <= 0.0 {
            return Err(SimError::invalid("route length", 0.0, "positive (metres)"));
        }
        Ok(Self {
            points,
            cumulative,
            closed,
        })
    }

    /// One lap of the building's corridor loop, counter-clockwise, starting and ending in the
    /// middle of the south corridor. Its length is the loop's perimeter (at least 100 m with the
    /// default [`BuildingConfig`](crate::sim::BuildingConfig)).
    #[must_use]
    pub fn corridor_loop(building: &Building) -> Self {
        let c = building.corridor_loop();
        let start = 0.5 * (c[0] + c[1]);
        let points = vec![start, c[1], c[2], c[3], c[0], start];
        // Four distinct corners: `new` cannot fail; fall back to a straight line if it did.
        Self::new(points, true).unwrap_or_else(|_| Self {
            points: vec![c[0], c[1]],
            cumulative: vec![0.0, (c[1] - c[0]).norm()],
            closed: false,
        })
    }

    /// Waypoints (metres); a closed route repeats its first point at the end.
    #[must_use]
    pub fn points(&self) -> &[Vector2<f64>] {
        &self.points
    }

    /// Whether the route returns to its start.
    #[must_use]
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// Length (metres).
    #[must_use]
    pub fn length(&self) -> f64 {
        self.cumulative[self.cumulative.len() - 1]
    }

    /// The point at arc length `s` (clamped to the route, or wrapped on a closed route).
    #[must_use]
    pub fn point_at(&self, s: f64) -> Vector2<f64> {
        let len = self.length();
        let s = if self.closed {
            s.rem_euclid(len)
        } else {
            s.clamp(0.0, len)
        };
        let k = self
            .cumulative
            .partition_point(|&c| c <= s)
            .clamp(1, self.points.len() - 1);
        let (a, b) = (self.points[k - 1], self.points[k]);
        let seg = self.cumulative[k] - self.cumulative[k - 1];
        if seg <= 0.0 {
            return a;
        }
        a + (b - a) * ((s - self.cumulative[k - 1]) / seg)
    }

    /// The plan-view pose at arc length `s`: on the polyline, facing along the chord from
    /// `s - 0.6 m` to `s + 0.6 m`, so the heading turns smoothly through corners (Spot walks
    /// sideways a little there, as it can).
    #[must_use]
    pub fn pose_at(&self, s: f64) -> Pose2 {
        let p = self.point_at(s);
        let mut chord = self.point_at(s + HEADING_CHORD) - self.point_at(s - HEADING_CHORD);
        if chord.norm() < 1e-9 {
            // Only when the whole route is shorter than the chord: face along it.
            chord = self.points[self.points.len() - 1] - self.points[0];
        }
        Pose2::new(p, chord.y.atan2(chord.x))
    }

    /// The route walked at `speed` m/s, sampled at `rate` Hz: stamps (seconds from 0) and
    /// `world_T_body` with the body `body_height` metres above the floor, level. The last
    /// sample is the route's end (the start again for a closed route).
    ///
    /// # Errors
    /// [`SimError::InvalidConfig`] for a speed or rate that is not finite and positive.
    pub fn walk(
        &self,
        speed: f64,
        rate: f64,
        body_height: f64,
    ) -> Result<Vec<StampedPose>, SimError> {
        if !(speed.is_finite() && speed > 0.0) {
            return Err(SimError::invalid(
                "speed",
                speed,
                "finite and positive (m/s)",
            ));
        }
        if !(rate.is_finite() && rate > 0.0) {
            return Err(SimError::invalid(
                "rate",
                rate,
                "finite and positive (hertz)",
            ));
        }
        let len = self.length();
        let step = speed / rate;
        let n = (len / step).ceil() as usize;
        let mut out = Vec::with_capacity(n + 1);
        let mut last_yaw: Option<f64> = None;
        for k in 0..=n {
            let s = (k as f64 * step).min(len);
            // At the very end of a closed route take the heading just before the wrap so that
            // it continues the lap instead of jumping to the start's.
            let pose = self.pose_at(if self.closed && k == n { len - 1e-6 } else { s });
            let mut yaw = pose.rotation.angle();
            let t = self.point_at(s);
            // Keep yaw continuous (no jumps of 2 pi), though the pose does not care.
            if let Some(prev) = last_yaw {
                yaw = prev + (yaw - prev + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI;
            }
            last_yaw = Some(yaw);
            out.push(StampedPose {
                stamp: k as f64 / rate,
                pose: Pose3::from_parts(
                    Translation3::new(t.x, t.y, body_height),
                    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw),
                ),
            });
        }
        Ok(out)
    }
}
