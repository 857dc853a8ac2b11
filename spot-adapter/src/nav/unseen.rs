//! What blocks the way and the LiDAR no longer sees: the live obstacles that shut a path the
//! map alone leaves open, when the last scan shows none of them.
//!
//! A person who walked past close by leaves the cells they stood on occupied in the live layer:
//! the cells within a couple of metres of the sensor lie under its lowest beam, and a beam
//! clears only where it passes low over a cell (see [`LiveLayerConfig::clear_below`]), so no
//! scan taken from there clears them. Standing still, the robot would wait for them in vain.
//!
//! [`LiveLayerConfig::clear_below`]: gridmap::LiveLayerConfig::clear_below

use gridmap::{CellState, LiveLayer, LocalCell};
use slam_core::Cell;

/// The live obstacle cells (occupied in the live layer, not on the static map) that block a cell
/// of `blocked` (cells of the map's own path that the live layer blocks) as the planning grid
/// measures it: their points within `inflation` plus `margin` metres (its point margin), their
/// centres within `inflation` when no points are recorded; when the live layer's last scan saw none of them occupied: memories of
/// something that moved on, or that the sensor cannot see from here. `None` when the last scan
/// sees one of them (something stands there now: wait for it) or there are none.
// Cell offsets within a few cells of a map cell: the casts are exact.
pub(crate) fn unseen_blockers(
    live: &LiveLayer,
    blocked: &[Cell],
    (inflation, margin): (f64, f64),
) -> Option<Vec<Cell>> {
    let combined = live.combined();
    let map = live.static_map();
    let geometry = combined.geometry();
    // The planning grid measures from the points in each occupied cell, which lie up to half a
    // cell's diagonal nearer than its centre: search that much farther, then measure as it does.
    let (cells, margin) = (
        inflation / geometry.resolution,
        margin / geometry.resolution,
    );
    let reach = (cells + margin + std::f64::consts::FRAC_1_SQRT_2).ceil() as i64;
    let radius = cells + margin + 1e-9;
    let scan = live.last_local_grid();
    let (gx, gy) = geometry.cell_coords(
        scan.map_t_grid.translation.vector + nalgebra::Vector2::repeat(0.5 * scan.resolution),
    );
    let seen_occupied = |x: i64, y: i64| {
        let (lx, ly) = (x - gx, y - gy);
        (0..i64::from(scan.width)).contains(&lx)
            && (0..i64::from(scan.height)).contains(&ly)
            && scan.cells[(ly * i64::from(scan.width) + lx) as usize] == LocalCell::Obstacle
    };
    let mut blockers: Vec<Cell> = Vec::new();
    for b in blocked {
        for dy in -reach..=reach {
            for dx in -reach..=reach {
                let (x, y) = (i64::from(b.x) + dx, i64::from(b.y) + dy);
                if x < 0
                    || y < 0
                    || x >= i64::from(combined.width())
                    || y >= i64::from(combined.height())
                {
                    continue;
                }
                let c = Cell::new(x as u32, y as u32);
                let Some(points) = combined.extent(c) else {
                    continue;
                };
                let d = points.squared_distance_from_centre((dx, dy)).sqrt();
                if (if points.is_centre() { d + margin } else { d }) > radius
                    || map.state(c) == CellState::Occupied
                    || blockers.contains(&c)
                {
                    continue;
                }
                if seen_occupied(x, y) {
                    return None;
                }
                blockers.push(c);
            }
        }
    }
    (!blockers.is_empty()).then_some(blockers)
}

#[cfg(test)]
mod tests {
    use super::*;
    use gridmap::{LiveLayerConfig, OccupancyGrid};
    use slam_core::GridGeometry;

    #[test]
    fn only_live_obstacles_within_the_inflation_that_no_scan_sees_are_blockers() {
        let geometry = GridGeometry {
            origin: nalgebra::Vector2::zeros(),
            resolution: 0.1,
        };
        let mut map = OccupancyGrid::new(100, 100, geometry, CellState::Free).unwrap();
        // A wall cell on the map itself: never a blocker.
        map.set(Cell::new(50, 52), CellState::Occupied).unwrap();
        let mut live = LiveLayer::new(map, LiveLayerConfig::default()).unwrap();
        // Something marked (a person's cell, a stuck robot's mark): no scan saw it.
        live.mark(Cell::new(50, 50), CellState::Occupied, 1.0)
            .unwrap();
        assert_eq!(
            unseen_blockers(&live, &[Cell::new(50, 53)], (0.3, 0.05)),
            Some(vec![Cell::new(50, 50)])
        );
        // Farther than the inflation from every blocked cell: nothing.
        assert_eq!(
            unseen_blockers(&live, &[Cell::new(50, 54)], (0.3, 0.05)),
            None
        );
        assert_eq!(unseen_blockers(&live, &[], (0.3, 0.05)), None);
    }
}
