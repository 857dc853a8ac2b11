//! The mission's picture: the occupancy grid with its inflated obstacles, the start, the goals,
//! the exploration's path and the frontiers it left, the planned and walked paths and the
//! obstacles dropped after mapping, with a scale bar and a legend. Lines and boxes are drawn with `imageproc`, labels in the 8x8 bitmap font of
//! `font8x8` (no font file needed).

use std::path::Path;

use anyhow::{Context, Result};
use font8x8::UnicodeFonts;
use gridmap::{OccupancyGrid, render};
use image::{Rgb, RgbImage, imageops};
use imageproc::drawing::{draw_filled_rect_mut, draw_hollow_rect_mut, draw_line_segment_mut};
use imageproc::rect::Rect;
use nalgebra::Vector2;
use slam_core::BitGrid;

/// Colours of the overlays.
const START: Rgb<u8> = Rgb([0, 160, 0]);
const GOAL: Rgb<u8> = Rgb([220, 0, 0]);
const PLANNED: Rgb<u8> = Rgb([40, 90, 255]);
const WALKED: Rgb<u8> = Rgb([0, 170, 80]);
const OBSTACLE: Rgb<u8> = Rgb([200, 0, 200]);
const EXPLORED: Rgb<u8> = Rgb([150, 100, 40]);
const FRONTIER: Rgb<u8> = Rgb([0, 190, 255]);
const TEXT: Rgb<u8> = Rgb([0, 0, 0]);

/// What is drawn over the grid, in map-frame metres.
#[derive(Clone, Debug, Default)]
pub struct Overlay {
    /// Where the robot started (exploring, or navigating after a lap).
    pub start: Option<Vector2<f64>>,
    /// The exploration's path (ground truth, in the map frame); empty after a lap.
    pub explored: Vec<Vector2<f64>>,
    /// Centres of the frontier cells (known free next to unknown) left on the map.
    pub frontiers: Vec<Vector2<f64>>,
    /// The goals in the order visited.
    pub goals: Vec<Vector2<f64>>,
    /// Each leg's first planned path (waypoints from the robot to the goal).
    pub planned: Vec<Vec<Vector2<f64>>>,
    /// The walked path (ground truth, in the map frame).
    pub walked: Vec<Vector2<f64>>,
    /// Plan-view footprints (min, max corners) of obstacles dropped after mapping.
    pub obstacles: Vec<(Vector2<f64>, Vector2<f64>)>,
}

/// Pixels per grid cell in the picture.
const SCALE: u32 = 3;

/// The picture of `grid` (with `inflated` obstacles) and `overlay`, with a legend band below.
#[must_use]
pub fn draw(grid: &OccupancyGrid, inflated: &BitGrid, overlay: &Overlay) -> RgbImage {
    let base = render(grid, Some(inflated), &[], &[]);
    let (w, h) = (base.width() * SCALE, base.height() * SCALE);
    let base = imageops::resize(&base, w, h, imageops::FilterType::Nearest);
    let legend_height = (LEGEND_ROWS + 1) * 12 + 8;
    let mut img = RgbImage::from_pixel(w.max(640), h + legend_height, Rgb([255, 255, 255]));
    imageops::overlay(&mut img, &base, 0, 0);
    let geo = *grid.geometry();
    let rows = grid.height();
    let px = |p: Vector2<f64>| {
        let x = (p.x - geo.origin.x) / geo.resolution * f64::from(SCALE);
        let y = (f64::from(rows) - (p.y - geo.origin.y) / geo.resolution) * f64::from(SCALE);
        (x as f32, y as f32)
    };
    for w in overlay.explored.windows(2) {
        draw_line_segment_mut(&mut img, px(w[0]), px(w[1]), EXPLORED);
    }
    for &f in &overlay.frontiers {
        let (x, y) = px(f);
        let rect = Rect::at(x as i32 - 1, y as i32 - 1).of_size(SCALE, SCALE);
        draw_filled_rect_mut(&mut img, rect, FRONTIER);
    }
    for path in &overlay.planned {
        for w in path.windows(2) {
            draw_line_segment_mut(&mut img, px(w[0]), px(w[1]), PLANNED);
        }
    }
    for w in overlay.walked.windows(2) {
        draw_line_segment_mut(&mut img, px(w[0]), px(w[1]), WALKED);
    }
    for &(lo, hi) in &overlay.obstacles {
        let (x0, y1) = px(lo);
        let (x1, y0) = px(hi);
        let rect = Rect::at(x0 as i32, y0 as i32)
            .of_size(((x1 - x0) as u32).max(2), ((y1 - y0) as u32).max(2));
        draw_filled_rect_mut(&mut img, rect, OBSTACLE);
    }
    let marker = |img: &mut RgbImage, p: Vector2<f64>, colour: Rgb<u8>| {
        let (x, y) = px(p);
        let rect = Rect::at(x as i32 - 4, y as i32 - 4).of_size(9, 9);
        draw_filled_rect_mut(img, rect, colour);
    };
    if let Some(s) = overlay.start {
        marker(&mut img, s, START);
    }
    for (k, &g) in overlay.goals.iter().enumerate() {
        marker(&mut img, g, GOAL);
        let (x, y) = px(g);
        text(
            &mut img,
            x as i32 + 6,
            y as i32 - 4,
            &format!("{}", k + 1),
            GOAL,
        );
    }
    legend(&mut img, h + 4, geo.resolution);
    img
}

/// Write [`draw`]'s picture as a PNG.
///
/// # Errors
/// When the file cannot be written.
pub fn write_png(
    path: &Path,
    grid: &OccupancyGrid,
    inflated: &BitGrid,
    overlay: &Overlay,
) -> Result<()> {
    draw(grid, inflated, overlay)
        .save_with_format(path, image::ImageFormat::Png)
        .with_context(|| format!("writing {}", path.display()))
}

/// Rows of the legend's columns.
const LEGEND_ROWS: u32 = 6;

/// The legend (a swatch and a label per entry) and a 5 m scale bar, from row `top`.
fn legend(img: &mut RgbImage, top: u32, resolution: f64) {
    let entries: [(Rgb<u8>, &str); 11] = [
        (Rgb(gridmap::colours::FREE), "free"),
        (Rgb(gridmap::colours::OCCUPIED), "occupied"),
        (
            Rgb(gridmap::colours::INFLATED),
            "inflated (robot does not fit)",
        ),
        (Rgb(gridmap::colours::UNKNOWN), "unknown"),
        (EXPLORED, "explored path (ground truth)"),
        (FRONTIER, "frontiers left"),
        (PLANNED, "planned path (first plan of each leg)"),
        (WALKED, "walked path (ground truth)"),
        (START, "start"),
        (GOAL, "goals, numbered in order"),
        (OBSTACLE, "obstacles dropped after mapping"),
    ];
    for (k, (colour, label)) in entries.iter().enumerate() {
        let rows = LEGEND_ROWS as usize;
        let column = (k / rows) as i32 * 300;
        let y = top as i32 + (k % rows) as i32 * 12;
        let swatch = Rect::at(column + 4, y).of_size(10, 10);
        draw_filled_rect_mut(img, swatch, *colour);
        draw_hollow_rect_mut(img, swatch, TEXT);
        text(img, column + 18, y + 1, label, TEXT);
    }
    // Scale bar: 5 m.
    let length = (5.0 / resolution * f64::from(SCALE)) as i32;
    let y = (top + LEGEND_ROWS * 12 + 2) as i32;
    let bar = Rect::at(4, y).of_size(length.max(1) as u32, 4);
    draw_filled_rect_mut(img, bar, TEXT);
    text(img, length + 10, y - 2, "5 m", TEXT);
}

/// `s` in the 8x8 font with its top-left corner at (`x`, `y`); characters the font lacks are
/// left blank, pixels outside the picture skipped.
fn text(img: &mut RgbImage, x: i32, y: i32, s: &str, colour: Rgb<u8>) {
    for (k, ch) in s.chars().enumerate() {
        let Some(glyph) = font8x8::BASIC_FONTS.get(ch) else {
            continue;
        };
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8 {
                if bits >> col & 1 == 1 {
                    let (px, py) = (x + k as i32 * 8 + col, y + row as i32);
                    if px >= 0 && py >= 0 && (px as u32) < img.width() && (py as u32) < img.height()
                    {
                        img.put_pixel(px as u32, py as u32, colour);
                    }
                }
            }
        }
    }
}
