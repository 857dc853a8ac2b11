//! The stairs a walk over several floors took, as links between the floors' planning grids:
//! where each flight was entered and left, and its length, for [`FloorGraph`] to route over.
//!
//! [`FloorGraph`]: crate::nav::FloorGraph

use gridmap::FloorLevels;
use nalgebra::{Point3, Vector2};
use slam_core::{BitGrid, Cell, InvalidSetting};

use crate::nav::NavError;
use crate::nav::floor_route::{FloorCell, StairsLink};

/// Two crossings of one pair of floors whose feet lie within this of each other, and their
/// tops too, are one flight (metres): a walk up and back down the same stairs gives one link.
/// A flight is 1-1.5 m wide; two flights between the same floors stand further apart.
pub const SAME_FLIGHT: f64 = 1.5;

/// The stairs the walk through `positions` (in walking order, z up, the poses `floors` was
/// split from) took: for each change of floor, the link from the walk's last pose before it
/// whose cell is free on the grid of the floor it left, the cells around it too (the foot of
/// the flight, short of the steps, which that floor's grid holds as an obstacle) to its first
/// such pose after it on the grid of the floor it reached, with the walk's length between the
/// two (metres, in 3D). The link's `foot` is on the lower of the two floors by height,
/// whichever way the walk went. Crossings of the same flight ([`SAME_FLIGHT`]) give one link,
/// the shorter walk kept. A change whose ends have no free cell on their floors, within the
/// walk on those floors, gives no link (no route could use it).
///
/// `grids[k]` is floor `k`'s planning grid (blocked cells the robot cannot stand on), in the
/// frame of `positions`.
///
/// # Errors
/// [`NavError::NoSuchFloor`] when `grids` holds fewer grids than `floors` has floors;
/// [`NavError::InvalidConfig`] naming `positions` when there are fewer positions than the poses
/// `floors` was split from, or a position on the walk is not finite.
pub fn stairs_links(
    positions: &[Point3<f64>],
    floors: &FloorLevels,
    grids: &[&BitGrid],
) -> Result<Vec<StairsLink>, NavError> {
    Ok(stairs_links_with_walks(positions, floors, grids)?
        .into_iter()
        .map(|(link, _)| link)
        .collect())
}

/// A link and the walk over it from its foot to its top.
pub(crate) type LinkWithWalk = (StairsLink, Vec<Point3<f64>>);

/// [`stairs_links`], each link with the walk over it from its foot to its top (the positions
/// of the walk between its ends, reversed for a walk down).
pub(crate) fn stairs_links_with_walks(
    positions: &[Point3<f64>],
    floors: &FloorLevels,
    grids: &[&BitGrid],
) -> Result<Vec<LinkWithWalk>, NavError> {
    let levels = floors.levels();
    if grids.len() < levels.len() {
        return Err(NavError::NoSuchFloor {
            what: "a floor of the walk",
            floor: grids.len(),
            floors: grids.len(),
        });
    }
    let mut links: Vec<LinkWithWalk> = Vec::new();
    for change in floors.changes() {
        if change.arrived_at >= positions.len() {
            return Err(bad_positions(
                positions.len() as f64,
                "as many as the poses the floors were split from",
            ));
        }
        let free_on = |floor: usize, i: usize| -> Option<Cell> {
            let p = positions[i];
            if !p.iter().all(|v| v.is_finite()) {
                return None;
            }
            let grid = grids[floor];
            grid.cell_at(Vector2::new(p.x, p.y))
                .filter(|&c| free_around(grid, c, END_MARGIN_CELLS))
        };
        // Back along the floor left, then on along the floor reached, to the first free cells.
        let left = (0..=change.left_at)
            .rev()
            .take_while(|&i| floors.floor_of(i) == Some(change.from))
            .find_map(|i| free_on(change.from, i).map(|c| (i, c)));
        let reached = (change.arrived_at..positions.len())
            .take_while(|&i| floors.floor_of(i) == Some(change.to))
            .find_map(|i| free_on(change.to, i).map(|c| (i, c)));
        let (Some((a, from_cell)), Some((b, to_cell))) = (left, reached) else {
            continue;
        };
        let length: f64 = positions[a..=b]
            .windows(2)
            .map(|w| (w[1] - w[0]).norm())
            .sum();
        if !length.is_finite() {
            return Err(bad_positions(length, "finite along the walk"));
        }
        let from = FloorCell {
            floor: change.from,
            cell: from_cell,
        };
        let to = FloorCell {
            floor: change.to,
            cell: to_cell,
        };
        let (foot, top) = if levels[change.from].height <= levels[change.to].height {
            (from, to)
        } else {
            (to, from)
        };
        let link = StairsLink { foot, top, length };
        let mut walk = positions[a..=b].to_vec();
        if foot != from {
            walk.reverse();
        }
        let near = |x: FloorCell, y: FloorCell| {
            let grid = grids[x.floor];
            x.floor == y.floor
                && (grid.cell_center(x.cell) - grid.cell_center(y.cell)).norm() <= SAME_FLIGHT
        };
        match links
            .iter_mut()
            .find(|(l, _)| near(l.foot, link.foot) && near(l.top, link.top))
        {
            Some(same) if link.length < same.0.length => *same = (link, walk),
            Some(_) => {}
            None => links.push((link, walk)),
        }
    }
    Ok(links)
}

/// A link's end is a cell free with this many cells around it free too: on the edge of the
/// inflation a navigator's own grid (its live layer, its cost) may read it blocked.
const END_MARGIN_CELLS: u32 = 1;

/// Whether `c` and every cell within `margin` cells of it (on the grid) are free.
fn free_around(grid: &BitGrid, c: Cell, margin: u32) -> bool {
    let (x0, y0) = (c.x.saturating_sub(margin), c.y.saturating_sub(margin));
    let x1 = (c.x + margin).min(grid.width() - 1);
    let y1 = (c.y + margin).min(grid.height() - 1);
    (y0..=y1).all(|y| (x0..=x1).all(|x| !grid.is_blocked(Cell::new(x, y))))
}

/// The error for `positions` that do not fit the walk.
fn bad_positions(value: f64, expected: &'static str) -> NavError {
    NavError::InvalidConfig(InvalidSetting {
        setting: "stairs_links positions",
        value,
        expected,
    })
}
