//! Map cloud to occupancy grid by direct binning of a height slice (O(N)), optionally with ray
//! casting from the scan origins to tell free from unknown.

use nalgebra::{Point3, Vector2};
use slam_core::{Cell, GridGeometry, PointCloud, Pose3};

use crate::config::OccupancyGridConfig;
use crate::error::{GridMapError, check, check_finite_points, check_not_negative};
use crate::extent::CellExtent;
use crate::occupancy::{CellState, OccupancyGrid};
use crate::rays::traverse;

/// Builds [`OccupancyGrid`]s from map clouds. The thesis tested each cell with a k-d tree search
/// (O(cells log N)); binning each slice point into its cell is O(N) and gives the same cells.
#[derive(Clone, Debug)]
pub struct OccupancyGridBuilder {
    config: OccupancyGridConfig,
}

impl OccupancyGridBuilder {
    /// A builder with checked settings.
    ///
    /// # Errors
    /// [`GridMapError::InvalidConfig`] for a resolution, slice or margin that is not finite and
    /// non-negative (resolution positive), or `min_points == 0`.
    pub fn new(config: OccupancyGridConfig) -> Result<Self, GridMapError> {
        let c = &config;
        check(
            c.resolution.is_finite() && c.resolution > 0.0,
            "OccupancyGridConfig::resolution",
            c.resolution,
            "finite and positive",
        )?;
        check_not_negative(&[
            ("OccupancyGridConfig::slice_below", c.slice_below),
            ("OccupancyGridConfig::slice_above", c.slice_above),
            ("OccupancyGridConfig::margin", c.margin),
        ])?;
        check(
            c.min_points > 0,
            "OccupancyGridConfig::min_points",
            f64::from(c.min_points),
            "at least 1",
        )?;
        Ok(Self { config })
    }

    /// The settings.
    #[must_use]
    pub fn config(&self) -> &OccupancyGridConfig {
        &self.config
    }

    pub(crate) fn check_cloud(cloud: &PointCloud) -> Result<(), GridMapError> {
        if cloud.is_empty() {
            return Err(GridMapError::EmptyCloud);
        }
        check_finite_points(cloud.points())
    }

    fn slice_bounds(&self, lidar_height: f64) -> Result<(f64, f64), GridMapError> {
        check(
            lidar_height.is_finite(),
            "lidar_height",
            lidar_height,
            "finite",
        )?;
        Ok((
            lidar_height - self.config.slice_below,
            lidar_height + self.config.slice_above,
        ))
    }

    /// The geometry and size (columns, rows) of the grid over `min`..`max` (world x, y) with
    /// the configured margin: its origin on a multiple of the resolution.
    pub(crate) fn empty_grid_geometry(
        &self,
        min: Vector2<f64>,
        max: Vector2<f64>,
    ) -> Result<(GridGeometry, u32, u32), GridMapError> {
        let r = self.config.resolution;
        let m = self.config.margin;
        let origin = Vector2::new(((min.x - m) / r).floor() * r, ((min.y - m) / r).floor() * r);
        let w = (((max.x + m - origin.x) / r).floor() + 1.0).max(1.0);
        let h = (((max.y + m - origin.y) / r).floor() + 1.0).max(1.0);
        let cells = w * h;
        let within = cells.is_finite() && cells <= self.config.max_cells as f64;
        if !within || w > f64::from(u32::MAX) || h > f64::from(u32::MAX) {
            return Err(GridMapError::TooManyCells {
                width: w as u64,
                height: h as u64,
                max_cells: self.config.max_cells,
            });
        }
        Ok((GridGeometry::try_new(origin, r)?, w as u32, h as u32))
    }

    /// A grid over `extent` (min and max world x, y) with the configured margin.
    pub(crate) fn empty_grid(
        &self,
        min: Vector2<f64>,
        max: Vector2<f64>,
        fill: CellState,
    ) -> Result<OccupancyGrid, GridMapError> {
        let (geometry, w, h) = self.empty_grid_geometry(min, max)?;
        OccupancyGrid::new(w, h, geometry, fill)
    }

    /// Mark occupied every cell holding at least `min_points` of `points` (world x, y), with
    /// the box of its points ([`CellExtent`]).
    pub(crate) fn mark_occupied(
        &self,
        grid: &mut OccupancyGrid,
        points: &[Vector2<f64>],
    ) -> Result<(), GridMapError> {
        let geometry = *grid.geometry();
        let (w, h) = (grid.width(), grid.height());
        let min_points = self.config.min_points;
        let mut counts = vec![0u32; w as usize * h as usize];
        let mut extents = vec![CellExtent::CENTRE; w as usize * h as usize];
        for p in points {
            let ((x, y), extent) = CellExtent::of_point(&geometry, *p);
            if x < 0 || y < 0 || x >= i64::from(w) || y >= i64::from(h) {
                continue;
            }
            let k = y as usize * w as usize + x as usize;
            counts[k] = counts[k].saturating_add(1);
            extents[k] = extents[k].union(extent);
        }
        for (k, (&n, &extent)) in counts.iter().zip(&extents).enumerate() {
            if n > 0 && n >= min_points {
                let cell = Cell::new((k % w as usize) as u32, (k / w as usize) as u32);
                grid.set_occupied_within(cell, extent)?;
            }
        }
        Ok(())
    }

    /// The occupancy grid of a map cloud (world frame) around the LiDAR height: a cell is
    /// occupied when at least `min_points` slice points fall in it; every other cell is free.
    ///
    /// # Errors
    /// [`GridMapError::EmptyCloud`], [`GridMapError::NonFinitePoints`],
    /// [`GridMapError::EmptySlice`] or [`GridMapError::TooManyCells`].
    pub fn build(
        &self,
        cloud: &PointCloud,
        lidar_height: f64,
    ) -> Result<OccupancyGrid, GridMapError> {
        Self::check_cloud(cloud)?;
        let (lo, hi) = self.slice_bounds(lidar_height)?;
        let slice: Vec<Vector2<f64>> = cloud
            .points()
            .iter()
            .filter(|p| (lo..=hi).contains(&f64::from(p.z)))
            .map(|p| Vector2::new(f64::from(p.x), f64::from(p.y)))
            .collect();
        let (min, max) = extent(slice.iter().copied()).ok_or(GridMapError::EmptySlice {
            min_z: lo,
            max_z: hi,
        })?;
        let mut grid = self.empty_grid(min, max, CellState::Free)?;
        self.mark_occupied(&mut grid, &slice)?;
        Ok(grid)
    }

    /// The occupancy grid of scans (each in its sensor frame, placed by `world_T_sensor`), with
    /// free space from ray casting: cells a ray from the sensor to a slice point crosses are free,
    /// cells holding points are occupied (occupied wins), all others unknown.
    ///
    /// # Errors
    /// As [`OccupancyGridBuilder::build`], for the scans together.
    pub fn build_from_scans(
        &self,
        scans: &[(Pose3, &PointCloud)],
        lidar_height: f64,
    ) -> Result<OccupancyGrid, GridMapError> {
        if scans.iter().all(|(_, c)| c.is_empty()) {
            return Err(GridMapError::EmptyCloud);
        }
        let (lo, hi) = self.slice_bounds(lidar_height)?;
        let mut rays: Vec<(Vector2<f64>, Vec<Vector2<f64>>)> = Vec::with_capacity(scans.len());
        for (pose, cloud) in scans {
            Self::check_cloud(cloud).or_else(|e| if cloud.is_empty() { Ok(()) } else { Err(e) })?;
            let origin = pose.translation.vector.xy();
            let hits: Vec<Vector2<f64>> = cloud
                .points()
                .iter()
                .map(|p| pose * Point3::new(f64::from(p.x), f64::from(p.y), f64::from(p.z)))
                .filter(|p| (lo..=hi).contains(&p.z))
                .map(|p| p.coords.xy())
                .collect();
            rays.push((origin, hits));
        }
        let all = rays
            .iter()
            .flat_map(|(o, h)| std::iter::once(*o).chain(h.iter().copied()));
        let (min, max) = extent(all).ok_or(GridMapError::EmptySlice {
            min_z: lo,
            max_z: hi,
        })?;
        if rays.iter().all(|(_, h)| h.is_empty()) {
            return Err(GridMapError::EmptySlice {
                min_z: lo,
                max_z: hi,
            });
        }
        let mut grid = self.empty_grid(min, max, CellState::Unknown)?;
        let hits: Vec<Vector2<f64>> = rays.iter().flat_map(|(_, h)| h.iter().copied()).collect();
        self.mark_occupied(&mut grid, &hits)?;
        for (origin, hits) in &rays {
            for hit in hits {
                clear_ray(&mut grid, *origin, *hit)?;
            }
        }
        Ok(grid)
    }
}

/// Smallest and largest x, y of `points`.
pub(crate) fn extent(
    points: impl Iterator<Item = Vector2<f64>>,
) -> Option<(Vector2<f64>, Vector2<f64>)> {
    points.fold(None, |acc, p| match acc {
        None => Some((p, p)),
        Some((lo, hi)) => Some((lo.inf(&p), hi.sup(&p))),
    })
}

/// Mark free every cell the segment from `from` to `to` crosses before the cell of `to`
/// (Amanatides-Woo traversal), leaving occupied cells as they are.
pub(crate) fn clear_ray(
    grid: &mut OccupancyGrid,
    from: Vector2<f64>,
    to: Vector2<f64>,
) -> Result<(), GridMapError> {
    let g = *grid.geometry();
    let (w, h) = (i64::from(grid.width()), i64::from(grid.height()));
    let mut result = Ok(());
    traverse(
        (from - g.origin) / g.resolution,
        (to - g.origin) / g.resolution,
        false,
        |x, y| {
            if result.is_ok() && x >= 0 && y >= 0 && x < w && y < h {
                let c = Cell::new(x as u32, y as u32);
                if grid.state(c) != CellState::Occupied {
                    result = grid.set(c, CellState::Free);
                }
            }
        },
    );
    result
}
