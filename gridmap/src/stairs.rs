//! The cells of a flight of stairs, found from the walk over it and the map's points: treads
//! near the height the robot's feet passed at, rising between two floors, with room above them.
//!
//! A floor's obstacle band sees a flight as a wall on the floor it rises from (its lower steps
//! are in the band) and as a hole, read free or unknown, on the floor it reaches (its stairwell).
//! Neither is true: the flight is walkable only by a stairs controller. [`stairs_cells`] finds
//! its cells so that [`OccupancyGrid::mark_stairs`] can mark them on both floors' grids.

use std::collections::VecDeque;

use nalgebra::{Point3, Vector2};
use slam_core::{BitGrid, Cell};

use crate::error::{GridMapError, check};
use crate::occupancy::OccupancyGrid;

/// Settings of [`stairs_cells`]. Lengths in metres.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct StairsConfig {
    /// Cells up to this far from the walk's track (in plan view) are looked at, 1.0 m: a flight
    /// is 0.9-1.5 m wide and the robot walks up near its middle.
    pub reach: f64,
    /// A tread is a point within this of the ground height the walk passed at the nearest
    /// point of its track, 0.2 m: the track's ground is a ramp through the step tops, never
    /// more than about a rise (0.15-0.2 m) from the step under it.
    pub tread_tolerance: f64,
    /// Above a tread nothing may stand from this height over the walk's ground height, 0.45 m:
    /// a cell holds at most one riser (treads are deeper than a cell), whose top stands at most
    /// a rise (0.15-0.2 m) above the tread plus the track's error (a rise and a half) below it...
    pub clear_from: f64,
    /// ...up to this height, 0.8 m: a wall or a rail beside the flight is no tread.
    pub headroom: f64,
    /// A tread needs at least this many points in its cell, 2.
    pub min_points: u32,
    /// A tread lies at least this above the lower floor and this below the upper one, 0.08 m
    /// (the obstacle band's lowest height): the floors at either end are no stairs.
    pub min_step: f64,
}

impl Default for StairsConfig {
    fn default() -> Self {
        Self {
            reach: 1.0,
            tread_tolerance: 0.2,
            clear_from: 0.45,
            headroom: 0.8,
            min_points: 2,
            min_step: 0.08,
        }
    }
}

impl StairsConfig {
    /// Every length finite and positive, the tread's window below the clear one and that below
    /// the headroom, and `min_points` at least 1.
    ///
    /// # Errors
    /// [`GridMapError::InvalidConfig`] naming the first bad setting.
    pub fn validate(&self) -> Result<(), GridMapError> {
        for (setting, v) in [
            ("StairsConfig::reach", self.reach),
            ("StairsConfig::tread_tolerance", self.tread_tolerance),
            ("StairsConfig::min_step", self.min_step),
        ] {
            check(v.is_finite() && v > 0.0, setting, v, "finite and positive")?;
        }
        check(
            self.clear_from.is_finite() && self.clear_from >= self.tread_tolerance,
            "StairsConfig::clear_from",
            self.clear_from,
            "finite and at least StairsConfig::tread_tolerance",
        )?;
        check(
            self.headroom.is_finite() && self.headroom > self.clear_from,
            "StairsConfig::headroom",
            self.headroom,
            "finite and above StairsConfig::clear_from",
        )?;
        check(
            self.min_points >= 1,
            "StairsConfig::min_points",
            f64::from(self.min_points),
            "at least 1",
        )
    }
}

/// A walk over a flight of stairs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Climb<'a> {
    /// The ground under the robot along the walk (metres, the map's frame, z up), in walking
    /// order, up or down: at least two positions, best from its last poses on one floor to its
    /// first on the other.
    pub track: &'a [Point3<f64>],
    /// The ground height of the floor the flight rises from (metres).
    pub lower: f64,
    /// The ground height of the floor it reaches (metres).
    pub upper: f64,
}

/// The cells of `grid` (its size and placement) on the flight `climb` walked over, from the
/// map's `points`, each with the position of the sensor that saw it (the map frame; points far
/// from the walk are passed over): cells within
/// [`StairsConfig::reach`] of the walk's track holding a tread (points near the ground height
/// the walk passed at there, most of them between the two floors' heights: a floor or a slab
/// edge beside the flight is none) with nothing above
/// it up to [`StairsConfig::headroom`] nor below it down to the lower floor (a solid flight
/// hides what lies under its treads: stairs with open risers are not found), joined to a cell the track crosses on the flight. Cells
/// no point fell in (a step hides the back of the tread below it) are taken for the flight
/// where they lie between its treads.
///
/// ```
/// use gridmap::{CellState, Climb, OccupancyGrid, StairsConfig, stairs_cells};
/// use nalgebra::{Point3, Vector2};
/// use slam_core::GridGeometry;
///
/// // Ten steps of 0.2 m rise and 0.3 m tread along +x from x = 1 m, 1 m wide (y 0 to 1),
/// // between a floor at 0 m and one at 2 m; their tops sampled every 5 cm.
/// let mut points = Vec::new();
/// for i in 0..100 {
///     for j in 0..20 {
///         let (x, y) = (1.0 + 0.03 * i as f64 + 0.015, 0.05 * j as f64 + 0.025);
///         let step = ((x - 1.0) / 0.3).floor() + 1.0;
///         let tread = Point3::new(x, y, 0.2 * step);
///         // Seen from 1 m behind and 0.8 m above.
///         points.push((tread, tread + nalgebra::Vector3::new(-1.0, 0.0, 0.8)));
///     }
/// }
/// // The walk up its middle, the ground a ramp through the step tops.
/// let track: Vec<Point3<f64>> =
///     (0..=10).map(|k| Point3::new(0.85 + 0.3 * k as f64, 0.5, 0.2 * k as f64)).collect();
/// let geometry = GridGeometry::try_new(Vector2::new(-1.0, -1.0), 0.1)?;
/// let mut grid = OccupancyGrid::new(60, 30, geometry, CellState::Free)?;
/// let climb = Climb { track: &track, lower: 0.0, upper: 2.0 };
/// let stairs = stairs_cells(&grid, points, &climb, &StairsConfig::default())?;
/// grid.mark_stairs(&stairs)?;
/// let on = |x: f64, y: f64| grid.state(stairs.cell_at(Vector2::new(x, y)).unwrap());
/// assert_eq!(on(2.0, 0.5), CellState::Stairs);
/// assert_eq!(on(0.5, 0.5), CellState::Free, "the floor before the flight");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
///
/// # Errors
/// [`GridMapError::InvalidConfig`] for bad settings, a track of fewer than two positions, or
/// floors not finite or less than two [`StairsConfig::min_step`] apart;
/// [`GridMapError::NonFinitePosition`] for a position of the track that is not finite.
pub fn stairs_cells(
    grid: &OccupancyGrid,
    points: impl IntoIterator<Item = (Point3<f64>, Point3<f64>)>,
    climb: &Climb<'_>,
    config: &StairsConfig,
) -> Result<BitGrid, GridMapError> {
    check_climb(climb, config)?;
    let geometry = *grid.geometry();
    let mut stairs = BitGrid::new(grid.width(), grid.height())?.with_geometry(geometry);
    let Some(window) = Window::around(grid, climb.track, config.reach) else {
        return Ok(stairs);
    };
    let between = |z: f64| z >= climb.lower + config.min_step && z <= climb.upper - config.min_step;
    // The walk's ground height at each cell's nearest point of the track (NaN beyond reach).
    let expected: Vec<f64> = window
        .cells()
        .map(|c| ground_near(climb.track, geometry.cell_center(c), config.reach))
        .collect();
    let CellCounts {
        treads,
        floor,
        upper_floor,
        blocked,
    } = CellCounts::of(points, &window, &geometry, &expected, climb, config);
    // A wall's foot beside the flight adds a few points at a floor's height to a tread's cell;
    // a floor's cell is mostly floor.
    let tread: Vec<bool> = (0..expected.len())
        .map(|i| treads[i] >= config.min_points && treads[i] > floor[i] && !blocked[i])
        .collect();
    // A step hides the back of the tread below it from a sensor climbing past, and the
    // robot's own body the treads under it: cells (next to) no point fell in are passed
    // through, and kept where they lie between treads of the flight.
    let unseen: Vec<bool> = (0..expected.len())
        .map(|i| treads[i] + floor[i] < config.min_points && !blocked[i] && expected[i].is_finite())
        .collect();
    let passable = |i: usize| tread[i] || unseen[i];
    // Treads joined to the cells the walk crossed on the flight.
    let mut queue: VecDeque<usize> = climb
        .track
        .iter()
        .filter(|p| between(p.z))
        .filter_map(|p| window.index(&geometry, *p))
        .filter(|&i| passable(i))
        .collect();
    let mut reached = vec![false; expected.len()];
    for &i in &queue {
        reached[i] = true;
    }
    while let Some(i) = queue.pop_front() {
        for j in window.neighbours(i) {
            if passable(j) && !reached[j] {
                reached[j] = true;
                queue.push_back(j);
            }
        }
    }
    let treads_reached: Vec<bool> = (0..expected.len())
        .map(|i| reached[i] && tread[i])
        .collect();
    // The back of the top step, under the robot as it steps off, is seen by no one (a
    // climbing sensor sees the risers ahead and the treads behind): an unseen strip between
    // the flight's treads and the upper floor counts as well. The lower floor before the foot
    // is seen from afar.
    let edges: Vec<bool> = (0..expected.len())
        .map(|i| treads_reached[i] || upper_floor[i] >= config.min_points.max(treads[i] + 1))
        .collect();
    for (i, r) in reached.iter_mut().enumerate() {
        if *r && !treads_reached[i] && window.between_marked(i, &edges, GAP_CELLS) {
            // Kept only where a tread is its neighbour within the gap on one side.
            *r = window.near_marked(i, &treads_reached, GAP_CELLS);
        } else if !treads_reached[i] {
            *r = *r && window.between_marked(i, &treads_reached, GAP_CELLS);
        }
    }
    let treads_reached: Vec<bool> = (0..expected.len())
        .map(|i| treads_reached[i] || reached[i])
        .collect();
    // A lone cell between two of its cells is the flight too, whatever stood in it.
    for (i, r) in reached.iter_mut().enumerate() {
        *r = treads_reached[i]
            || (expected[i].is_finite() && window.between_marked(i, &treads_reached, 1));
    }
    for (i, c) in window.cells().enumerate() {
        if reached[i] {
            stairs.set(c, true)?;
        }
    }
    Ok(stairs)
}

/// Settings valid, and a climb of at least two finite positions between two floors apart.
fn check_climb(climb: &Climb<'_>, config: &StairsConfig) -> Result<(), GridMapError> {
    config.validate()?;
    check(
        climb.track.len() >= 2,
        "Climb::track",
        climb.track.len() as f64,
        "at least two positions",
    )?;
    if let Some(index) = climb
        .track
        .iter()
        .position(|p| !p.iter().all(|v| v.is_finite()))
    {
        return Err(GridMapError::NonFinitePosition { index });
    }
    check(
        climb.lower.is_finite(),
        "Climb::lower",
        climb.lower,
        "finite",
    )?;
    check(
        climb.upper.is_finite() && climb.upper - climb.lower > 2.0 * config.min_step,
        "Climb::upper",
        climb.upper,
        "finite and more than twice StairsConfig::min_step above Climb::lower",
    )?;
    Ok(())
}

/// An unseen strip up to this many cells wide between two treads is taken for the flight
/// (0.3 m at 0.1 m cells: a tread's depth).
const GAP_CELLS: i64 = 3;

/// What the points in each cell of the window say (indexed as [`Window::cells`]).
struct CellCounts {
    /// Points near the walk's ground between the floors (treads and risers).
    treads: Vec<u32>,
    /// Points near the walk's ground at a floor's height (the floors at the flight's ends, a
    /// slab beside it), or a ceiling at a tread's height seen from below.
    floor: Vec<u32>,
    /// Those of `floor` at the upper floor's height.
    upper_floor: Vec<u32>,
    /// Something stands above the walk's ground within the headroom, or was seen under it.
    blocked: Vec<bool>,
}

impl CellCounts {
    /// The counts of `points` (each with its sensor's position) in `window`'s cells, whose
    /// walk's ground heights are `expected`.
    fn of(
        points: impl IntoIterator<Item = (Point3<f64>, Point3<f64>)>,
        window: &Window,
        geometry: &slam_core::GridGeometry,
        expected: &[f64],
        climb: &Climb<'_>,
        config: &StairsConfig,
    ) -> Self {
        // Where the walk stood on a floor (beyond the flight's foot or top, or on its top step with
        // its front feet on the upper floor), a tread must be seen from above: a ceiling at that
        // height is seen from below only.
        let margin = 0.5 * config.min_step;
        let at_end: Vec<bool> = expected
            .iter()
            .map(|&z| z <= climb.lower + margin || z >= climb.upper - margin)
            .collect();
        // Per cell: points near the walk's ground between the floors (treads and risers) and at a
        // floor's height (the floors at the flight's ends, a slab beside it).
        let mut counts = CellCounts {
            treads: vec![0; expected.len()],
            floor: vec![0; expected.len()],
            upper_floor: vec![0; expected.len()],
            blocked: vec![false; expected.len()],
        };
        let between =
            |z: f64| z >= climb.lower + config.min_step && z <= climb.upper - config.min_step;
        for (p, seen_from) in points {
            let Some(i) = window.index(geometry, p) else {
                continue;
            };
            let dz = p.z - expected[i];
            if dz < -config.tread_tolerance {
                // A surface with something seen under it, down to the lower floor, is no step (a
                // solid flight hides what is below its treads): a ceiling beside or beyond the
                // flight's top, seen from the steps or the floor under it. (What lies below the
                // lower floor, a flight under this one, is not looked at.)
                if dz < -config.clear_from && p.z >= climb.lower - config.min_step {
                    counts.blocked[i] = true;
                }
            } else if dz <= config.tread_tolerance {
                if between(p.z) && (seen_from.z > p.z || !at_end[i]) {
                    counts.treads[i] += 1;
                } else {
                    counts.floor[i] += 1;
                    if p.z > climb.upper - config.min_step {
                        counts.upper_floor[i] += 1;
                    }
                }
            } else if (config.clear_from..=config.headroom).contains(&dz) {
                counts.blocked[i] = true;
            }
        }
        counts
    }
}

/// The ground height of `track` at its nearest point to `at` in plan view, or NaN when that is
/// farther than `reach`.
fn ground_near(track: &[Point3<f64>], at: Vector2<f64>, reach: f64) -> f64 {
    let mut best = (reach * reach, f64::NAN);
    for w in track.windows(2) {
        let (a, b) = (w[0].xy().coords, w[1].xy().coords);
        let ab = b - a;
        let len2 = ab.norm_squared();
        let t = if len2 > 0.0 {
            ((at - a).dot(&ab) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let d2 = (a + ab * t - at).norm_squared();
        if d2 <= best.0 {
            best = (d2, w[0].z + (w[1].z - w[0].z) * t);
        }
    }
    best.1
}

/// The rectangle of a grid's cells around a track, row by row.
struct Window {
    x0: u32,
    y0: u32,
    w: u32,
    h: u32,
}

impl Window {
    /// The cells within `reach` of `track`'s bounding box, clipped to `grid`; `None` when none.
    fn around(grid: &OccupancyGrid, track: &[Point3<f64>], reach: f64) -> Option<Self> {
        let lo = track
            .iter()
            .fold(Vector2::repeat(f64::INFINITY), |m, p| m.inf(&p.xy().coords))
            - Vector2::repeat(reach);
        let hi = track
            .iter()
            .fold(Vector2::repeat(f64::NEG_INFINITY), |m, p| {
                m.sup(&p.xy().coords)
            })
            + Vector2::repeat(reach);
        let g = grid.geometry();
        let (x0, y0) = g.cell_coords(lo);
        let (x1, y1) = g.cell_coords(hi);
        let (x0, y0) = (x0.max(0), y0.max(0));
        let x1 = x1.min(i64::from(grid.width()) - 1);
        let y1 = y1.min(i64::from(grid.height()) - 1);
        if x0 > x1 || y0 > y1 {
            return None;
        }
        Some(Self {
            x0: x0 as u32,
            y0: y0 as u32,
            w: (x1 - x0 + 1) as u32,
            h: (y1 - y0 + 1) as u32,
        })
    }

    /// Its cells, row by row.
    fn cells(&self) -> impl Iterator<Item = Cell> + '_ {
        (0..self.h).flat_map(move |y| (0..self.w).map(move |x| Cell::new(self.x0 + x, self.y0 + y)))
    }

    /// The index of the cell holding `p`, if in the window.
    fn index(&self, g: &slam_core::GridGeometry, p: Point3<f64>) -> Option<usize> {
        let (x, y) = g.cell_coords(p.xy().coords);
        let (x, y) = (x - i64::from(self.x0), y - i64::from(self.y0));
        (x >= 0 && y >= 0 && x < i64::from(self.w) && y < i64::from(self.h))
            .then(|| y as usize * self.w as usize + x as usize)
    }

    /// Whether cell `i` has a `marked` cell on both sides along a row, a column or a diagonal,
    /// each within `gap` cells.
    fn between_marked(&self, i: usize, marked: &[bool], gap: i64) -> bool {
        let (x, y) = ((i % self.w as usize) as i64, (i / self.w as usize) as i64);
        let at = |dx: i64, dy: i64| {
            let (nx, ny) = (x + dx, y + dy);
            nx >= 0
                && ny >= 0
                && nx < i64::from(self.w)
                && ny < i64::from(self.h)
                && marked[ny as usize * self.w as usize + nx as usize]
        };
        [(1, 0), (0, 1), (1, 1), (1, -1)].iter().any(|&(dx, dy)| {
            (1..=gap).any(|a| at(a * dx, a * dy)) && (1..=gap).any(|b| at(-b * dx, -b * dy))
        })
    }

    /// Whether a `marked` cell lies within `gap` cells of cell `i` along a row, a column or a
    /// diagonal.
    fn near_marked(&self, i: usize, marked: &[bool], gap: i64) -> bool {
        let (x, y) = ((i % self.w as usize) as i64, (i / self.w as usize) as i64);
        (-gap..=gap).any(|dy| {
            (-gap..=gap).any(|dx| {
                let (nx, ny) = (x + dx, y + dy);
                (dx == 0 || dy == 0 || dx.abs() == dy.abs())
                    && nx >= 0
                    && ny >= 0
                    && nx < i64::from(self.w)
                    && ny < i64::from(self.h)
                    && marked[ny as usize * self.w as usize + nx as usize]
            })
        })
    }

    /// The 8 neighbours of index `i` in the window.
    fn neighbours(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        let (x, y) = ((i % self.w as usize) as i64, (i / self.w as usize) as i64);
        (-1..=1_i64).flat_map(move |dy| {
            (-1..=1_i64).filter_map(move |dx| {
                let (nx, ny) = (x + dx, y + dy);
                ((dx, dy) != (0, 0)
                    && nx >= 0
                    && ny >= 0
                    && nx < i64::from(self.w)
                    && ny < i64::from(self.h))
                .then(|| ny as usize * self.w as usize + nx as usize)
            })
        })
    }
}
