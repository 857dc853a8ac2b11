//! ROS `map_server` maps: a YAML file and a trinary PGM image. The image's first row is the grid's
//! top row (origin = lower-left pixel, y up); occupied 0, free 254, unknown 205, as `map_saver`
//! writes them.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use image::codecs::pnm::{PnmEncoder, PnmSubtype, SampleEncoding};
use image::{ExtendedColorType, GrayImage, ImageEncoder, Luma};
use nalgebra::Vector2;
use slam_core::{Cell, GridGeometry};

use crate::error::GridMapError;
use crate::occupancy::{CellState, OccupancyGrid};

const OCCUPIED: u8 = 0;
const FREE: u8 = 254;
const UNKNOWN: u8 = 205;

fn io_err(path: &Path, source: std::io::Error) -> GridMapError {
    GridMapError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Write `grid` as `yaml_path` plus a PGM beside it (same name, `.pgm`). Returns the PGM's path.
///
/// # Errors
/// [`GridMapError::Io`] or [`GridMapError::Image`] when a file cannot be written.
pub fn write_ros_map(
    grid: &OccupancyGrid,
    yaml_path: impl AsRef<Path>,
) -> Result<PathBuf, GridMapError> {
    let yaml_path = yaml_path.as_ref();
    let pgm_path = yaml_path.with_extension("pgm");
    let (w, h) = (grid.width(), grid.height());
    let img = GrayImage::from_fn(w, h, |px, py| {
        let cell = Cell::new(px, h - 1 - py);
        Luma([match grid.state(cell) {
            CellState::Occupied => OCCUPIED,
            CellState::Free => FREE,
            CellState::Unknown => UNKNOWN,
        }])
    });
    let file = std::fs::File::create(&pgm_path).map_err(|e| io_err(&pgm_path, e))?;
    // Binary greyscale (P5), the form map_server and map_saver use.
    PnmEncoder::new(std::io::BufWriter::new(file))
        .with_subtype(PnmSubtype::Graymap(SampleEncoding::Binary))
        .write_image(img.as_raw(), w, h, ExtendedColorType::L8)
        .map_err(|source| GridMapError::Image {
            path: pgm_path.clone(),
            source,
        })?;
    let g = grid.geometry();
    let name = pgm_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut yaml = String::new();
    // `{:?}` prints floats so they read back exactly.
    let _ = writeln!(yaml, "image: {name}");
    let _ = writeln!(yaml, "mode: trinary");
    let _ = writeln!(yaml, "resolution: {:?}", g.resolution);
    let _ = writeln!(yaml, "origin: [{:?}, {:?}, 0.0]", g.origin.x, g.origin.y);
    let _ = writeln!(yaml, "negate: 0");
    let _ = writeln!(yaml, "occupied_thresh: 0.65");
    let _ = writeln!(yaml, "free_thresh: 0.196");
    std::fs::write(yaml_path, yaml).map_err(|e| io_err(yaml_path, e))?;
    Ok(pgm_path)
}

/// Read a `map_server` YAML and its image. Pixels are classified as `map_server` does
/// (`p = (255 - v) / 255`, inverted when `negate: 1`): occupied above `occupied_thresh`, free below
/// `free_thresh`, unknown between.
///
/// # Errors
/// [`GridMapError::Io`], [`GridMapError::Yaml`] (missing or malformed keys, a non-zero origin
/// yaw, which this grid cannot represent) or [`GridMapError::Image`].
pub fn read_ros_map(yaml_path: impl AsRef<Path>) -> Result<OccupancyGrid, GridMapError> {
    let yaml_path = yaml_path.as_ref();
    let text = std::fs::read_to_string(yaml_path).map_err(|e| io_err(yaml_path, e))?;
    let err = |line: usize, message: String| GridMapError::Yaml {
        path: yaml_path.to_path_buf(),
        line,
        message,
    };
    let (mut image, mut resolution, mut origin) = (None, None, None);
    let (mut negate, mut occ, mut free) = (false, 0.65, 0.196);
    for (k, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let Some((key, value)) = line.split_once(':') else {
            return Err(err(k + 1, format!("expected 'key: value', found {line:?}")));
        };
        let value = value.trim();
        let num = |v: &str| {
            v.trim()
                .parse::<f64>()
                .map_err(|_| err(k + 1, format!("{key}: {v:?} is not a number")))
        };
        match key.trim() {
            "image" => image = Some(value.trim_matches(|c| c == '"' || c == '\'').to_string()),
            "resolution" => resolution = Some(num(value)?),
            "origin" => {
                let inner = value.trim_start_matches('[').trim_end_matches(']');
                let v: Vec<f64> = inner.split(',').map(num).collect::<Result<_, _>>()?;
                if v.len() != 3 {
                    return Err(err(
                        k + 1,
                        format!("origin has {} values, 3 expected", v.len()),
                    ));
                }
                if v[2] != 0.0 {
                    return Err(err(
                        k + 1,
                        format!(
                            "origin yaw {} is not supported (rotate the map first)",
                            v[2]
                        ),
                    ));
                }
                origin = Some(Vector2::new(v[0], v[1]));
            }
            "negate" => negate = num(value)? != 0.0,
            "occupied_thresh" => occ = num(value)?,
            "free_thresh" => free = num(value)?,
            _ => {}
        }
    }
    let image = image.ok_or_else(|| err(0, "no image key".into()))?;
    let resolution = resolution.ok_or_else(|| err(0, "no resolution key".into()))?;
    let origin = origin.ok_or_else(|| err(0, "no origin key".into()))?;
    let geometry = GridGeometry::try_new(origin, resolution)?;
    let image_path = yaml_path.parent().unwrap_or(Path::new(".")).join(&image);
    let img = image::open(&image_path)
        .map_err(|source| GridMapError::Image {
            path: image_path.clone(),
            source,
        })?
        .into_luma8();
    let (w, h) = img.dimensions();
    let mut grid = OccupancyGrid::new(w, h, geometry, CellState::Unknown)?;
    for (px, py, Luma([v])) in img.enumerate_pixels() {
        let mut p = f64::from(255 - *v) / 255.0;
        if negate {
            p = 1.0 - p;
        }
        let state = if p > occ {
            CellState::Occupied
        } else if p < free {
            CellState::Free
        } else {
            CellState::Unknown
        };
        grid.set(Cell::new(px, h - 1 - py), state)?;
    }
    Ok(grid)
}
