//! The floor under the robot's paths, per tile of about a metre: the lowest dense band of points
//! near a reference height that starts at the robot's own feet and spreads from tile to tile.

use std::collections::VecDeque;

use nalgebra::{Point3, Vector2};
use slam_core::{InvalidSetting, PointCloud, Pose3};

use crate::error::{GridMapError, check};

/// Settings of [`FloorMap::estimate`]. Lengths in metres.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct FloorConfig {
    /// Side of a floor tile, 1.0 m: one floor height per tile.
    pub tile: f64,
    /// A tile's floor is searched within this distance above and below its reference height (the
    /// hints in it, else the floor of the neighbouring tiles already estimated), 0.15 m: a
    /// surface farther from the reference (a 0.2 m step, a crate's top) is not taken for floor.
    pub search: f64,
    /// Height of the bins the search counts points in, 0.02 m.
    pub bin: f64,
    /// A bin is dense when it holds at least this many points, 5: the floor is the mean height of
    /// the points in the lowest dense bin and the bin above it. Tiles with no dense bin take
    /// their neighbours' floor.
    pub min_points: u32,
    /// The floor lies within this distance of the hints' heights, 1.0 m: points farther above
    /// or below them (most of the walls, the ceiling) are not looked at.
    pub span: f64,
    /// The largest number of tiles allocated (guards against a stray far point), 10,000,000.
    pub max_tiles: u64,
}

impl Default for FloorConfig {
    fn default() -> Self {
        Self {
            tile: 1.0,
            search: 0.15,
            bin: 0.02,
            min_points: 5,
            span: 1.0,
            max_tiles: 10_000_000,
        }
    }
}

impl FloorConfig {
    /// Check every setting.
    ///
    /// # Errors
    /// [`GridMapError::InvalidConfig`] for a tile, search, bin or span that is not finite and
    /// positive,
    /// a bin larger than the search window (`2 search`) or below a 10,000th of it, or
    /// `min_points == 0`.
    pub fn validate(&self) -> Result<(), GridMapError> {
        for (setting, v) in [
            ("FloorConfig::tile", self.tile),
            ("FloorConfig::search", self.search),
            ("FloorConfig::bin", self.bin),
            ("FloorConfig::span", self.span),
        ] {
            check(v.is_finite() && v > 0.0, setting, v, "finite and positive")?;
        }
        check(
            self.bin <= 2.0 * self.search && 2.0 * self.search <= 10_000.0 * self.bin,
            "FloorConfig::bin",
            self.bin,
            "from 2 FloorConfig::search / 10,000 to 2 FloorConfig::search",
        )?;
        check(
            self.min_points > 0,
            "FloorConfig::min_points",
            f64::from(self.min_points),
            "at least 1",
        )?;
        Ok(())
    }
}

/// Floor height (map frame z, metres) per square tile, for taking obstacles from a band above the
/// floor ([`ObstacleBandConfig`](crate::ObstacleBandConfig)).
///
/// [`FloorMap::estimate`] finds it from a map cloud and floor hints (points on the floor under the
/// robot, e.g. its feet at its poses: [`floor_hints_below`]); [`FloorMap::flat`] is one height
/// everywhere. Outside its tiles a query takes the nearest tile.
#[derive(Clone, Debug, PartialEq)]
pub struct FloorMap {
    origin: Vector2<f64>,
    tile: f64,
    width: u32,
    height: u32,
    floors: Vec<f64>,
    /// Tiles whose floor was measured (the others inherited it).
    measured: usize,
}

impl FloorMap {
    /// One floor height `z` (metres, map frame) everywhere.
    ///
    /// # Errors
    /// [`GridMapError::InvalidConfig`] for a non-finite `z`.
    pub fn flat(z: f64) -> Result<Self, GridMapError> {
        check(z.is_finite(), "FloorMap::flat z", z, "finite")?;
        Ok(Self {
            origin: Vector2::zeros(),
            tile: 1.0,
            width: 1,
            height: 1,
            floors: vec![z],
            measured: 0,
        })
    }

    /// The floor of `cloud` (map frame, z up), per tile of `config.tile` over the extent of its
    /// points within `config.span` of the hints' heights (one flat tile at the hints' mean height
    /// when there is none).
    ///
    /// `hints` are points on the floor under the robot's paths (map frame; the feet of the robot
    /// at its poses, or the LiDAR's positions lowered by its height above the ground: see
    /// [`floor_hints_below`]); they need not be exact, only within `config.search` of the floor.
    /// The estimate grows from the tiles holding hints to their neighbours, breadth first: each
    /// tile searches `config.search` around its reference height (the mean of its hints, else the
    /// mean floor of its neighbours estimated before it) for the lowest dense bin of points, and
    /// a tile without one inherits the reference. So the floor follows the building's floor from
    /// where the robot stood, and a crate's top or a table is never the floor (it lies more than
    /// `search` above the floor around it).
    ///
    /// # Errors
    /// [`GridMapError::InvalidConfig`] for invalid settings or a non-finite hint,
    /// [`GridMapError::NoFloorHint`] without hints, [`GridMapError::EmptyCloud`],
    /// [`GridMapError::NonFinitePoints`], [`GridMapError::TooManyCells`] past
    /// `config.max_tiles`.
    pub fn estimate(
        cloud: &PointCloud,
        hints: &[Point3<f64>],
        config: &FloorConfig,
    ) -> Result<Self, GridMapError> {
        crate::OccupancyGridBuilder::check_cloud(cloud)?;
        Self::estimate_points(&CloudPasses(cloud.points()), hints, config)
    }

    /// [`FloorMap::estimate`] for scans, each in its sensor frame placed by `world_T_sensor`.
    ///
    /// # Errors
    /// As [`FloorMap::estimate`], for the scans together.
    pub fn estimate_from_scans(
        scans: &[(Pose3, &PointCloud)],
        hints: &[Point3<f64>],
        config: &FloorConfig,
    ) -> Result<Self, GridMapError> {
        let points: Vec<(Pose3, &[Point3<f32>])> =
            scans.iter().map(|(pose, c)| (*pose, c.points())).collect();
        Self::estimate_from_scan_points(&points, hints, config)
    }

    /// [`FloorMap::estimate_from_scans`] for scans given as their points alone (a caller that
    /// keeps many scans' points in a few large buffers rather than a cloud each).
    ///
    /// # Errors
    /// As [`FloorMap::estimate_from_scans`].
    pub fn estimate_from_scan_points(
        scans: &[(Pose3, &[Point3<f32>])],
        hints: &[Point3<f64>],
        config: &FloorConfig,
    ) -> Result<Self, GridMapError> {
        Self::estimate_from_scan_passes(|visit| visit(scans), hints, config)
    }

    /// [`FloorMap::estimate_from_scan_points`] for scans handed over in batches, pass after
    /// pass: `scans` gives every batch to its argument, in order, each time it is called (four
    /// times), the same scans in the same order every time. For a caller that reads a map's
    /// scans from a file a batch at a time rather than holding them all in memory; the floor is
    /// the one [`FloorMap::estimate_from_scan_points`] gives for all the batches' scans in
    /// order.
    ///
    /// # Errors
    /// As [`FloorMap::estimate_from_scans`].
    pub fn estimate_from_scan_passes(
        scans: impl Fn(&mut dyn FnMut(&[(Pose3, &[Point3<f32>])])),
        hints: &[Point3<f64>],
        config: &FloorConfig,
    ) -> Result<Self, GridMapError> {
        let (mut any, mut bad) = (false, 0usize);
        scans(&mut |batch| {
            for (_, c) in batch {
                any |= !c.is_empty();
                bad += c
                    .iter()
                    .filter(|p| !p.iter().all(|v| v.is_finite()))
                    .count();
            }
        });
        if !any {
            return Err(GridMapError::EmptyCloud);
        }
        if bad > 0 {
            return Err(GridMapError::NonFinitePoints { count: bad });
        }
        // Transformed on every pass rather than stored: a map's scans hold millions of points.
        Self::estimate_points(&ScanPasses(scans), hints, config)
    }

    fn estimate_points(
        points: &impl PointPasses,
        hints: &[Point3<f64>],
        config: &FloorConfig,
    ) -> Result<Self, GridMapError> {
        config.validate()?;
        if hints.is_empty() {
            return Err(GridMapError::NoFloorHint);
        }
        if let Some(value) = hints
            .iter()
            .flat_map(|h| h.iter().copied())
            .find(|v| !v.is_finite())
        {
            let bad = InvalidSetting {
                setting: "FloorMap::estimate hints",
                value,
                expected: "finite",
            };
            return Err(bad.into());
        }
        let (mut lo, mut hi) = (
            Vector2::repeat(f64::INFINITY),
            Vector2::repeat(f64::NEG_INFINITY),
        );
        points.pass(|p| {
            lo = lo.inf(&p.coords.xy());
            hi = hi.sup(&p.coords.xy());
        });
        if lo.x > hi.x {
            // No point near the hints' heights: one tile at the hints' mean height.
            let mean = hints.iter().map(|h| h.z).sum::<f64>() / hints.len() as f64;
            return Self::flat(mean);
        }
        let t = config.tile;
        let origin = Vector2::new((lo.x / t).floor() * t, (lo.y / t).floor() * t);
        let w = ((hi.x - origin.x) / t).floor() + 1.0;
        let h = ((hi.y - origin.y) / t).floor() + 1.0;
        let tiles = w * h;
        if !(tiles.is_finite() && tiles <= config.max_tiles as f64) {
            return Err(GridMapError::TooManyCells {
                width: w as u64,
                height: h as u64,
                max_cells: config.max_tiles,
            });
        }
        let (w, h) = (w as u32, h as u32);
        let mut map = Self {
            origin,
            tile: t,
            width: w,
            height: h,
            floors: vec![f64::NAN; w as usize * h as usize],
            measured: 0,
        };
        let (start, z) = map.heights_by_tile(points);
        // Reference heights: the mean of the hints in each tile.
        let mut hint_sum = vec![(0.0, 0u32); map.floors.len()];
        for hint in hints {
            let s = &mut hint_sum[map.tile_index(hint.x, hint.y)];
            s.0 += hint.z;
            s.1 += 1;
        }
        let mut queue: VecDeque<usize> = VecDeque::new();
        let mut queued = vec![false; map.floors.len()];
        for (k, s) in hint_sum.iter().enumerate() {
            if s.1 > 0 {
                queue.push_back(k);
                queued[k] = true;
            }
        }
        let mut histogram = Vec::new();
        while let Some(k) = queue.pop_front() {
            let (x, y) = (k % w as usize, k / w as usize);
            let neighbours = [
                (x > 0).then(|| k - 1),
                (x + 1 < w as usize).then(|| k + 1),
                (y > 0).then(|| k - w as usize),
                (y + 1 < h as usize).then(|| k + w as usize),
            ];
            let reference = if hint_sum[k].1 > 0 {
                hint_sum[k].0 / f64::from(hint_sum[k].1)
            } else {
                let known: Vec<f64> = neighbours
                    .iter()
                    .flatten()
                    .map(|&n| map.floors[n])
                    .filter(|f| !f.is_nan())
                    .collect();
                known.iter().sum::<f64>() / known.len() as f64
            };
            let heights = &z[start[k] as usize..start[k + 1] as usize];
            map.floors[k] = match lowest_dense_band(heights, reference, config, &mut histogram) {
                Some(f) => {
                    map.measured += 1;
                    f
                }
                None => reference,
            };
            for n in neighbours.into_iter().flatten() {
                if !queued[n] {
                    queued[n] = true;
                    queue.push_back(n);
                }
            }
        }
        Ok(map)
    }

    /// The heights of `points` sorted by tile (counting sort): tile `k`'s are
    /// `z[start[k]..start[k + 1]]`.
    fn heights_by_tile(&self, points: &impl PointPasses) -> (Vec<u32>, Vec<f32>) {
        let mut start = vec![0u32; self.floors.len() + 1];
        points.pass(|p| start[self.tile_index(p.x, p.y) + 1] += 1);
        for i in 1..start.len() {
            start[i] += start[i - 1];
        }
        let mut fill = start.clone();
        let mut z = vec![0f32; start[start.len() - 1] as usize];
        points.pass(|p| {
            let k = self.tile_index(p.x, p.y);
            z[fill[k] as usize] = p.z as f32;
            fill[k] += 1;
        });
        (start, z)
    }

    /// Index of the tile containing (x, y), clamped to the tiles.
    #[inline]
    fn tile_index(&self, x: f64, y: f64) -> usize {
        // Truncation is the floor for the non-negative values kept; NaN becomes 0.
        let clamp = |v: f64, n: u32| (v.max(0.0) as u64).min(u64::from(n) - 1) as usize;
        let inv = 1.0 / self.tile;
        let tx = clamp((x - self.origin.x) * inv, self.width);
        let ty = clamp((y - self.origin.y) * inv, self.height);
        ty * self.width as usize + tx
    }

    /// This floor with every tile's height kept within `lo`..=`hi` (metres): for a floor known
    /// to lie at one level (a storey of a building), whose estimate a stairwell drags down (over
    /// a flight the lowest dense band is a step, and the tiles beside it follow).
    ///
    /// # Errors
    /// [`GridMapError::InvalidConfig`] naming `FloorMap::clamped` for bounds that are not finite
    /// or not in order.
    pub fn clamped(mut self, lo: f64, hi: f64) -> Result<Self, GridMapError> {
        check(lo.is_finite(), "FloorMap::clamped lo", lo, "finite")?;
        check(
            hi.is_finite() && hi >= lo,
            "FloorMap::clamped hi",
            hi,
            "finite and at least lo",
        )?;
        for z in &mut self.floors {
            *z = z.clamp(lo, hi);
        }
        Ok(self)
    }

    /// The floor height (metres, map frame z) under map point (x, y): that of the tile containing
    /// it, or of the nearest tile outside the tiles.
    #[inline]
    #[must_use]
    pub fn floor_at(&self, x: f64, y: f64) -> f64 {
        self.floors[self.tile_index(x, y)]
    }

    /// Tiles (columns, rows), the tile side (metres) and the outer corner of tile (0, 0).
    #[must_use]
    pub fn tiles(&self) -> (u32, u32, f64, Vector2<f64>) {
        (self.width, self.height, self.tile, self.origin)
    }

    /// How many tiles had a dense floor band of their own (the others took their neighbours').
    #[must_use]
    pub fn measured_tiles(&self) -> usize {
        self.measured
    }
}

/// Points (map frame) visited pass after pass, the same points in the same order on each: the
/// estimate looks at them three times (their extent, then their tiles, then their heights).
trait PointPasses {
    /// Calls `visit` with every point, in order.
    fn pass(&self, visit: impl FnMut(Point3<f64>));
}

/// A map cloud's points.
struct CloudPasses<'a>(&'a [Point3<f32>]);

impl PointPasses for CloudPasses<'_> {
    fn pass(&self, mut visit: impl FnMut(Point3<f64>)) {
        for p in self.0 {
            visit(Point3::new(f64::from(p.x), f64::from(p.y), f64::from(p.z)));
        }
    }
}

/// Placed scans handed over in batches ([`FloorMap::estimate_from_scan_passes`]).
struct ScanPasses<F>(F);

impl<F: Fn(&mut dyn FnMut(&[(Pose3, &[Point3<f32>])]))> PointPasses for ScanPasses<F> {
    fn pass(&self, mut visit: impl FnMut(Point3<f64>)) {
        (self.0)(&mut |batch| {
            for (pose, cloud) in batch {
                for p in *cloud {
                    visit(pose * Point3::new(f64::from(p.x), f64::from(p.y), f64::from(p.z)));
                }
            }
        });
    }
}

/// The floor among `heights` within `config.search` of `reference`: the mean of the points in the
/// lowest bin holding `min_points` or more and the bin above it; `None` without such a bin.
fn lowest_dense_band(
    heights: &[f32],
    reference: f64,
    config: &FloorConfig,
    histogram: &mut Vec<u32>,
) -> Option<f64> {
    let lo = reference - config.search;
    let bins = ((2.0 * config.search / config.bin).ceil() as usize).max(1);
    histogram.clear();
    histogram.resize(bins, 0);
    let bin_of = |z: f32| {
        let b = (f64::from(z) - lo) / config.bin;
        (b >= 0.0 && b < bins as f64).then_some(b as usize)
    };
    for &z in heights {
        if let Some(b) = bin_of(z) {
            histogram[b] += 1;
        }
    }
    let first = histogram.iter().position(|&n| n >= config.min_points)?;
    let (mut sum, mut n) = (0.0, 0u32);
    for &z in heights {
        if bin_of(z).is_some_and(|b| b == first || b == first + 1) {
            sum += f64::from(z);
            n += 1;
        }
    }
    Some(sum / f64::from(n))
}

/// Floor hints below sensor (or body) poses: each pose's position lowered by `height_above_floor`
/// metres along the map's z axis (Spot: the body frame is 0.50 m above the ground, the default
/// LiDAR mounting 0.80 m).
#[must_use]
pub fn floor_hints_below(poses: &[Pose3], height_above_floor: f64) -> Vec<Point3<f64>> {
    poses
        .iter()
        .map(|p| {
            let t = p.translation.vector;
            Point3::new(t.x, t.y, t.z - height_above_floor)
        })
        .collect()
}
