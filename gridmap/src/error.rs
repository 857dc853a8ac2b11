//! Errors of the gridmap crate.

use std::path::PathBuf;

use slam_core::InvalidSetting;
use thiserror::Error;

/// Errors building, transforming or storing occupancy grids.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum GridMapError {
    /// The input cloud has no points.
    #[error("the map cloud is empty")]
    EmptyCloud,
    /// The cloud has non-finite points (drop them first with `PointCloud::remove_non_finite`).
    #[error("the map cloud has {count} non-finite points")]
    NonFinitePoints {
        /// How many.
        count: usize,
    },
    /// No point lies in the height slice.
    #[error("no point lies between {min_z} m and {max_z} m")]
    EmptySlice {
        /// Lower bound of the slice.
        min_z: f64,
        /// Upper bound of the slice.
        max_z: f64,
    },
    /// No point lies in the obstacle band above the floor.
    #[error("no point lies between {above_floor} m and {up_to} m above the floor")]
    EmptyBand {
        /// Lower bound of the band above the floor.
        above_floor: f64,
        /// Upper bound of the band above the floor.
        up_to: f64,
    },
    /// A position of a walk is not finite.
    #[error("position {index} of the walk is not finite")]
    NonFinitePosition {
        /// Its index.
        index: usize,
    },
    /// A floor estimate needs at least one hint of where the floor is.
    #[error("no floor hint given (points on the floor under the robot's poses)")]
    NoFloorHint,
    /// Updates of a live layer must come in time order.
    #[error("stamp {stamp} s is before the previous update's {previous} s")]
    StampOutOfOrder {
        /// The previous update's stamp.
        previous: f64,
        /// The stamp given.
        stamp: f64,
    },
    /// A setting or argument is out of its valid range.
    #[error(transparent)]
    InvalidConfig(#[from] InvalidSetting),
    /// A local grid's cell list does not match its size.
    #[error("local grid has {cells} cells for {width}x{height}")]
    LocalGridCells {
        /// Cells given.
        cells: usize,
        /// Columns.
        width: u32,
        /// Rows.
        height: u32,
    },
    /// The grid would have more cells than the configured budget.
    #[error("a {width}x{height} grid exceeds the budget of {max_cells} cells")]
    TooManyCells {
        /// Width the grid would have.
        width: u64,
        /// Height the grid would have.
        height: u64,
        /// The budget.
        max_cells: u64,
    },
    /// The two grids do not have the same size and placement.
    #[error("grids differ in size or placement")]
    GeometryMismatch,
    /// A map file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A map YAML line could not be parsed.
    #[error("{path} line {line}: {message}")]
    Yaml {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A map YAML parsed from memory has a line that could not be parsed (from a file, the
    /// error is [`GridMapError::Yaml`], which names the file).
    #[error("map YAML line {line}: {message}")]
    YamlText {
        /// 1-based line (0 for a key missing from the whole text).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The image codec failed.
    #[error("image {path}: {source}")]
    Image {
        /// The file.
        path: PathBuf,
        /// The codec's error.
        source: image::ImageError,
    },
    /// A grid operation failed.
    #[error(transparent)]
    Grid(#[from] slam_core::GridError),
}

/// [`GridMapError::InvalidConfig`] for `setting` unless `ok`.
pub(crate) fn check(
    ok: bool,
    setting: &'static str,
    value: f64,
    expected: &'static str,
) -> Result<(), GridMapError> {
    Ok(InvalidSetting::check(ok, setting, value, expected)?)
}

/// [`GridMapError::InvalidConfig`] for the first of `settings` (name, value) that is not finite
/// and non-negative.
pub(crate) fn check_not_negative(settings: &[(&'static str, f64)]) -> Result<(), GridMapError> {
    for &(setting, v) in settings {
        check(
            v.is_finite() && v >= 0.0,
            setting,
            v,
            "finite and not negative",
        )?;
    }
    Ok(())
}

/// [`GridMapError::NonFinitePoints`] when any point of `cloud` has a coordinate that is not finite.
pub(crate) fn check_finite_points(cloud: &[nalgebra::Point3<f32>]) -> Result<(), GridMapError> {
    let bad = cloud
        .iter()
        .filter(|p| !p.iter().all(|v| v.is_finite()))
        .count();
    if bad > 0 {
        return Err(GridMapError::NonFinitePoints { count: bad });
    }
    Ok(())
}
