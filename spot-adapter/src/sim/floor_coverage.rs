//! How much of a building's reachable floor a map knows free: the figure an exploration is
//! judged by against the simulator's floor plan.

use std::collections::VecDeque;

use gridmap::{CellState, OccupancyGrid};
use nalgebra::{Point3, Vector2};
use slam_core::{Cell, Pose3};

use crate::sim::Building;

/// Side of the cells the floor plan is sampled at (metres): the navigator's grid resolution.
const FLOOR_CELL: f64 = 0.1;

/// The reachable floor of a building and the part of it a map knows free, in cells of 0.1 m.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FloorCoverage {
    /// Cells whose centre is at least the inflation from every obstacle and 4-connected to the
    /// start through such cells.
    pub reachable: usize,
    /// Those of them the map knows free.
    pub known_free: usize,
}

impl FloorCoverage {
    /// `known_free / reachable`, 0 when nothing is reachable.
    #[must_use]
    pub fn share(&self) -> f64 {
        if self.reachable == 0 {
            0.0
        } else {
            self.known_free as f64 / self.reachable as f64
        }
    }

    /// The reachable floor's area (square metres).
    #[must_use]
    pub fn reachable_area(&self) -> f64 {
        self.reachable as f64 * FLOOR_CELL * FLOOR_CELL
    }
}

/// The floor of `building` free at `inflation` (metres; cell centres that far from every
/// obstacle, boxes included) and 4-connected to `start` (world frame), and how much of it
/// `occupancy` (in the map frame, placed in the world by `world_t_map`) knows free. A closed
/// door cuts off what lies behind it: that part is not reachable, so not counted.
#[must_use]
pub fn floor_coverage(
    building: &Building,
    start: Vector2<f64>,
    world_t_map: &Pose3,
    occupancy: &OccupancyGrid,
    inflation: f64,
) -> FloorCoverage {
    let size = building.size();
    let (w, h) = ((size.x / FLOOR_CELL) as i64, (size.y / FLOOR_CELL) as i64);
    let centre = |x: i64, y: i64| Vector2::new(x as f64 + 0.5, y as f64 + 0.5) * FLOOR_CELL;
    let inside = |x: i64, y: i64| x >= 0 && y >= 0 && x < w && y < h;
    let free = |x: i64, y: i64| inside(x, y) && building.clearance(centre(x, y)) >= inflation;
    let first = (
        (start.x / FLOOR_CELL).floor() as i64,
        (start.y / FLOOR_CELL).floor() as i64,
    );
    let mut coverage = FloorCoverage {
        reachable: 0,
        known_free: 0,
    };
    if !inside(first.0, first.1) {
        return coverage;
    }
    let mut seen = vec![false; (w * h) as usize];
    let mut queue = VecDeque::from([first]);
    seen[(first.1 * w + first.0) as usize] = true;
    let map_t_world = world_t_map.inverse();
    while let Some((x, y)) = queue.pop_front() {
        coverage.reachable += 1;
        let c = centre(x, y);
        let p = map_t_world * Point3::new(c.x, c.y, 0.0);
        let (cx, cy) = occupancy.geometry().cell_coords(p.coords.xy());
        if let (Ok(cx), Ok(cy)) = (u32::try_from(cx), u32::try_from(cy))
            && occupancy.state(Cell::new(cx, cy)) == CellState::Free
        {
            coverage.known_free += 1;
        }
        for (dx, dy) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
            let (nx, ny) = (x + dx, y + dy);
            if free(nx, ny) && !seen[(ny * w + nx) as usize] {
                seen[(ny * w + nx) as usize] = true;
                queue.push_back((nx, ny));
            }
        }
    }
    coverage
}
