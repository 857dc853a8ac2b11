//! The thesis' path filter: drop every waypoint a straight, collision-free segment can skip.

use slam_core::{BitGrid, Cell, GridPath};

use crate::line_of_sight::line_of_sight;

/// A path reduced to the waypoints a robot must turn at.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FilteredPath {
    /// Start, turning points, goal.
    pub waypoints: Vec<Cell>,
    /// Euclidean length through the waypoints, in cells (multiply by the resolution for metres).
    pub length: f64,
    /// Turning points of the dense cell path (changes of step direction).
    pub turns_before: usize,
    /// Turning points after filtering (waypoints other than start and goal).
    pub turns_after: usize,
}

/// Filter `path` on `grid`: from each kept waypoint, walk along the dense path while the cells
/// stay in line of sight (see [`line_of_sight`]) and keep the last visible one. Works on paths of
/// any planner (dense or jump points).
#[must_use]
pub fn filter_path(grid: &BitGrid, path: &GridPath) -> FilteredPath {
    let cells = path.expand();
    let turns_before = count_turns(&cells);
    let mut waypoints = Vec::new();
    if let Some(&first) = cells.first() {
        waypoints.push(first);
        let mut anchor = 0;
        while anchor + 1 < cells.len() {
            // The next cell is always visible (a legal step); stop at the first hidden one.
            let mut best = anchor + 1;
            while best + 1 < cells.len() && line_of_sight(grid, cells[anchor], cells[best + 1]) {
                best += 1;
            }
            waypoints.push(cells[best]);
            anchor = best;
        }
    }
    let length = waypoints
        .windows(2)
        .map(|w| {
            let dx = f64::from(w[1].x) - f64::from(w[0].x);
            let dy = f64::from(w[1].y) - f64::from(w[0].y);
            dx.hypot(dy)
        })
        // From +0.0: `sum()` of no steps is -0.0.
        .fold(0.0, |a, b| a + b);
    let turns_after = waypoints.len().saturating_sub(2);
    FilteredPath {
        waypoints,
        length,
        turns_before,
        turns_after,
    }
}

fn count_turns(cells: &[Cell]) -> usize {
    let step = |a: Cell, b: Cell| {
        (
            i64::from(b.x) - i64::from(a.x),
            i64::from(b.y) - i64::from(a.y),
        )
    };
    cells
        .windows(3)
        .filter(|w| step(w[0], w[1]) != step(w[1], w[2]))
        .count()
}
