//! The cells of the planning grid the robot can reach from where it stands: where an explored
//! map's random goals may be drawn.

use std::collections::VecDeque;

use nalgebra::Vector2;
use slam_core::{BitGrid, Cell};

/// The free cells of a planning grid 4-connected to one cell (a 4-connected walk is one the
/// planner's 8-connected moves without corner cutting can make too).
pub(crate) struct ReachableCells {
    grid: BitGrid,
}

impl ReachableCells {
    /// The free cells of `grid` (blocked: occupied, inflated or unknown) reachable from `from`
    /// (metres, map frame), or from the free cell nearest it within 1 m: an exploration may end
    /// at a frontier goal within the inflation of a wall. None when there is no such cell.
    pub(crate) fn from(grid: &BitGrid, from: Vector2<f64>) -> Self {
        // Blocked where not reached: the same type as the grid, and cheap to query.
        let mut reached = grid.clone();
        for y in 0..grid.height() {
            reached.row_words_mut(y).fill(u64::MAX);
        }
        if let Some(first) = nearest_free(grid, from, 1.0) {
            let mut queue = VecDeque::from([first]);
            let _ = reached.set(first, false);
            while let Some(c) = queue.pop_front() {
                let (x, y) = (i64::from(c.x), i64::from(c.y));
                for (nx, ny) in [(x + 1, y), (x - 1, y), (x, y + 1), (x, y - 1)] {
                    if grid.is_free_signed(nx, ny) && !reached.is_free_signed(nx, ny) {
                        let n = Cell::new(nx as u32, ny as u32);
                        let _ = reached.set(n, false);
                        queue.push_back(n);
                    }
                }
            }
        }
        Self { grid: reached }
    }

    /// Whether the robot can reach `p` (metres, map frame).
    pub(crate) fn contains(&self, p: Vector2<f64>) -> bool {
        self.grid
            .cell_at(p)
            .is_some_and(|c| !self.grid.is_blocked(c))
    }
}

/// The free cell of `grid` nearest `p` (metres) within `radius` metres.
fn nearest_free(grid: &BitGrid, p: Vector2<f64>, radius: f64) -> Option<Cell> {
    let geometry = grid.geometry();
    let (cx, cy) = geometry.cell_coords(p);
    let r = (radius / geometry.resolution).ceil() as i64;
    (-r..=r)
        .flat_map(|dy| (-r..=r).map(move |dx| (cx + dx, cy + dy)))
        .filter(|&(x, y)| grid.is_free_signed(x, y))
        .map(|(x, y)| Cell::new(x as u32, y as u32))
        .map(|c| ((grid.cell_center(c) - p).norm(), c))
        .filter(|&(d, _)| d <= radius)
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, c)| c)
}
