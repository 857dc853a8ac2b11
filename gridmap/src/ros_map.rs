//! ROS `map_server` maps: a YAML file and a trinary PGM image. The image's first row is the grid's
//! top row (origin = lower-left pixel, y up); occupied 0, free 254, unknown 205, as `map_saver`
//! writes them.

use std::fmt::Write as _;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use image::codecs::pnm::{PnmEncoder, PnmSubtype, SampleEncoding};
use image::{ExtendedColorType, GrayImage, ImageEncoder, ImageReader, Luma};
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

/// The keys of a `map_server` YAML file that this reader uses.
#[derive(Clone, Debug, PartialEq)]
pub struct RosMapYaml {
    /// The image file, relative to the YAML file's folder (or absolute).
    pub image: String,
    /// Metres per pixel.
    pub resolution: f64,
    /// World x, y (metres) of the lower-left pixel's outer corner (the yaw must be 0).
    pub origin: Vector2<f64>,
    /// Whether white means occupied (`negate: 1`).
    pub negate: bool,
    /// Occupancy probability above which a pixel is occupied, in `[0, 1]`; usually 0.65.
    pub occupied_thresh: f64,
    /// Occupancy probability below which a pixel is free, in `[0, 1]`; usually 0.196.
    pub free_thresh: f64,
}

impl RosMapYaml {
    /// Parse the YAML text of a map (the flat `key: value` form `map_saver` writes).
    ///
    /// # Errors
    /// [`GridMapError::YamlText`] for a malformed line, a missing `image`, `resolution` or
    /// `origin`, a non-zero origin yaw (which this grid cannot represent), a `negate` other
    /// than 0 or 1, or a threshold that is not a number in `[0, 1]` (NaN included).
    pub fn parse(text: &str) -> Result<Self, GridMapError> {
        let err = |line: usize, message: String| GridMapError::YamlText { line, message };
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
            // NaN fails the range test too (it would make every pixel unknown).
            let probability = |v: &str| {
                let p = num(v)?;
                if (0.0..=1.0).contains(&p) {
                    Ok(p)
                } else {
                    Err(err(
                        k + 1,
                        format!("{key}: {v:?} is not a probability in [0, 1]"),
                    ))
                }
            };
            match key.trim() {
                "image" => image = Some(unquote(value).to_string()),
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
                "negate" => {
                    negate = match value {
                        "0" => false,
                        "1" => true,
                        other => {
                            return Err(err(k + 1, format!("negate: {other:?} is not 0 or 1")));
                        }
                    };
                }
                "occupied_thresh" => occ = probability(value)?,
                "free_thresh" => free = probability(value)?,
                _ => {}
            }
        }
        Ok(Self {
            image: image.ok_or_else(|| err(0, "no image key".into()))?,
            resolution: resolution.ok_or_else(|| err(0, "no resolution key".into()))?,
            origin: origin.ok_or_else(|| err(0, "no origin key".into()))?,
            negate,
            occupied_thresh: occ,
            free_thresh: free,
        })
    }

    /// The YAML text `map_saver` would write for these keys (floats printed so they read back
    /// exactly; the image name quoted when it must be, e.g. for a leading space). A name with `#`
    /// or a line break cannot be written (nor read: `#` starts a comment).
    #[must_use]
    pub fn to_text(&self) -> String {
        let mut yaml = String::new();
        let _ = writeln!(yaml, "image: {}", quote_if_needed(&self.image));
        let _ = writeln!(yaml, "mode: trinary");
        let _ = writeln!(yaml, "resolution: {:?}", self.resolution);
        let _ = writeln!(
            yaml,
            "origin: [{:?}, {:?}, 0.0]",
            self.origin.x, self.origin.y
        );
        let _ = writeln!(yaml, "negate: {}", u8::from(self.negate));
        let _ = writeln!(yaml, "occupied_thresh: {:?}", self.occupied_thresh);
        let _ = writeln!(yaml, "free_thresh: {:?}", self.free_thresh);
        yaml
    }

    /// The grid of the map whose image file holds `image_bytes` (PGM or PNG, 8-bit grey or
    /// converted to it). Pixels are classified as `map_server` does (`p = (255 - v) / 255`,
    /// inverted when `negate`): occupied above `occupied_thresh`, free below `free_thresh`,
    /// unknown between. The image decoder's default memory limit (512 MiB) applies.
    ///
    /// # Errors
    /// [`GridMapError::Image`] (naming [`RosMapYaml::image`]) when the bytes do not decode,
    /// [`GridMapError::Grid`] for an unusable resolution or origin.
    pub fn grid_from_image(&self, image_bytes: &[u8]) -> Result<OccupancyGrid, GridMapError> {
        let image_err = |source| GridMapError::Image {
            path: PathBuf::from(&self.image),
            source,
        };
        let reader = ImageReader::new(Cursor::new(image_bytes))
            .with_guessed_format()
            .map_err(|e| image_err(image::ImageError::IoError(e)))?;
        self.classify(reader, &PathBuf::from(&self.image))
    }

    /// Decode the image of `reader` (named `path` in errors) and classify its pixels.
    fn classify<R: std::io::BufRead + std::io::Seek>(
        &self,
        reader: ImageReader<R>,
        path: &Path,
    ) -> Result<OccupancyGrid, GridMapError> {
        let geometry = GridGeometry::try_new(self.origin, self.resolution)?;
        let img = reader
            .decode()
            .map_err(|source| GridMapError::Image {
                path: path.to_path_buf(),
                source,
            })?
            .into_luma8();
        let (w, h) = img.dimensions();
        let mut grid = OccupancyGrid::new(w, h, geometry, CellState::Unknown)?;
        for (px, py, Luma([v])) in img.enumerate_pixels() {
            let mut p = f64::from(255 - *v) / 255.0;
            if self.negate {
                p = 1.0 - p;
            }
            let state = if p > self.occupied_thresh {
                CellState::Occupied
            } else if p < self.free_thresh {
                CellState::Free
            } else {
                CellState::Unknown
            };
            grid.set(Cell::new(px, h - 1 - py), state)?;
        }
        Ok(grid)
    }
}

/// `value` without one pair of enclosing quotes (`"..."` or `'...'`), else as it is.
fn unquote(value: &str) -> &str {
    for q in ['"', '\''] {
        if let Some(inner) = value.strip_prefix(q).and_then(|rest| rest.strip_suffix(q)) {
            return inner;
        }
    }
    value
}

/// `name` as a YAML value that [`unquote`] reads back to `name` after the line is trimmed.
fn quote_if_needed(name: &str) -> String {
    if !name.is_empty() && name.trim() == name && unquote(name) == name {
        name.to_owned()
    } else {
        format!("'{name}'")
    }
}

/// The binary greyscale PGM (P5, the form `map_server` and `map_saver` use) of `grid`. Stairs
/// cells are written occupied: the format has no stairs, and a 2D planner must not walk onto
/// a flight.
///
/// # Errors
/// [`GridMapError::Image`] (naming `name`) when the encoder fails.
pub fn ros_map_pgm(grid: &OccupancyGrid, name: &Path) -> Result<Vec<u8>, GridMapError> {
    let (w, h) = (grid.width(), grid.height());
    let img = GrayImage::from_fn(w, h, |px, py| {
        let cell = Cell::new(px, h - 1 - py);
        Luma([match grid.state(cell) {
            // A 2D planner reading the map must not walk onto a flight.
            CellState::Occupied | CellState::Stairs => OCCUPIED,
            CellState::Free => FREE,
            CellState::Unknown => UNKNOWN,
        }])
    });
    let mut bytes = Vec::new();
    PnmEncoder::new(&mut bytes)
        .with_subtype(PnmSubtype::Graymap(SampleEncoding::Binary))
        .write_image(img.as_raw(), w, h, ExtendedColorType::L8)
        .map_err(|source| GridMapError::Image {
            path: name.to_path_buf(),
            source,
        })?;
    Ok(bytes)
}

/// The YAML keys `map_saver` writes for `grid` with its image named `image`.
#[must_use]
pub fn ros_map_yaml(grid: &OccupancyGrid, image: &str) -> RosMapYaml {
    let g = grid.geometry();
    RosMapYaml {
        image: image.to_owned(),
        resolution: g.resolution,
        origin: g.origin,
        negate: false,
        occupied_thresh: 0.65,
        free_thresh: 0.196,
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
    let pgm = ros_map_pgm(grid, &pgm_path)?;
    std::fs::write(&pgm_path, pgm).map_err(|e| io_err(&pgm_path, e))?;
    let name = pgm_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let yaml = ros_map_yaml(grid, &name).to_text();
    std::fs::write(yaml_path, yaml).map_err(|e| io_err(yaml_path, e))?;
    Ok(pgm_path)
}

/// Read a `map_server` YAML and its image (see [`RosMapYaml::parse`] and
/// [`RosMapYaml::grid_from_image`]).
///
/// # Errors
/// [`GridMapError::Io`], [`GridMapError::Yaml`] (as [`RosMapYaml::parse`], naming the file) or
/// [`GridMapError::Image`].
pub fn read_ros_map(yaml_path: impl AsRef<Path>) -> Result<OccupancyGrid, GridMapError> {
    let yaml_path = yaml_path.as_ref();
    let text = std::fs::read_to_string(yaml_path).map_err(|e| io_err(yaml_path, e))?;
    let yaml = RosMapYaml::parse(&text).map_err(|e| match e {
        GridMapError::YamlText { line, message } => GridMapError::Yaml {
            path: yaml_path.to_path_buf(),
            line,
            message,
        },
        other => other,
    })?;
    let image_path = yaml_path
        .parent()
        .unwrap_or(Path::new("."))
        .join(&yaml.image);
    // The image streams through the decoder (which bounds its allocations); a device or a pipe
    // named by the YAML is refused before it is read.
    let meta = std::fs::metadata(&image_path).map_err(|e| io_err(&image_path, e))?;
    if !meta.is_file() {
        return Err(io_err(
            &image_path,
            std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a regular file"),
        ));
    }
    let reader = ImageReader::open(&image_path)
        .and_then(ImageReader::with_guessed_format)
        .map_err(|e| io_err(&image_path, e))?;
    yaml.classify(reader, &image_path)
}
