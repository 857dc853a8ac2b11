//! A tour of every floor of a building: a lap of the ground floor's corridor, up the stairs, a
//! lap of each floor above, and back down to where it started; the body's height follows the
//! steps and it pitches with the flight.

use nalgebra::{Translation3, UnitQuaternion, Vector2, Vector3};
use slam_core::Pose3;
use slam_core::io::StampedPose;

use crate::sim::SimError;
use crate::sim::building::Building;
use crate::sim::route::Route;
use crate::sim::setting_checks::require_positive;
use crate::sim::staircase::Staircase;
use crate::sim::stairs_gait::stairs_ground;

/// Speed along the slope of a flight (m/s): Spot's stairs mode climbs at about 0.3-0.5 m/s.
pub const STAIRS_SPEED: f64 = 0.4;
/// From the door into the room before turning towards the flight (metres).
const ENTRY_DEPTH: f64 = 0.8;
/// Past the flight's top edge on the upper floor before turning (metres).
const TOP_LANDING: f64 = 0.45;
/// Half the length over which the body's pitch follows the slope (metres): about half of
/// Spot's body, so it tilts as its front legs reach the flight, not at one instant.
const PITCH_HALF_BASE: f64 = 0.3;

/// A change of height along the tour: the body's ground follows `flight`'s
/// [`Staircase::walk_height`] from arc length `s0` to `s1`, up it or down.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Ramp {
    s0: f64,
    s1: f64,
    flight: Staircase,
    up: bool,
}

impl Ramp {
    /// How far past the flight's foot along it arc length `s` is (clamped to the ramp's ends).
    fn along(&self, s: f64) -> f64 {
        let f = &self.flight;
        let d = (s - self.s0).clamp(0.0, self.s1 - self.s0);
        let half = 0.5 * f.tread;
        if self.up {
            -half + d
        } else {
            f.run() + half - d
        }
    }

    /// The ground's height at arc length `s` (clamped to the ramp's ends).
    fn height(&self, s: f64) -> f64 {
        self.flight.walk_height(self.along(s))
    }
}

/// The tour through every floor of a building, as a plan-view [`Route`] and the height of the
/// ground under it; walked, the body takes the flights' steps with their jolts and nods
/// ([`STAIRS_JOLT`](crate::sim::STAIRS_JOLT), [`STAIRS_NOD`](crate::sim::STAIRS_NOD)).
///
/// The ground height follows each flight's [`Staircase::walk_height`], a line through its step
/// tops (level on a landing): never more than half a rise from the true step under the body.
#[derive(Clone, Debug, PartialEq)]
pub struct FloorsTour {
    route: Route,
    ramps: Vec<Ramp>,
}

/// The plan-view waypoints of one flight in both directions and where on them it starts.
struct FlightLegs {
    /// From the corridor, through the door, to the upper floor's landing.
    up: Vec<Vector2<f64>>,
    /// From the landing back along the free side of the stairwell, out to the corridor.
    out_upstairs: Vec<Vector2<f64>>,
}

impl FloorsTour {
    /// The tour of `building`: a corridor lap on every floor, climbing each staircase in turn,
    /// then down every staircase back to the start, the middle of the south corridor.
    ///
    /// # Errors
    /// [`SimError::InvalidConfig`] when the route cannot be made (never for a generated
    /// building).
    pub fn new(building: &Building) -> Result<Self, SimError> {
        let corners = *building.corridor_loop();
        let start = 0.5 * (corners[0] + corners[1]);
        let mut points = vec![start];
        points.extend(loop_path(&corners, start, start, true));
        let mut ramps = Vec::new();
        let flights = building.staircases();
        let legs: Vec<FlightLegs> = flights
            .iter()
            .map(|f| flight_legs(f, building.corridor_width()))
            .collect();
        for (flight, leg) in flights.iter().zip(&legs) {
            let here = points[points.len() - 1];
            points.extend(loop_path(&corners, here, leg.up[0], false));
            push_flight(&mut points, &mut ramps, &leg.up, flight, true);
            points.extend(leg.out_upstairs.iter().copied());
            let door = points[points.len() - 1];
            points.extend(loop_path(&corners, door, door, true));
        }
        for (flight, leg) in flights.iter().zip(&legs).rev() {
            let here = points[points.len() - 1];
            let back_in: Vec<Vector2<f64>> = leg.out_upstairs.iter().rev().copied().collect();
            points.extend(loop_path(&corners, here, back_in[0], false));
            points.extend(back_in);
            let down: Vec<Vector2<f64>> = leg.up.iter().rev().copied().collect();
            push_flight(&mut points, &mut ramps, &down, flight, false);
        }
        let here = points[points.len() - 1];
        points.extend(loop_path(&corners, here, start, false));
        let route = Route::new(points.clone(), false)?;
        // Arc lengths of the ramps: `push_flight` left plan points; measure them on the route.
        let ramps = ramps
            .into_iter()
            .map(|(at, r): (usize, Ramp)| {
                let s = arc_length(&points, at);
                Ramp {
                    s0: s + r.s0,
                    s1: s + r.s1,
                    ..r
                }
            })
            .collect();
        Ok(Self { route, ramps })
    }

    /// The plan-view route.
    #[must_use]
    pub fn route(&self) -> &Route {
        &self.route
    }

    /// Height of the ground under the body (metres) at arc length `s` of the route.
    #[must_use]
    pub fn ground_height(&self, s: f64) -> f64 {
        let mut z = 0.0;
        for r in &self.ramps {
            if s < r.s0 {
                return z;
            }
            if s <= r.s1 {
                return r.height(s);
            }
            z = r.height(r.s1);
        }
        z
    }

    /// The body's jolt at arc length `s`: the height (metres) and the nod (radians, nose up)
    /// a body taking the steps adds to the ground's smooth line; zero off the flights.
    fn jolt(&self, s: f64) -> (f64, f64) {
        self.ramps
            .iter()
            .find(|r| (r.s0..=r.s1).contains(&s))
            .map_or((0.0, 0.0), |r| {
                let u = r.along(s);
                let ground = stairs_ground(&r.flight, u);
                (ground.height - ground.line, ground.nod)
            })
    }

    /// Whether arc length `s` is on a flight.
    #[must_use]
    pub fn on_stairs(&self, s: f64) -> bool {
        self.ramps.iter().any(|r| (r.s0..=r.s1).contains(&s))
    }

    /// The tour walked at `speed` m/s on the floors and [`STAIRS_SPEED`] along the flights,
    /// sampled at `rate` Hz: `world_T_body` with the body `body_height` above the ground,
    /// pitched with the flight, and whether each sample is on a flight.
    ///
    /// # Errors
    /// [`SimError::InvalidConfig`] for a speed or rate that is not finite and positive.
    pub fn walk(
        &self,
        speed: f64,
        rate: f64,
        body_height: f64,
    ) -> Result<(Vec<StampedPose>, Vec<bool>), SimError> {
        require_positive(&[
            ("speed", speed, "finite and positive (m/s)"),
            ("rate", rate, "finite and positive (hertz)"),
        ])?;
        let len = self.route.length();
        let (mut poses, mut stairs) = (Vec::new(), Vec::new());
        let (mut s, mut k, mut last_yaw) = (0.0_f64, 0_u32, None::<f64>);
        loop {
            let slope = (self.ground_height(s + PITCH_HALF_BASE)
                - self.ground_height(s - PITCH_HALF_BASE))
                / (2.0 * PITCH_HALF_BASE);
            let mut yaw = self.route.pose_at(s).rotation.angle();
            if let Some(prev) = last_yaw {
                yaw = prev + (yaw - prev + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI;
            }
            last_yaw = Some(yaw);
            let p = self.route.point_at(s);
            // Nose up on the way up: a negative turn about the body's y axis.
            let (jolt, nod) = self.jolt(s);
            let rotation = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw)
                * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), -(slope.atan() + nod));
            poses.push(StampedPose {
                stamp: f64::from(k) / rate,
                pose: Pose3::from_parts(
                    Translation3::new(p.x, p.y, self.ground_height(s) + jolt + body_height),
                    rotation,
                ),
            });
            let climbing = self.on_stairs(s);
            stairs.push(climbing);
            if s >= len {
                break;
            }
            // Along the slope at the stairs speed: slower in plan view by the slope's cosine.
            let ground = if climbing {
                STAIRS_SPEED * slope.atan().cos()
            } else {
                speed
            };
            s = (s + ground / rate).min(len);
            k += 1;
        }
        Ok((poses, stairs))
    }
}

/// The plan-view legs through `flight`'s room for a corridor `corridor_width` wide.
fn flight_legs(flight: &Staircase, corridor_width: f64) -> FlightLegs {
    let room = &flight.room;
    let inward = room.inward;
    let across = Vector2::new(inward.y.abs(), inward.x.abs());
    let at = |a: f64, depth: f64| across * a + inward * (room.door.dot(&inward) + depth);
    let corridor = room.door - inward * (0.5 * corridor_width);
    let entry = room.door + inward * ENTRY_DEPTH;
    let lane = flight.foot.dot(&across);
    let landing = flight.top() + inward * TOP_LANDING;
    let landing_depth = (landing - room.door).dot(&inward);
    // The free side: between the stairwell's edge and the far side wall.
    let (well_lo, well_hi) = flight.stairwell();
    let (room_lo, room_hi) = (room.min.dot(&across), room.max.dot(&across));
    let free = if lane - room_lo < room_hi - lane {
        0.5 * (well_hi.dot(&across) + room_hi)
    } else {
        0.5 * (well_lo.dot(&across) + room_lo)
    };
    FlightLegs {
        up: vec![corridor, room.door, entry, at(lane, ENTRY_DEPTH), landing],
        out_upstairs: vec![
            at(free, landing_depth),
            at(free, ENTRY_DEPTH),
            entry,
            room.door,
            corridor,
        ],
    }
}

/// Append `legs` (which cross `flight` once, up or down) to `points`, and the flight's ramp
/// with its arc lengths relative to the waypoint where the straight leg over it begins.
fn push_flight(
    points: &mut Vec<Vector2<f64>>,
    ramps: &mut Vec<(usize, Ramp)>,
    legs: &[Vector2<f64>],
    flight: &Staircase,
    up: bool,
) {
    points.extend(legs.iter().copied());
    // The straight leg over the flight: lane point to landing going up, the reverse going down.
    let (from, k) = if up {
        (legs[3], points.len() - 2)
    } else {
        (legs[0], points.len() - legs.len())
    };
    let half = 0.5 * flight.tread;
    let to_foot = (flight.foot - from).norm();
    let to_top = (flight.top() - from).norm();
    let (s0, s1) = if up {
        (to_foot - half, to_top + half)
    } else {
        (to_top - half, to_foot + half)
    };
    let ramp = Ramp {
        s0,
        s1,
        flight: *flight,
        up,
    };
    ramps.push((k, ramp));
}

/// Arc length of the polyline `points` at waypoint `k`, as [`Route::new`] measures it
/// (repeated points add nothing).
fn arc_length(points: &[Vector2<f64>], k: usize) -> f64 {
    points[..=k].windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// Waypoints walking counter-clockwise along the corridor loop's centre line from `from` to
/// `to` (both on it): the corners passed, then `to`. With `full`, a whole lap when they are
/// the same point; without, nothing then.
fn loop_path(
    corners: &[Vector2<f64>; 4],
    from: Vector2<f64>,
    to: Vector2<f64>,
    full: bool,
) -> Vec<Vector2<f64>> {
    let sides: Vec<f64> = (0..4)
        .map(|k| (corners[(k + 1) % 4] - corners[k]).norm())
        .collect();
    let perimeter: f64 = sides.iter().sum();
    // Arc position of a point on the loop, and the arc position of each corner.
    let mut corner_at = [0.0; 4];
    for k in 1..4 {
        corner_at[k] = corner_at[k - 1] + sides[k - 1];
    }
    let position = |p: Vector2<f64>| {
        (0..4)
            .map(|k| {
                let (a, b) = (corners[k], corners[(k + 1) % 4]);
                let d = (b - a) / sides[k];
                let t = (p - a).dot(&d).clamp(0.0, sides[k]);
                ((a + d * t - p).norm(), corner_at[k] + t)
            })
            .min_by(|x, y| x.0.total_cmp(&y.0))
            .map_or(0.0, |(_, s)| s)
    };
    let (a, mut b) = (position(from), position(to));
    if b < a - 1e-9 || (full && (b - a).abs() <= 1e-9) {
        b += perimeter;
    }
    let mut out: Vec<Vector2<f64>> = (0..8)
        .map(|k| {
            (
                corner_at[k % 4] + if k < 4 { 0.0 } else { perimeter },
                corners[k % 4],
            )
        })
        .filter(|&(s, _)| s > a + 1e-9 && s < b - 1e-9)
        .map(|(_, c)| c)
        .collect();
    out.push(to);
    out
}
