//! The jolts of a legged body on stairs: each step taken lifts (or drops) the body by part of
//! the step's rise at once, and the body nods as its front and hind legs take the step in turn.

use crate::sim::staircase::Staircase;

/// The share of each step's edge the body's height takes at once on a flight: its height is the
/// smooth walking line ([`Staircase::walk_height`]) plus this share of the true step's height
/// above that line, so it jumps by this share of a rise at every step edge (0.3: up to
/// 2.7 cm either side of the line on 0.18 m rises).
pub const STAIRS_JOLT: f64 = 0.3;
/// The body's nod on a flight's slope (radians, 1.5°): an extra pitch swinging once per tread,
/// nose up as the front legs reach the next step, down as the hind legs follow.
pub const STAIRS_NOD: f64 = 0.026;

/// The body's ground on `flight`, `u` metres past its foot along it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StairsGround {
    /// The smooth walking line's height ([`Staircase::walk_height`], metres).
    pub(crate) line: f64,
    /// Its slope ([`Staircase::walk_slope`], rise over run).
    pub(crate) slope: f64,
    /// The body's ground with the step jolts (metres).
    pub(crate) height: f64,
    /// The pitch the nod adds (radians, positive nose up going up the flight; zero off the
    /// flight's slopes and on a landing's level part).
    pub(crate) nod: f64,
}

/// [`StairsGround`] on `flight` at `u` metres past its foot.
pub(crate) fn stairs_ground(flight: &Staircase, u: f64) -> StairsGround {
    let (line, slope) = flight.walk_at(u);
    let height = line + STAIRS_JOLT * (flight.surface_at(u) - line);
    let nod = if slope == 0.0 {
        0.0
    } else {
        STAIRS_NOD * (std::f64::consts::TAU * u / flight.tread).sin()
    };
    StairsGround {
        line,
        slope,
        height,
        nod,
    }
}
