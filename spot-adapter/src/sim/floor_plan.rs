//! The building's ground-truth floor plan: which plan-view points a walking robot cannot occupy,
//! as a predicate and as a [`BitGrid`].

use nalgebra::Vector2;
use slam_core::{BitGrid, GridGeometry};

use crate::sim::SimError;
use crate::sim::building::Building;
use crate::sim::staircase::Staircase;

/// Boxes whose bottom lies at or below this height (metres) block a walking robot; lintels above
/// doors (2.1 m) do not. Spot is 0.84 m tall with its LiDAR, so anything lower than this
/// obstructs it.
pub const OBSTACLE_HEIGHT: f64 = 1.0;

impl Building {
    /// Whether the plan-view point `p` (metres) lies inside a wall, pillar or piece of furniture,
    /// or outside the building.
    #[must_use]
    pub fn is_obstacle(&self, p: Vector2<f64>) -> bool {
        if !(p.x > 0.0 && p.y > 0.0 && p.x < self.size.x && p.y < self.size.y) {
            return true;
        }
        self.boxes
            .iter()
            .any(|b| b.min.z < OBSTACLE_HEIGHT && b.contains_xy(p))
    }

    /// Distance (metres) from `p` to the nearest obstacle footprint or the building's outline;
    /// zero inside an obstacle.
    #[must_use]
    pub fn clearance(&self, p: Vector2<f64>) -> f64 {
        let outline =
            p.x.min(p.y)
                .min(self.size.x - p.x)
                .min(self.size.y - p.y)
                .max(0.0);
        self.boxes
            .iter()
            .filter(|b| b.min.z < OBSTACLE_HEIGHT)
            .map(|b| {
                let dx = (b.min.x - p.x).max(p.x - b.max.x).max(0.0);
                let dy = (b.min.y - p.y).max(p.y - b.max.y).max(0.0);
                dx.hypot(dy)
            })
            .fold(outline, f64::min)
    }

    /// Distance (metres) from `p` to the nearest obstacle of floor `floor` (its walls and
    /// furniture, a flight rising from it, the stairwell of a flight arriving at it) or to the
    /// building's outline, the flights in `except` (indices into
    /// [`Building::staircases`]; an index past them leaves none out) left out; zero inside an
    /// obstacle. Floor 0 with no flight
    /// left out is [`Building::clearance`].
    #[must_use]
    pub fn clearance_on(&self, floor: usize, p: Vector2<f64>, except: Option<usize>) -> f64 {
        let z = self.floor_height(floor);
        let outline =
            p.x.min(p.y)
                .min(self.size.x - p.x)
                .min(self.size.y - p.y)
                .max(0.0);
        let to_rect = |min: Vector2<f64>, max: Vector2<f64>| {
            let dx = (min.x - p.x).max(p.x - max.x).max(0.0);
            let dy = (min.y - p.y).max(p.y - max.y).max(0.0);
            dx.hypot(dy)
        };
        // The skipped flight's steps, made once: this runs every control step on a flight.
        let skipped = except
            .and_then(|i| self.staircases.get(i))
            .map_or_else(Vec::new, crate::sim::Staircase::step_boxes);
        let own_step = |b: &crate::sim::SolidBox| {
            b.kind == crate::sim::BoxKind::Step && skipped.iter().any(|s| s == b)
        };
        let boxes = self
            .boxes
            .iter()
            .filter(|b| b.min.z < z + OBSTACLE_HEIGHT && b.max.z > z + 0.01 && !own_step(b))
            .map(|b| to_rect(b.min.xy().coords, b.max.xy().coords));
        let wells = self
            .staircases
            .iter()
            .enumerate()
            .filter(|(i, f)| {
                Some(*i) != except && (f.base_z + f.climb() - z).abs() < 0.5 * OBSTACLE_HEIGHT
            })
            .map(|(_, f)| {
                let (min, max) = f.stairwell();
                to_rect(min, max)
            });
        boxes.chain(wells).fold(outline, f64::min)
    }

    /// The ground-truth occupancy grid at `resolution` metres per cell, covering the building
    /// with its corner at the world origin. A cell is blocked when any obstacle footprint
    /// overlaps it (conservative, so thin walls are never lost) or it lies outside the building.
    ///
    /// # Errors
    /// [`SimError::Grid`] for a resolution that is not finite and positive or a grid too
    /// large.
    pub fn occupancy_grid(&self, resolution: f64) -> Result<BitGrid, SimError> {
        self.occupancy_grid_on(0, resolution)
    }

    /// [`Building::occupancy_grid`] of floor `floor`: the obstacles [`Building::clearance_on`]
    /// counts there (its walls and furniture, a flight rising from it, the stairwell of a
    /// flight arriving at it). A floor the building does not have reads as its slab would:
    /// free but for the outline.
    ///
    /// # Errors
    /// As [`Building::occupancy_grid`].
    pub fn occupancy_grid_on(&self, floor: usize, resolution: f64) -> Result<BitGrid, SimError> {
        let z = self.floor_height(floor);
        let geometry = GridGeometry::try_new(Vector2::zeros(), resolution)?;
        let width = (self.size.x / resolution).ceil().max(1.0);
        let height = (self.size.y / resolution).ceil().max(1.0);
        if width > f64::from(u32::MAX) || height > f64::from(u32::MAX) {
            return Err(slam_core::GridError::TooLarge {
                width: u32::MAX,
                height: u32::MAX,
                max_cells: slam_core::MAX_GRID_CELLS,
            }
            .into());
        }
        let (w, h) = (width as u32, height as u32);
        let mut grid = BitGrid::new(w, h)?.with_geometry(geometry);
        let cells = |lo: f64, hi: f64, n: u32| {
            let a = (lo / resolution).floor().max(0.0) as u32;
            let b = ((hi / resolution).ceil() as i64 - 1).clamp(0, i64::from(n) - 1) as u32;
            (a.min(n - 1), b)
        };
        let boxes = self
            .boxes
            .iter()
            .filter(|b| b.min.z < z + OBSTACLE_HEIGHT && b.max.z > z + 0.01)
            .map(|b| (b.min.xy().coords, b.max.xy().coords));
        let wells = self
            .staircases
            .iter()
            .filter(|f| (f.base_z + f.climb() - z).abs() < 0.5 * OBSTACLE_HEIGHT)
            .map(Staircase::stairwell);
        for (min, max) in boxes.chain(wells) {
            let (x0, x1) = cells(min.x, max.x, w);
            let (y0, y1) = cells(min.y, max.y, h);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    grid.set(slam_core::Cell::new(x, y), true)?;
                }
            }
        }
        // Cells reaching past the building's outline (the last row and column when the size is
        // not a multiple of the resolution) are outside.
        for y in 0..h {
            for x in 0..w {
                let far = Vector2::new(f64::from(x + 1), f64::from(y + 1)) * resolution;
                if far.x > self.size.x + 1e-9 || far.y > self.size.y + 1e-9 {
                    grid.set(slam_core::Cell::new(x, y), true)?;
                }
            }
        }
        Ok(grid)
    }
}
