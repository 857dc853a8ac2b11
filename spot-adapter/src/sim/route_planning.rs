//! A route between two points over the building's ground-truth floor plan: the floor plan's
//! grid inflated by the clearance (`gridmap::inflate`), a shortest path on it
//! (`pathfind::AStar`), and the turning points a straight collision-free segment cannot skip
//! (`pathfind::filter_path`).

use gridmap::inflate;
use nalgebra::Vector2;
use pathfind::{AStar, filter_path};
use slam_core::{Cell, Planner};

use crate::sim::SimError;
use crate::sim::building::Building;
use crate::sim::route::Route;

/// Settings of [`Route::between`].
#[derive(Clone, Debug, PartialEq)]
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

impl Route {
    /// A collision-free route from `start` to `goal` (plan-view metres) that keeps
    /// `config.clearance` from every obstacle: A* over the building's ground-truth grid
    /// inflated by the clearance, then the filtered path's turning points; the route enters
    /// and leaves through the centres of the start's and the goal's cells.
    ///
    /// # Errors
    /// [`SimError::BlockedEndpoint`] when start or goal is within the clearance of an
    /// obstacle or outside the building, [`SimError::NoRoute`] when they are not connected,
    /// [`SimError::InvalidConfig`] for a clearance that is negative or not finite, and
    /// [`SimError::Grid`] for an unusable resolution.
    pub fn between(
        building: &Building,
        start: Vector2<f64>,
        goal: Vector2<f64>,
        config: &RouteConfig,
    ) -> Result<Self, SimError> {
        if !(config.clearance.is_finite() && config.clearance >= 0.0) {
            return Err(SimError::invalid(
                "clearance",
                config.clearance,
                "finite and non-negative (metres)",
            ));
        }
        // A point of a free cell lies within half a diagonal of its centre, and so does an
        // obstacle's edge of a blocked cell's: inflating by the clearance plus 1.5 cells keeps
        // every point of every free cell at least the clearance from every obstacle. The route
        // runs through cell centres joined by segments whose every touched cell is free, so all
        // of it lies in free cells.
        let grid = inflate(
            &building.occupancy_grid(config.resolution)?,
            config.clearance + 1.5 * config.resolution,
        )
        .map_err(SimError::NavigationGrid)?;
        let to_cell = |which: &'static str, p: Vector2<f64>| {
            grid.cell_at(p)
                .filter(|&c| !grid.is_blocked(c))
                .ok_or(SimError::BlockedEndpoint {
                    which,
                    x: p.x,
                    y: p.y,
                })
        };
        let (s, g): (Cell, Cell) = (to_cell("start", start)?, to_cell("goal", goal)?);
        let path = AStar::new(&grid)
            .plan(s, g)
            .map_err(SimError::Planner)?
            .ok_or(SimError::NoRoute)?;
        let filtered = filter_path(&grid, &path);
        let mut kept = vec![start];
        kept.extend(filtered.waypoints.iter().map(|&c| grid.cell_center(c)));
        kept.push(goal);
        kept.dedup_by(|a, b| (*a - *b).norm() < 1e-9);
        if kept.len() < 2 {
            // A route needs length; stay in place over a tiny step.
            kept = vec![start, start + Vector2::new(1e-3, 0.0)];
        }
        Route::new(kept, false)
    }
}

/// The length (metres) of the shortest way from `start` to `goal` (plan-view metres) over the
/// building's ground-truth floor plan at `resolution`, with every cell whose centre lies within
/// `inflation` of a wall's cell blocked, as a navigator's planning grid blocks them: A*'s path
/// through the cell centres with every turn a straight line of sight can skip skipped
/// (`pathfind::filter_path`), joined to `start` and `goal`. `None` when an endpoint lies in a
/// blocked cell or outside the building, or the two are not connected. The figure a walk to
/// `goal` is measured against: [`Route::between`] keeps a wider berth and can go round.
///
/// # Errors
/// [`SimError::NavigationGrid`] for an `inflation` that is negative or not finite,
/// [`SimError::Grid`] for an unusable resolution, [`SimError::Planner`] when the planner
/// fails.
pub fn shortest_length(
    building: &Building,
    start: Vector2<f64>,
    goal: Vector2<f64>,
    inflation: f64,
    resolution: f64,
) -> Result<Option<f64>, SimError> {
    let grid = inflate(&building.occupancy_grid(resolution)?, inflation)
        .map_err(SimError::NavigationGrid)?;
    let free = |p: Vector2<f64>| grid.cell_at(p).filter(|&c| !grid.is_blocked(c));
    let (Some(s), Some(g)) = (free(start), free(goal)) else {
        return Ok(None);
    };
    let Some(path) = AStar::new(&grid).plan(s, g).map_err(SimError::Planner)? else {
        return Ok(None);
    };
    let filtered = filter_path(&grid, &path);
    let mut points = vec![start];
    points.extend(filtered.waypoints.iter().map(|&c| grid.cell_center(c)));
    points.push(goal);
    Ok(Some(points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()))
}

impl Route {
    /// A collision-free route visiting `waypoints` in order (plan-view metres), each leg planned
    /// as in [`Route::between`]; with `closed`, a last leg returns to the first waypoint. For
    /// tours that enter rooms, e.g. through [`Room::entry_point`](crate::sim::Room::entry_point)s.
    ///
    /// # Errors
    /// As [`Route::between`] for any leg; [`SimError::InvalidConfig`] for fewer than two
    /// waypoints.
    pub fn through(
        building: &Building,
        waypoints: &[Vector2<f64>],
        closed: bool,
        config: &RouteConfig,
    ) -> Result<Self, SimError> {
        if waypoints.len() < 2 {
            return Err(SimError::invalid(
                "waypoints",
                waypoints.len() as f64,
                "at least two points for a tour",
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

impl Building {
    /// A `size`-metre cube of [`BoxKind::Obstacle`](crate::sim::BoxKind::Obstacle) on the
    /// route from `from` to `goal` (as [`Route::between`] plans it): halfway along, shifted
    /// sideways as little as needed for the goal to stay reachable with `config`'s clearance;
    /// `None` when no such place lies 2 m from both ends. The box is not added: pass it to
    /// [`Building::add_box`].
    #[must_use]
    pub fn obstacle_on_route(
        &self,
        from: Vector2<f64>,
        goal: Vector2<f64>,
        size: f64,
        config: &RouteConfig,
    ) -> Option<crate::sim::SolidBox> {
        let route = Route::between(self, from, goal, config).ok()?;
        let at = route.point_at(0.5 * route.length());
        if !(size.is_finite() && size > 0.0) || (at - from).norm() < 2.0 || (at - goal).norm() < 2.0
        {
            return None;
        }
        let ahead = route.point_at(0.5 * route.length() + 0.2) - at;
        let side = Vector2::new(-ahead.y, ahead.x).try_normalize(1e-12)?;
        let half = 0.5 * size;
        for shift in [0.0, 0.2, -0.2, 0.4, -0.4, 0.6, -0.6] {
            let c = at + side * shift;
            let solid = crate::sim::SolidBox {
                min: nalgebra::Point3::new(c.x - half, c.y - half, 0.0),
                max: nalgebra::Point3::new(c.x + half, c.y + half, size),
                kind: crate::sim::BoxKind::Obstacle,
            };
            let mut trial = self.clone();
            if trial.add_box(solid).is_ok()
                && trial.clearance(from) >= 0.5
                && Route::between(&trial, from, goal, config).is_ok()
            {
                return Some(solid);
            }
        }
        None
    }
}
