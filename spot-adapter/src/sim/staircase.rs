//! A straight staircase joining one floor of a building to the next: solid steps rising from
//! the lower floor (a landing midway on a tall storey), and the stairwell they need in the slab
//! above.

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
/// A storey of more rises than this is climbed in two runs with a landing between them
/// (building codes cap one run at 16-18 rises).
pub const MAX_RISES_WITHOUT_LANDING: usize = 16;
/// Depth of a landing along the flight (metres): as deep as the flight is wide, as codes ask.
pub(crate) const LANDING_DEPTH: f64 = STAIR_WIDTH;

/// A landing midway up a flight: the step after `after` steps is a platform `depth` metres
/// deep instead of a tread.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Landing {
    /// The steps below the landing; the landing is step `after + 1`, as high as it.
    pub after: usize,
    /// Its depth along the flight (metres).
    pub depth: f64,
}

/// A straight flight of steps in a room, from the floor at `base_z` up one storey.
///
/// Step `k` (1 to [`Staircase::steps`]) is a solid box from the lower floor up to
/// `base_z + k * rise`, its tread `tread` metres deep along [`Staircase::up`] (the
/// [`Landing`]'s, when it has one, `depth` deep); the last step's far edge meets the upper
/// floor, one rise above it. The slab above has a stairwell over the flight (see
/// [`Staircase::stairwell`]).
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
    /// The landing midway, on a storey of more than [`MAX_RISES_WITHOUT_LANDING`] rises.
    pub landing: Option<Landing>,
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
        let rises = (storey / STEP_RISE).round().max(2.0) as usize;
        Self {
            room,
            foot,
            up,
            base_z,
            rise: storey / rises as f64,
            tread: STEP_TREAD,
            width: STAIR_WIDTH,
            steps: rises - 1,
            landing: (rises > MAX_RISES_WITHOUT_LANDING).then_some(Landing {
                after: rises / 2 - 1,
                depth: LANDING_DEPTH,
            }),
        }
    }

    /// The same flight in one run, its landing made steps.
    pub(crate) fn without_landing(self) -> Self {
        Self {
            landing: None,
            ..self
        }
    }

    /// Horizontal length from the foot to the upper floor's edge (metres).
    #[must_use]
    pub fn run(&self) -> f64 {
        self.step_front(self.steps + 1)
    }

    /// Distance from the foot to the front edge of step `k` (1-based; `steps + 1`: the upper
    /// floor's edge), metres.
    fn step_front(&self, k: usize) -> f64 {
        let front = (k.max(1) - 1) as f64 * self.tread;
        match self.landing {
            Some(l) if k > l.after + 1 => front + l.depth - self.tread,
            _ => front,
        }
    }

    /// The step (1-based; 0: the lower floor, `steps + 1`: the upper one) under `u` metres
    /// past the foot along the flight.
    fn step_at(&self, u: f64) -> usize {
        if u < 0.0 {
            return 0;
        }
        (1..=self.steps + 1)
            .rev()
            .find(|&k| u >= self.step_front(k))
            .unwrap_or(0)
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
                let (min, max) = self.span(self.step_front(k), self.step_front(k + 1), 0.0);
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
        self.base_z + self.step_at(u) as f64 * self.rise
    }

    /// The height of the ground a body walking the flight follows (metres), `u` metres past
    /// the foot along it: a line through the middles of the treads at their heights, from half
    /// a tread before the foot (the lower floor) to half a tread past the top (the upper one),
    /// level over a landing but for half a tread at each of its ends. Never more than half a
    /// rise from [`Staircase::surface_at`].
    #[must_use]
    pub fn walk_height(&self, u: f64) -> f64 {
        self.walk_at(u).0
    }

    /// The slope of [`Staircase::walk_height`] at `u` (rise over run; 0 off the flight and on
    /// a landing's level part).
    #[must_use]
    pub fn walk_slope(&self, u: f64) -> f64 {
        self.walk_at(u).1
    }

    /// [`Staircase::walk_height`] and [`Staircase::walk_slope`] at `u`, from one pass over the
    /// line's knots.
    #[must_use]
    pub fn walk_at(&self, u: f64) -> (f64, f64) {
        let knots = self.walk_knots();
        let (first, last) = (knots[0], knots[knots.len() - 1]);
        if u < first.0 {
            return (first.1, 0.0);
        }
        if u >= last.0 {
            return (last.1, 0.0);
        }
        knots
            .windows(2)
            .find(|w| u >= w[0].0 && u < w[1].0)
            .map_or((last.1, 0.0), |w| {
                let slope = (w[1].1 - w[0].1) / (w[1].0 - w[0].0);
                (w[0].1 + slope * (u - w[0].0), slope)
            })
    }

    /// The knots (distance past the foot, height) of [`Staircase::walk_height`], in order.
    fn walk_knots(&self) -> Vec<(f64, f64)> {
        let half = 0.5 * self.tread;
        let mut knots = vec![(-half, self.base_z)];
        for k in 1..=self.steps + 1 {
            let (a, b) = (self.step_front(k), self.step_front(k + 1));
            let z = self.base_z + k as f64 * self.rise;
            if k == self.steps + 1 {
                knots.push((a + half, z));
            } else if b - a > self.tread + 1e-9 {
                knots.push((a + half, z));
                knots.push((b - half, z));
            } else {
                knots.push((0.5 * (a + b), z));
            }
        }
        knots
    }
}
