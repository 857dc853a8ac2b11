//! A route between two points over the building's ground-truth floor plan: A* on an inflated
//! occupancy grid, then line-of-sight shortcuts. A small planner of its own so that the
//! simulator does not depend on the `pathfind` crate; it is not meant for real maps.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use nalgebra::Vector2;
use slam_core::{BitGrid, Cell};

use crate::building::Building;
use crate::error::AdapterError;
use crate::route::Route;

/// Settings of [`Route::between`].
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct RouteConfig {
    /// Grid resolution (metres per cell), 0.1 m.
    pub resolution: f64,
    /// Distance kept from every obstacle (metres), 0.30 m: Spot's half-width plus 5 cm.
    pub clearance: f64,
}

impl Default for RouteConfig {
    fn default() -> Self {
        Self {
            resolution: 0.1,
            clearance: 0.30,
        }
    }
}

#[derive(Clone, Copy, PartialEq)]
struct Open {
    f: f64,
    cell: usize,
}
impl Eq for Open {}
impl Ord for Open {
    fn cmp(&self, other: &Self) -> Ordering {
        // Min-heap on f; ties broken by cell index for determinism.
        other
            .f
            .total_cmp(&self.f)
            .then_with(|| other.cell.cmp(&self.cell))
    }
}
impl PartialOrd for Open {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// The ground-truth grid with every cell within `radius` metres of an obstacle cell blocked.
fn inflated(grid: &BitGrid, radius: f64) -> Result<BitGrid, AdapterError> {
    let res = grid.geometry().resolution;
    let r = (radius / res).ceil() as i64;
    let offsets: Vec<(i64, i64)> = (-r..=r)
        .flat_map(|dy| (-r..=r).map(move |dx| (dx, dy)))
        .filter(|&(dx, dy)| ((dx * dx + dy * dy) as f64).sqrt() * res <= radius + 1e-9)
        .collect();
    let mut out = grid.clone();
    for y in 0..grid.height() {
        for x in 0..grid.width() {
            if !grid.is_blocked(Cell::new(x, y)) {
                continue;
            }
            for &(dx, dy) in &offsets {
                let (cx, cy) = (i64::from(x) + dx, i64::from(y) + dy);
                if grid.contains_signed(cx, cy) {
                    out.set(Cell::new(cx as u32, cy as u32), true)?;
                }
            }
        }
    }
    Ok(out)
}

/// Cells of a shortest 8-connected path (no corner cutting), start first; `None` if unreachable.
fn astar(grid: &BitGrid, start: Cell, goal: Cell) -> Option<Vec<Cell>> {
    let w = grid.width() as usize;
    let n = grid.len();
    let idx = |c: Cell| c.y as usize * w + c.x as usize;
    let cell = |i: usize| Cell::new((i % w) as u32, (i / w) as u32);
    let h = |i: usize| {
        let c = cell(i);
        let dx = f64::from(c.x.abs_diff(goal.x));
        let dy = f64::from(c.y.abs_diff(goal.y));
        dx.max(dy) + (std::f64::consts::SQRT_2 - 1.0) * dx.min(dy)
    };
    let mut g = vec![f64::INFINITY; n];
    let mut parent = vec![usize::MAX; n];
    let mut heap = BinaryHeap::new();
    let (s, t) = (idx(start), idx(goal));
    g[s] = 0.0;
    heap.push(Open { f: h(s), cell: s });
    while let Some(Open { f, cell: i }) = heap.pop() {
        if i == t {
            let mut path = vec![goal];
            let mut k = t;
            while k != s {
                k = parent[k];
                path.push(cell(k));
            }
            path.reverse();
            return Some(path);
        }
        if f > g[i] + h(i) + 1e-9 {
            continue;
        }
        let c = cell(i);
        let free = |dx: i64, dy: i64| grid.is_free_signed(i64::from(c.x) + dx, i64::from(c.y) + dy);
        for dy in -1i64..=1 {
            for dx in -1i64..=1 {
                if (dx == 0 && dy == 0) || !free(dx, dy) {
                    continue;
                }
                let diagonal = dx != 0 && dy != 0;
                if diagonal && !(free(dx, 0) && free(0, dy)) {
                    continue;
                }
                let j = ((i64::from(c.y) + dy) as usize) * w + (i64::from(c.x) + dx) as usize;
                let cost = g[i]
                    + if diagonal {
                        std::f64::consts::SQRT_2
                    } else {
                        1.0
                    };
                if cost < g[j] {
                    g[j] = cost;
                    parent[j] = i;
                    heap.push(Open {
                        f: cost + h(j),
                        cell: j,
                    });
                }
            }
        }
    }
    None
}

/// Whether the segment from `a` to `b` (metres) crosses only free cells, sampled every quarter
/// cell.
fn line_of_sight(grid: &BitGrid, a: Vector2<f64>, b: Vector2<f64>) -> bool {
    let geo = grid.geometry();
    let steps = ((b - a).norm() / (0.25 * geo.resolution)).ceil().max(1.0) as usize;
    (0..=steps).all(|k| {
        let p = a + (b - a) * (k as f64 / steps as f64);
        let (x, y) = geo.cell_coords(p);
        grid.is_free_signed(x, y)
    })
}

impl Route {
    /// A collision-free route from `start` to `goal` (plan-view metres) that keeps
    /// `config.clearance` from every obstacle: A* over the building's ground-truth grid
    /// inflated by the clearance, shortened by line-of-sight shortcuts.
    ///
    /// # Errors
    /// [`AdapterError::BlockedEndpoint`] when start or goal is within the clearance of an
    /// obstacle or outside the building, [`AdapterError::NoRoute`] when they are not connected,
    /// [`AdapterError::InvalidConfig`] for a clearance that is negative or not finite, and
    /// [`AdapterError::Grid`] for an unusable resolution.
    pub fn between(
        building: &Building,
        start: Vector2<f64>,
        goal: Vector2<f64>,
        config: &RouteConfig,
    ) -> Result<Self, AdapterError> {
        if !(config.clearance.is_finite() && config.clearance >= 0.0) {
            return Err(AdapterError::InvalidConfig(format!(
                "clearance {} m must be finite and non-negative",
                config.clearance
            )));
        }
        // A point of a free cell lies within half a diagonal of its centre, and so does an
        // obstacle's edge of a blocked cell's: inflating by the clearance plus 1.5 cells keeps
        // every point of every free cell at least the clearance from every obstacle.
        let grid = inflated(
            &building.occupancy_grid(config.resolution)?,
            config.clearance + 1.5 * config.resolution,
        )?;
        let geo = *grid.geometry();
        let to_cell = |which: &'static str, p: Vector2<f64>| {
            let (x, y) = geo.cell_coords(p);
            if grid.is_free_signed(x, y) {
                Ok(Cell::new(x as u32, y as u32))
            } else {
                Err(AdapterError::BlockedEndpoint {
                    which,
                    x: p.x,
                    y: p.y,
                })
            }
        };
        let (s, g) = (to_cell("start", start)?, to_cell("goal", goal)?);
        let cells = astar(&grid, s, g).ok_or(AdapterError::NoRoute)?;
        // Metric polyline: exact endpoints, cell centres between them.
        let mut pts: Vec<Vector2<f64>> = Vec::with_capacity(cells.len());
        pts.push(start);
        pts.extend(
            cells[1..cells.len().saturating_sub(1)]
                .iter()
                .map(|&c| geo.cell_center(c)),
        );
        pts.push(goal);
        let mut kept = vec![start];
        let mut anchor = 0;
        let mut k = 1;
        while k < pts.len() {
            if !line_of_sight(&grid, pts[anchor], pts[k]) {
                anchor = k - 1;
                kept.push(pts[anchor]);
            }
            k += 1;
        }
        kept.push(goal);
        if (start - goal).norm() < 1e-9 {
            // A route needs length; stay in place over a tiny step.
            kept = vec![start, start + Vector2::new(1e-3, 0.0)];
        }
        Route::new(kept, false)
    }
}

impl Route {
    /// A collision-free route visiting `waypoints` in order (plan-view metres), each leg planned
    /// as in [`Route::between`]; with `closed`, a last leg returns to the first waypoint. For
    /// tours that enter rooms, e.g. through [`Room::entry_point`](crate::Room::entry_point)s.
    ///
    /// # Errors
    /// As [`Route::between`] for any leg; [`AdapterError::InvalidConfig`] for fewer than two
    /// waypoints.
    pub fn through(
        building: &Building,
        waypoints: &[Vector2<f64>],
        closed: bool,
        config: &RouteConfig,
    ) -> Result<Self, AdapterError> {
        if waypoints.len() < 2 {
            return Err(AdapterError::InvalidConfig(
                "a tour needs at least two waypoints".into(),
            ));
        }
        let mut stops = waypoints.to_vec();
        if closed {
            stops.push(waypoints[0]);
        }
        let mut points = vec![stops[0]];
        for leg in stops.windows(2) {
            let route = Self::between(building, leg[0], leg[1], config)?;
            points.extend_from_slice(&route.points()[1..]);
        }
        Self::new(points, closed)
    }
}
