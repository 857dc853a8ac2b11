//! Fusing a robot-centred local grid (Spot's `no_step` or `obstacle_distance` grids, or any local
//! costmap) into the global occupancy grid without rebuilding it.

use nalgebra::{Point2, Vector2};
use slam_core::{Cell, Pose2};

use crate::error::{GridMapError, check};
use crate::occupancy::{CellState, OccupancyGrid};

/// What a local grid says of one of its cells.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LocalCell {
    /// Not observed: the global cell keeps its state.
    Unknown,
    /// Seen free: clears an obstacle in the global grid.
    Free,
    /// An obstacle: added to the global grid.
    Obstacle,
}

/// A local grid with its own cell size and pose.
#[derive(Clone, Debug, PartialEq)]
pub struct LocalGrid {
    /// Pose of the local grid's frame in the map: its cell (0, 0) has its outer corner at the
    /// frame's origin, columns along the frame's x axis, rows along its y axis.
    pub map_t_grid: Pose2,
    /// Cell side, metres.
    pub resolution: f64,
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// States, row-major (`width * height`).
    pub cells: Vec<LocalCell>,
}

impl LocalGrid {
    /// The state of the local cell containing the local-frame point `p`, if any.
    fn at(&self, p: Point2<f64>) -> Option<LocalCell> {
        let (x, y) = (
            (p.x / self.resolution).floor(),
            (p.y / self.resolution).floor(),
        );
        if x < 0.0 || y < 0.0 || x >= f64::from(self.width) || y >= f64::from(self.height) {
            return None;
        }
        Some(self.cells[y as usize * self.width as usize + x as usize])
    }

    /// A local grid from Spot's `obstacle_distance` values (metres to the nearest obstacle, row-major):
    /// cells at or below `threshold` are obstacles, others free; non-finite values are unknown.
    #[must_use]
    pub fn from_obstacle_distance(
        map_t_grid: Pose2,
        resolution: f64,
        width: u32,
        height: u32,
        distances: &[f32],
        threshold: f32,
    ) -> Self {
        let cells = distances
            .iter()
            .map(|&d| {
                if !d.is_finite() {
                    LocalCell::Unknown
                } else if d <= threshold {
                    LocalCell::Obstacle
                } else {
                    LocalCell::Free
                }
            })
            .collect();
        Self {
            map_t_grid,
            resolution,
            width,
            height,
            cells,
        }
    }
}

/// What a fusion changed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FusionReport {
    /// Global cells that became occupied.
    pub added: usize,
    /// Global cells that were occupied or unknown and became free.
    pub cleared: usize,
}

/// Merge `local` into `global`: each global cell whose centre falls in a local cell takes that
/// cell's obstacle or free state; unknown local cells and global cells outside the local footprint
/// are untouched. Only the global cells under the local grid's bounding box are visited.
///
/// # Errors
/// [`GridMapError::LocalGridCells`] for a local grid whose cell count is wrong,
/// [`GridMapError::InvalidConfig`] for one whose resolution is not finite and positive.
pub fn fuse_local_grid(
    global: &mut OccupancyGrid,
    local: &LocalGrid,
) -> Result<FusionReport, GridMapError> {
    if local.cells.len() != local.width as usize * local.height as usize {
        return Err(GridMapError::LocalGridCells {
            cells: local.cells.len(),
            width: local.width,
            height: local.height,
        });
    }
    check(
        local.resolution.is_finite() && local.resolution > 0.0,
        "LocalGrid::resolution",
        local.resolution,
        "finite and positive",
    )?;
    let g = *global.geometry();
    let (lw, lh) = (
        f64::from(local.width) * local.resolution,
        f64::from(local.height) * local.resolution,
    );
    // Bounding box of the local footprint in the map.
    let corners = [(0.0, 0.0), (lw, 0.0), (0.0, lh), (lw, lh)]
        .map(|(x, y)| local.map_t_grid * Point2::new(x, y));
    let lo = corners
        .iter()
        .fold(Vector2::repeat(f64::INFINITY), |a, p| a.inf(&p.coords));
    let hi = corners
        .iter()
        .fold(Vector2::repeat(f64::NEG_INFINITY), |a, p| a.sup(&p.coords));
    let (x0, y0) = g.cell_coords(lo);
    let (x1, y1) = g.cell_coords(hi);
    let grid_t_map = local.map_t_grid.inverse();
    let mut report = FusionReport::default();
    for y in y0.max(0)..=y1.min(i64::from(global.height()) - 1) {
        for x in x0.max(0)..=x1.min(i64::from(global.width()) - 1) {
            let cell = Cell::new(x as u32, y as u32);
            let centre = g.cell_center(cell);
            let Some(state) = local.at(grid_t_map * Point2::from(centre)) else {
                continue;
            };
            let before = global.state(cell);
            match state {
                LocalCell::Unknown => {}
                LocalCell::Obstacle => {
                    if before != CellState::Occupied {
                        global.set(cell, CellState::Occupied)?;
                        report.added += 1;
                    }
                }
                LocalCell::Free => {
                    if before != CellState::Free {
                        global.set(cell, CellState::Free)?;
                        report.cleared += 1;
                    }
                }
            }
        }
    }
    Ok(report)
}
