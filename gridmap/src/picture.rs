//! PNG pictures of occupancy grids (stairs included), with optional inflation, path and waypoints.

use std::path::Path;

use image::{Rgb, RgbImage};
use slam_core::{BitGrid, Cell};

use crate::error::GridMapError;
use crate::occupancy::{CellState, OccupancyGrid};

/// Colours of a [`render`] picture.
pub mod colours {
    /// Free cells: white.
    pub const FREE: [u8; 3] = [255, 255, 255];
    /// Occupied cells: black.
    pub const OCCUPIED: [u8; 3] = [0, 0, 0];
    /// Unknown cells: grey.
    pub const UNKNOWN: [u8; 3] = [160, 160, 160];
    /// Free cells blocked by inflation: light orange.
    pub const INFLATED: [u8; 3] = [255, 200, 140];
    /// Stairs cells: teal.
    pub const STAIRS: [u8; 3] = [0, 160, 160];
    /// Path cells: blue.
    pub const PATH: [u8; 3] = [30, 90, 255];
    /// Waypoints: red.
    pub const WAYPOINT: [u8; 3] = [230, 20, 20];
}

/// A picture of `grid` (top row = highest y): free, occupied, unknown, stairs, and the cells `inflated`
/// adds, with `path` cells and `waypoints` drawn on top.
#[must_use]
pub fn render(
    grid: &OccupancyGrid,
    inflated: Option<&BitGrid>,
    path: &[Cell],
    waypoints: &[Cell],
) -> RgbImage {
    let (w, h) = (grid.width(), grid.height());
    let mut img = RgbImage::from_fn(w, h, |px, py| {
        let c = Cell::new(px, h - 1 - py);
        Rgb(match grid.state(c) {
            CellState::Occupied => colours::OCCUPIED,
            CellState::Stairs => colours::STAIRS,
            _ if inflated.is_some_and(|g| g.is_blocked(c)) => colours::INFLATED,
            CellState::Free => colours::FREE,
            CellState::Unknown => colours::UNKNOWN,
        })
    });
    for (cells, colour) in [(path, colours::PATH), (waypoints, colours::WAYPOINT)] {
        for c in cells.iter().filter(|c| c.x < w && c.y < h) {
            img.put_pixel(c.x, h - 1 - c.y, Rgb(colour));
        }
    }
    img
}

/// Write [`render`]'s picture as a PNG.
///
/// # Errors
/// [`GridMapError::Image`] when the file cannot be written.
pub fn write_png(
    path: impl AsRef<Path>,
    grid: &OccupancyGrid,
    inflated: Option<&BitGrid>,
    cells: &[Cell],
    waypoints: &[Cell],
) -> Result<(), GridMapError> {
    let path = path.as_ref();
    render(grid, inflated, cells, waypoints)
        .save_with_format(path, image::ImageFormat::Png)
        .map_err(|source| GridMapError::Image {
            path: path.to_path_buf(),
            source,
        })
}
