//! Obstacles from the floor up: the band from a few centimetres above the floor to the robot's
//! height plus a margin, from a map cloud or from scans with free space from their beams.

use nalgebra::{Point3, Vector2};
use slam_core::{PointCloud, Pose3};

use crate::band_accumulator::FloorBandAccumulator;
use crate::builder::{OccupancyGridBuilder, extent};
use crate::error::{GridMapError, check, check_not_negative};
use crate::floor::FloorMap;
use crate::occupancy::{CellState, OccupancyGrid};

/// The obstacle band, in metres above the local floor ([`FloorMap`]): points from `above_floor`
/// to `up_to` are obstacles. Spot: the body frame is 0.50 m above the ground, the LiDAR 0.30 m
/// above the body, the robot 0.84 m tall with it.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct ObstacleBandConfig {
    /// Lowest obstacle height above the floor, 0.08 m: floor points with their noise and the
    /// floor estimate's error stay below it; anything taller (a cable duct, a crate, a desk's
    /// legs) is an obstacle.
    pub above_floor: f64,
    /// Highest obstacle height above the floor, 0.94 m (Spot with its LiDAR, 0.84 m, plus
    /// 0.10 m): higher points (door lintels at 2.1 m, the ceiling) are overhangs the robot walks
    /// under; a 0.72 m desk top is an obstacle.
    pub up_to: f64,
}

impl Default for ObstacleBandConfig {
    fn default() -> Self {
        Self {
            above_floor: 0.08,
            up_to: 0.94,
        }
    }
}

impl ObstacleBandConfig {
    /// Check both bounds.
    ///
    /// # Errors
    /// [`GridMapError::InvalidConfig`] unless `0 <= above_floor < up_to`, both finite.
    pub fn validate(&self) -> Result<(), GridMapError> {
        check_not_negative(&[("ObstacleBandConfig::above_floor", self.above_floor)])?;
        check(
            self.up_to.is_finite() && self.up_to > self.above_floor,
            "ObstacleBandConfig::up_to",
            self.up_to,
            "finite and above ObstacleBandConfig::above_floor",
        )?;
        Ok(())
    }
}

/// Where a point lies relative to the obstacle band above its floor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Height {
    /// Below the band: the floor (or a dip below it).
    Floor,
    /// In the band: an obstacle.
    Obstacle,
    /// Above the band: an overhang.
    Overhang,
}

/// The band's height limits (map frame z) at map point (x, y).
#[inline]
pub(crate) fn band_at(floor: &FloorMap, band: &ObstacleBandConfig, x: f64, y: f64) -> (f64, f64) {
    let f = floor.floor_at(x, y);
    (f + band.above_floor, f + band.up_to)
}

/// Classify height `z` against the band `(lo, hi)`.
#[inline]
pub(crate) fn classify(z: f64, (lo, hi): (f64, f64)) -> Height {
    if z < lo {
        Height::Floor
    } else if z <= hi {
        Height::Obstacle
    } else {
        Height::Overhang
    }
}

impl OccupancyGridBuilder {
    /// The occupancy grid of a map cloud (map frame, z up) from its obstacle band: a cell is
    /// occupied when at least `min_points` points lie between `band.above_floor` and
    /// `band.up_to` above the floor under them (`floor`, from [`FloorMap::estimate`]); every
    /// other cell is free (a map cloud has no beams to tell free from unknown: use
    /// [`OccupancyGridBuilder::build_floor_band_from_scans`] for that). The grid spans the band
    /// points plus the margin. The slice settings of the builder are not used.
    ///
    /// # Errors
    /// [`GridMapError::InvalidConfig`] for an invalid band, [`GridMapError::EmptyCloud`],
    /// [`GridMapError::NonFinitePoints`], [`GridMapError::EmptyBand`] or
    /// [`GridMapError::TooManyCells`].
    pub fn build_floor_band(
        &self,
        cloud: &PointCloud,
        floor: &FloorMap,
        band: &ObstacleBandConfig,
    ) -> Result<OccupancyGrid, GridMapError> {
        band.validate()?;
        Self::check_cloud(cloud)?;
        let hits: Vec<Vector2<f64>> = cloud
            .points()
            .iter()
            .map(|p| Point3::new(f64::from(p.x), f64::from(p.y), f64::from(p.z)))
            .filter(|p| classify(p.z, band_at(floor, band, p.x, p.y)) == Height::Obstacle)
            .map(|p| p.coords.xy())
            .collect();
        let (min, max) = extent(hits.iter().copied()).ok_or(GridMapError::EmptyBand {
            above_floor: band.above_floor,
            up_to: band.up_to,
        })?;
        let mut grid = self.empty_grid(min, max, CellState::Free)?;
        self.mark_occupied(&mut grid, &hits)?;
        Ok(grid)
    }

    /// The occupancy grid of scans (each in its sensor frame, placed by `world_T_sensor`) from
    /// their obstacle band, with free space from their beams; cells never observed stay unknown.
    ///
    /// - A cell holding at least `min_points` band points (over all scans) is occupied.
    /// - A beam frees the cells its ground track crosses while it is at or below the band's top
    ///   (`band.up_to` above the floor under its end point): up to its end cell, excluded for a
    ///   band point (the obstacle), included for a floor point (the floor was seen there); a beam
    ///   to an overhang frees the cells up to where it rises past the band's top. Occupied wins.
    /// - Per scan, one beam per end cell and kind is traced (the first point's): the others would
    ///   cross the same cells up to the width of a cell.
    ///
    /// The grid spans the scan origins, the band points and the floor points, plus the margin.
    /// Drop-offs (stairs down) are not detected: points below the floor count as floor.
    ///
    /// # Errors
    /// As [`OccupancyGridBuilder::build_floor_band`], for the scans together.
    pub fn build_floor_band_from_scans(
        &self,
        scans: &[(Pose3, &PointCloud)],
        floor: &FloorMap,
        band: &ObstacleBandConfig,
    ) -> Result<OccupancyGrid, GridMapError> {
        band.validate()?;
        if scans.iter().all(|(_, c)| c.is_empty()) {
            return Err(GridMapError::EmptyCloud);
        }
        let mut all =
            FloorBandAccumulator::new(self.config().clone(), floor.clone(), band.clone())?;
        all.add_scans(scans)?;
        all.grid()
    }
}
