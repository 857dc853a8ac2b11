//! `walked_cells`: the cells a robot's own path crossed, for [`PlanningGrid::with_walked`]:
//! where the robot has walked, it fits.
//!
//! [`PlanningGrid::with_walked`]: crate::PlanningGrid::with_walked

use nalgebra::Vector2;
use slam_core::{BitGrid, Cell};

use crate::error::GridMapError;
use crate::occupancy::OccupancyGrid;
use crate::rays::traverse;

/// The cells of a grid over `occupancy` (its size and placement) that the straight segments
/// between consecutive `positions` (metres, the grid's frame: a robot's path, e.g. its
/// keyframes' body positions) cross. A segment longer than `max_step` metres is a jump in the
/// path (a gap in the recording, a relocalisation), not a walk: it is skipped. Non-finite
/// positions are skipped with the segments on either side; cells off the grid are ignored.
///
/// ```
/// use gridmap::{CellState, OccupancyGrid, walked_cells};
/// use nalgebra::Vector2;
/// use slam_core::{Cell, GridGeometry};
///
/// let geometry = GridGeometry::try_new(Vector2::zeros(), 0.1)?;
/// let occupancy = OccupancyGrid::new(20, 10, geometry, CellState::Free)?;
/// let path = [Vector2::new(0.05, 0.55), Vector2::new(1.05, 0.55), Vector2::new(5.0, 0.55)];
/// let walked = walked_cells(&occupancy, &path, 2.0)?;
/// assert!(walked.is_blocked(Cell::new(7, 5)));
/// // The 3.95 m step is a jump: skipped.
/// assert!(!walked.is_blocked(Cell::new(15, 5)));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
///
/// # Errors
/// [`GridMapError::InvalidConfig`] for a `max_step` that is not finite and positive.
pub fn walked_cells(
    occupancy: &OccupancyGrid,
    positions: &[Vector2<f64>],
    max_step: f64,
) -> Result<BitGrid, GridMapError> {
    crate::error::check(
        max_step.is_finite() && max_step > 0.0,
        "walked_cells::max_step",
        max_step,
        "finite and positive",
    )?;
    let geometry = *occupancy.geometry();
    let (w, h) = (occupancy.width(), occupancy.height());
    let mut walked = BitGrid::new(w, h)?.with_geometry(geometry);
    let r = geometry.resolution;
    let to_cells = |p: Vector2<f64>| (p - geometry.origin) / r;
    let mut mark = |x: i64, y: i64| {
        if let (Ok(x), Ok(y)) = (u32::try_from(x), u32::try_from(y))
            && x < w
            && y < h
        {
            // On the grid: cannot fail.
            let _ = walked.set(Cell::new(x, y), true);
        }
    };
    for pair in positions.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        if !(a.iter().chain(b.iter()).all(|v| v.is_finite()) && (b - a).norm() <= max_step) {
            continue;
        }
        traverse(to_cells(a), to_cells(b), true, &mut mark);
    }
    if let [only] = positions
        && only.iter().all(|v| v.is_finite())
    {
        let c = to_cells(*only);
        mark(c.x.floor() as i64, c.y.floor() as i64);
    }
    Ok(walked)
}
