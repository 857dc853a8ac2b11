//! The cells of the planning grid the robot can reach from where it stands: where an explored
//! map's random goals may be drawn.

use nalgebra::Vector2;
use pathfind::Components;
use slam_core::{BitGrid, Cell};

/// The free cells of a planning grid connected to one cell (pathfind's component labels: under
/// the no-corner-cutting rule the planner's 8-connected moves reach what 4-connected ones do).
pub(crate) struct ReachableCells {
    grid: BitGrid,
    components: Components,
    /// The component the robot stands in; `None` when no free cell is near it.
    component: Option<u32>,
}

impl ReachableCells {
    /// The free cells of `grid` (blocked: occupied, inflated or unknown) reachable from `from`
    /// (metres, map frame), or from the free cell nearest it within 1 m: an exploration may end
    /// at a frontier goal within the inflation of a wall. None when there is no such cell.
    pub(crate) fn from(grid: &BitGrid, from: Vector2<f64>) -> Self {
        let components = Components::new(grid);
        let component = nearest_free(grid, from, 1.0).map(|c| components.label(c));
        Self {
            grid: grid.clone(),
            components,
            component,
        }
    }

    /// Whether the robot can reach `p` (metres, map frame).
    pub(crate) fn contains(&self, p: Vector2<f64>) -> bool {
        self.grid.cell_at(p).is_some_and(|c| {
            !self.grid.is_blocked(c) && Some(self.components.label(c)) == self.component
        })
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
