//! `FloorBandAccumulator`: the obstacle-band occupancy of scans added a batch at a time, so that
//! a map that grows keyframe by keyframe costs what its new scans cost, not what all of them do.

use nalgebra::{Point3, Vector2};
use slam_core::{PointCloud, Pose3};

use crate::band::{Height, ObstacleBandConfig, band_at, classify};
use crate::builder::OccupancyGridBuilder;
use crate::config::OccupancyGridConfig;
use crate::error::{GridMapError, check_finite_points};
use crate::extent::CellExtent;
use crate::floor::FloorMap;
use crate::occupancy::{CellState, OccupancyGrid};
use crate::rays::{below_top, clip_to_bounds, floor_i64, traverse};

/// The least and the greatest (x, y) of some points (metres, map frame).
type Extent = (Vector2<f64>, Vector2<f64>);

/// The cells of the grid so far, on the lattice of cells of `resolution` metres anchored at the
/// map origin: global cell `(x, y)` covers `[x r, (x + 1) r) x [y r, (y + 1) r)`.
#[derive(Clone, Debug)]
struct Window {
    /// Global cell of the window's first cell.
    x0: i64,
    y0: i64,
    width: usize,
    height: usize,
    /// Band points that ended in each cell (over all scans).
    hits: Vec<u32>,
    /// The box of those points in each cell.
    extents: Vec<CellExtent>,
    /// Whether a beam crossed each cell.
    crossed: Vec<bool>,
    /// The last scan (its number) that traced a beam to an obstacle, and to a free end, in each
    /// cell: one beam per end cell and kind a scan.
    hit_stamp: Vec<u32>,
    free_stamp: Vec<u32>,
}

impl Window {
    fn empty(x0: i64, y0: i64, width: usize, height: usize) -> Self {
        let cells = width * height;
        Self {
            x0,
            y0,
            width,
            height,
            hits: vec![0; cells],
            extents: vec![CellExtent::CENTRE; cells],
            crossed: vec![false; cells],
            hit_stamp: vec![0; cells],
            free_stamp: vec![0; cells],
        }
    }

    /// The index of global cell `(x, y)`, when it is in the window.
    #[inline]
    fn index(&self, x: i64, y: i64) -> Option<usize> {
        let (dx, dy) = (x - self.x0, y - self.y0);
        (dx >= 0 && dy >= 0 && (dx as usize) < self.width && (dy as usize) < self.height)
            .then(|| dy as usize * self.width + dx as usize)
    }

    /// This window's counts in a window over `x0, y0, width, height` that contains it (stamps
    /// start over: they only tell one scan's beams apart).
    fn regrown(&self, x0: i64, y0: i64, width: usize, height: usize) -> Self {
        let mut grown = Self::empty(x0, y0, width, height);
        for row in 0..self.height {
            let y = self.y0 + row as i64;
            let Some(start) = grown.index(self.x0, y) else {
                continue;
            };
            let from = row * self.width..(row + 1) * self.width;
            grown.hits[start..start + self.width].copy_from_slice(&self.hits[from.clone()]);
            grown.extents[start..start + self.width].copy_from_slice(&self.extents[from.clone()]);
            grown.crossed[start..start + self.width].copy_from_slice(&self.crossed[from]);
        }
        grown
    }
}

/// The occupancy of the obstacle band above a fixed floor ([`FloorMap`]) from scans added a
/// batch at a time: the grid [`OccupancyGridBuilder::build_floor_band_from_scans`] gives for all
/// of them (which adds them as one batch), at the cost of the scans added.
///
/// A cell is occupied when at least `min_points` band points (over all scans) ended in it, else
/// free when a beam crossed it, else unknown. Both are counts over the scans, so the order of
/// the scans does not matter, with one exception: a beam to an overhang (a point above the
/// band) is traced only up to the edge of the grid at the time its batch is added (the extent
/// of the origins, band points and floor points so far, plus the margin), so a cell that a later
/// batch brings into the grid stays unknown where the batches added together would have freed
/// it. Beams to band points and to the floor lie inside the grid by construction.
///
/// The floor is fixed: a walk that finds more floor (another storey, a ramp) takes a new
/// accumulator over a new [`FloorMap`].
///
/// ```
/// use gridmap::{CellState, FloorBandAccumulator, FloorMap, ObstacleBandConfig, OccupancyGridConfig};
/// use nalgebra::Point3;
/// use slam_core::{PointCloud, Pose3};
///
/// // A sensor 0.6 m above a flat floor sees a wall 2 m ahead and the floor before it.
/// let mut points = vec![Point3::new(2.0f32, 0.0, 0.0)];
/// points.extend((1..15).map(|i| Point3::new(0.1 * i as f32, 0.0, -0.6)));
/// let scan = PointCloud::from_points(points);
/// let floor = FloorMap::flat(0.0)?;
/// let config = OccupancyGridConfig { resolution: 0.1, ..Default::default() };
/// let mut map = FloorBandAccumulator::new(config, floor, ObstacleBandConfig::default())?;
/// map.add_scans(&[(Pose3::translation(0.0, 0.0, 0.6), &scan)])?;
/// let grid = map.grid()?;
/// let at = |x: f64, y: f64| {
///     let (cx, cy) = grid.geometry().cell_coords(nalgebra::Vector2::new(x, y));
///     grid.state(slam_core::Cell::new(cx as u32, cy as u32))
/// };
/// assert_eq!(at(2.05, 0.05), CellState::Occupied);
/// assert_eq!(at(1.05, 0.05), CellState::Free);
/// assert_eq!(at(1.05, 0.45), CellState::Unknown);
/// # Ok::<(), gridmap::GridMapError>(())
/// ```
#[derive(Clone, Debug)]
pub struct FloorBandAccumulator {
    builder: OccupancyGridBuilder,
    floor: FloorMap,
    band: ObstacleBandConfig,
    /// Extent (x, y) of the origins, band points and floor points so far.
    bounds: Option<Extent>,
    any_hit: bool,
    window: Option<Window>,
    /// Scans added so far (numbers the stamps).
    scans: u32,
}

impl FloorBandAccumulator {
    /// An empty accumulator over `floor`.
    ///
    /// # Errors
    /// [`GridMapError::InvalidConfig`] for invalid grid or band settings.
    pub fn new(
        config: OccupancyGridConfig,
        floor: FloorMap,
        band: ObstacleBandConfig,
    ) -> Result<Self, GridMapError> {
        band.validate()?;
        Ok(Self {
            builder: OccupancyGridBuilder::new(config)?,
            floor,
            band,
            bounds: None,
            any_hit: false,
            window: None,
            scans: 0,
        })
    }

    /// The floor the band is measured from.
    #[must_use]
    pub fn floor(&self) -> &FloorMap {
        &self.floor
    }

    /// Scans added so far (empty ones included).
    #[must_use]
    pub fn scans(&self) -> usize {
        self.scans as usize
    }

    /// Adds `scans` (each in its sensor frame, placed by `world_T_sensor`) as one batch. Nothing
    /// is added when it fails.
    ///
    /// # Errors
    /// [`GridMapError::NonFinitePoints`] for a scan with a non-finite point,
    /// [`GridMapError::TooManyCells`] when the grid would grow beyond `max_cells`.
    pub fn add_scans(&mut self, scans: &[(Pose3, &PointCloud)]) -> Result<(), GridMapError> {
        let points: Vec<(Pose3, &[Point3<f32>])> =
            scans.iter().map(|(pose, c)| (*pose, c.points())).collect();
        self.add_scan_points(&points)
    }

    /// [`Self::add_scans`] for scans given as their points alone (a caller that keeps many
    /// scans' points in a few large buffers rather than a cloud each).
    ///
    /// # Errors
    /// As [`Self::add_scans`].
    pub fn add_scan_points(
        &mut self,
        scans: &[(Pose3, &[Point3<f32>])],
    ) -> Result<(), GridMapError> {
        // 1. The extent with this batch, checked before anything changes.
        let (bounds, any_hit) = self.extent_with(scans)?;
        let Some((min, max)) = bounds else {
            return Ok(());
        };
        let mut window = self.window_over(min, max)?;
        // 2. The beams, on the grown window.
        let r = self.builder.config().resolution;
        let (x0, y0) = (window.x0, window.y0);
        let (lo, hi) = (
            Vector2::new(x0 as f64, y0 as f64),
            Vector2::new(
                (x0 + window.width as i64) as f64,
                (y0 + window.height as i64) as f64,
            ),
        );
        let mut beams: Vec<(Vector2<f64>, Vector2<f64>, bool)> = Vec::new();
        for (pose, cloud) in scans {
            self.scans = if let Some(n) = self.scans.checked_add(1) {
                n
            } else {
                // Stamps start over (after 2^32 scans).
                window.hit_stamp.fill(0);
                window.free_stamp.fill(0);
                1
            };
            let stamp = self.scans;
            let origin = Point3::from(pose.translation.vector);
            beams.clear();
            for p in world_points(pose, cloud) {
                let (band_lo, band_hi) = band_at(&self.floor, &self.band, p.x, p.y);
                let kind = classify(p.z, (band_lo, band_hi));
                let Some((a, b)) = below_top(origin, p, band_hi) else {
                    continue;
                };
                let Some((a, b, cut)) =
                    clip_to_bounds(a.coords.xy() / r, b.coords.xy() / r, lo, hi)
                else {
                    continue;
                };
                let end = window.index(floor_i64(b.x), floor_i64(b.y));
                if kind == Height::Obstacle && !cut {
                    if let Some(i) = end {
                        window.hits[i] = window.hits[i].saturating_add(1);
                        let within = Vector2::new(b.x - b.x.floor(), b.y - b.y.floor());
                        window.extents[i] = window.extents[i].union(CellExtent::at(within));
                        if window.hit_stamp[i] == stamp {
                            continue;
                        }
                        window.hit_stamp[i] = stamp;
                    }
                    beams.push((a, b, false));
                } else {
                    if let Some(i) = end {
                        if window.free_stamp[i] == stamp {
                            continue;
                        }
                        window.free_stamp[i] = stamp;
                    }
                    beams.push((a, b, true));
                }
            }
            for &(a, b, include_end) in &beams {
                traverse(a, b, include_end, |x, y| {
                    if let Some(i) = window.index(x, y) {
                        window.crossed[i] = true;
                    }
                });
            }
        }
        self.window = Some(window);
        self.bounds = bounds;
        self.any_hit = any_hit;
        Ok(())
    }

    /// Grows the grid to the extent adding `scans` would give it, without adding them: for a
    /// caller that adds a map's scans a batch at a time (reading them from a file, say) and
    /// wants the grid of adding them all as one batch. Extended over every batch first, the
    /// accumulator then traces each batch's beams to overhangs up to the edge of the whole
    /// map's grid, so adding the batches in order gives the grid [`Self::add_scan_points`]
    /// gives for all of them at once. Nothing changes when it fails.
    ///
    /// # Errors
    /// As [`Self::add_scans`].
    pub fn extend_over(&mut self, scans: &[(Pose3, &[Point3<f32>])]) -> Result<(), GridMapError> {
        let (bounds, _) = self.extent_with(scans)?;
        let Some((min, max)) = bounds else {
            return Ok(());
        };
        self.window = Some(self.window_over(min, max)?);
        self.bounds = bounds;
        Ok(())
    }

    /// The extent (x, y) of the origins, band points and floor points so far and in `scans`,
    /// and whether any point so far or in `scans` lies in the band.
    fn extent_with(
        &self,
        scans: &[(Pose3, &[Point3<f32>])],
    ) -> Result<(Option<Extent>, bool), GridMapError> {
        let mut bounds = self.bounds;
        let mut any_hit = self.any_hit;
        for (pose, cloud) in scans {
            check_finite_points(cloud)?;
            let mut grow = |p: Vector2<f64>| {
                bounds = Some(bounds.map_or((p, p), |(lo, hi)| (lo.inf(&p), hi.sup(&p))));
            };
            grow(pose.translation.vector.xy());
            for p in world_points(pose, cloud) {
                match classify(p.z, band_at(&self.floor, &self.band, p.x, p.y)) {
                    Height::Obstacle => {
                        any_hit = true;
                        grow(p.coords.xy());
                    }
                    Height::Floor => grow(p.coords.xy()),
                    Height::Overhang => {}
                }
            }
        }
        Ok((bounds, any_hit))
    }

    /// The window over `min`..`max` (the builder's margin added): the current one when it
    /// covers those cells already, else the current one's counts in a new one.
    fn window_over(
        &mut self,
        min: Vector2<f64>,
        max: Vector2<f64>,
    ) -> Result<Window, GridMapError> {
        let (x0, y0, width, height) = self.cells_over(min, max)?;
        Ok(match self.window.take() {
            Some(w) if (w.x0, w.y0, w.width, w.height) == (x0, y0, width, height) => w,
            Some(w) => w.regrown(x0, y0, width, height),
            None => Window::empty(x0, y0, width, height),
        })
    }

    /// The occupancy grid of the scans added so far.
    ///
    /// # Errors
    /// [`GridMapError::EmptyCloud`] when no scan with points was added,
    /// [`GridMapError::EmptyBand`] when no point lies in the band.
    pub fn grid(&self) -> Result<OccupancyGrid, GridMapError> {
        let (Some((min, max)), Some(window)) = (self.bounds, &self.window) else {
            return Err(GridMapError::EmptyCloud);
        };
        if !self.any_hit {
            return Err(GridMapError::EmptyBand {
                above_floor: self.band.above_floor,
                up_to: self.band.up_to,
            });
        }
        let mut grid = self.builder.empty_grid(min, max, CellState::Unknown)?;
        let min_points = self.builder.config().min_points;
        for (i, (&hits, &crossed)) in window.hits.iter().zip(&window.crossed).enumerate() {
            let cell = slam_core::Cell::new((i % window.width) as u32, (i / window.width) as u32);
            if hits >= min_points {
                grid.set_occupied_within(cell, window.extents[i])?;
            } else if crossed {
                grid.set(cell, CellState::Free)?;
            }
        }
        Ok(grid)
    }

    /// The global cells of the grid over `min`..`max` (the builder's margin added): its first
    /// cell and its size, as [`OccupancyGridBuilder`]'s grids have them.
    fn cells_over(
        &self,
        min: Vector2<f64>,
        max: Vector2<f64>,
    ) -> Result<(i64, i64, usize, usize), GridMapError> {
        let (geometry, width, height) = self.builder.empty_grid_geometry(min, max)?;
        let (origin, r) = (geometry.origin, geometry.resolution);
        Ok((
            (origin.x / r).round() as i64,
            (origin.y / r).round() as i64,
            width as usize,
            height as usize,
        ))
    }
}

/// The points of `cloud` in the world frame.
pub(crate) fn world_points<'a>(
    pose: &'a Pose3,
    cloud: &'a [Point3<f32>],
) -> impl Iterator<Item = Point3<f64>> + 'a {
    cloud
        .iter()
        .map(move |p| pose * Point3::new(f64::from(p.x), f64::from(p.y), f64::from(p.z)))
}

#[cfg(test)]
#[path = "band_accumulator_tests.rs"]
mod tests;
