//! A straight staircase joining one floor of a building to the next: solid steps rising from
//! the lower floor, and the stairwell they need in the slab above.

use nalgebra::{Point3, Vector2};

use crate::sim::building::Room;
use crate::sim::solid_box::{BoxKind, SolidBox};

/// Height of a step, about (metres); the real rise divides the storey height evenly.
pub(crate) const STEP_RISE: f64 = 0.18;
/// Depth of a step's tread (metres).
pub(crate) const STEP_TREAD: f64 = 0.28;
/// Width of the flight (metres).
pub(crate) const STAIR_WIDTH: f64 = 1.2;
/// The stairwell reaches this far past the flight's sides and foot (metres), so that the slab
/// edge does not sit exactly over a step's edge.
pub(crate) const STAIRWELL_MARGIN: f64 = 0.1;

/// A straight flight of steps in a room, from the floor at `base_z` up one storey.
///
/// Step `k` (1 to [`Staircase::steps`]) is a solid box from the lower floor up to
/// `base_z + k * rise`, its tread `tread` metres deep along [`Staircase::up`]; the last step's
/// far edge meets the upper floor, one rise above it. The slab above has a stairwell over the
/// flight (see [`Staircase::stairwell`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Staircase {
    /// The room it stands in (the same room on every floor).
    pub room: Room,
    /// Plan-view centre of the first step's front edge (metres).
    pub foot: Vector2<f64>,
    /// Unit plan-view direction up the flight.
    pub up: Vector2<f64>,
    /// Height of the lower floor (metres).
    pub base_z: f64,
    /// Height of each step (metres): the storey height over the number of rises.
    pub rise: f64,
    /// Depth of each tread (metres).
    pub tread: f64,
    /// Width (metres).
    pub width: f64,
    /// Number of step boxes; the flight climbs `steps + 1` rises, the last onto the upper floor.
    pub steps: usize,
}

impl Staircase {
    /// A flight at `foot` going `up`, climbing `storey` metres from `base_z` in rises of
    /// about [`STEP_RISE`].
    pub(crate) fn new(
        room: Room,
        foot: Vector2<f64>,
        up: Vector2<f64>,
        base_z: f64,
        storey: f64,
    ) -> Self {
        let rises = (storey / STEP_RISE).round().max(2.0);
        Self {
            room,
            foot,
            up,
            base_z,
            rise: storey / rises,
            tread: STEP_TREAD,
            width: STAIR_WIDTH,
            steps: rises as usize - 1,
        }
    }

    /// Horizontal length from the foot to the upper floor's edge (metres).
    #[must_use]
    pub fn run(&self) -> f64 {
        self.steps as f64 * self.tread
    }

    /// Height climbed from the lower floor to the upper one (metres).
    #[must_use]
    pub fn climb(&self) -> f64 {
        (self.steps + 1) as f64 * self.rise
    }

    /// Plan-view centre of the edge where the flight meets the upper floor.
    #[must_use]
    pub fn top(&self) -> Vector2<f64> {
        self.foot + self.up * self.run()
    }

    /// The plan-view axis-aligned rectangle (min, max) of the part of the flight from `a` to
    /// `b` metres past the foot, widened by `margin` on each side.
    fn span(&self, a: f64, b: f64, margin: f64) -> (Vector2<f64>, Vector2<f64>) {
        let across = Vector2::new(-self.up.y, self.up.x) * (0.5 * self.width + margin);
        let (p, q) = (self.foot + self.up * a, self.foot + self.up * b);
        let corners = [p + across, p - across, q + across, q - across];
        let min = corners
            .iter()
            .fold(Vector2::repeat(f64::INFINITY), |m, c| m.inf(c));
        let max = corners
            .iter()
            .fold(Vector2::repeat(f64::NEG_INFINITY), |m, c| m.sup(c));
        (min, max)
    }

    /// The step boxes, the lowest first.
    #[must_use]
    pub fn step_boxes(&self) -> Vec<SolidBox> {
        (1..=self.steps)
            .map(|k| {
                let (min, max) = self.span((k - 1) as f64 * self.tread, k as f64 * self.tread, 0.0);
                SolidBox {
                    min: Point3::new(min.x, min.y, self.base_z),
                    max: Point3::new(max.x, max.y, self.base_z + k as f64 * self.rise),
                    kind: BoxKind::Step,
                }
            })
            .collect()
    }

    /// The plan-view rectangle (min, max) left open in the slab above: the flight widened by
    /// 0.1 m at its sides and foot, ending where the upper floor begins.
    #[must_use]
    pub fn stairwell(&self) -> (Vector2<f64>, Vector2<f64>) {
        self.span(-STAIRWELL_MARGIN, self.run(), STAIRWELL_MARGIN)
    }

    /// The true height of the walking surface (metres) `u` metres past the foot along the
    /// flight's centre line: the lower floor before it, the step's top on it, the upper floor
    /// past it.
    #[must_use]
    pub fn surface_at(&self, u: f64) -> f64 {
        if u < 0.0 {
            self.base_z
        } else if u >= self.run() {
            self.base_z + self.climb()
        } else {
            self.base_z + ((u / self.tread).floor() + 1.0) * self.rise
        }
    }
}
