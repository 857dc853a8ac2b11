//! `GrowingMap`: the explorer's navigation map and localisation cloud, grown by the keyframes
//! added since the last decision instead of rendered afresh from all of them at every decision.

use std::borrow::Cow;
use std::collections::HashSet;

use gridmap::{FloorBandAccumulator, FloorMap, floor_hints_below};
use nalgebra::{Isometry3, Point3, Vector2};
use rustc_hash::FxHashMap;
use slam_core::{
    CloudError, GraphSlam, KeyframeCloudError, MapRegistrator, Optimizer, PointCloud, Pose3,
};

use crate::nav::NavError;
use crate::nav::config::NavigationMapConfig;
use crate::nav::error::ExplorationError;
use crate::nav::keyframe_batches::KeyframeBatches;
use crate::nav::navigation_map::NavigationMap;
use crate::nav::scan_blocks::{BLOCK_POINTS, ScanBlocks};

/// A rendered keyframe that moved farther than this share of a grid cell (or turned so far that
/// a point [`GrowingMap`]'s `range` away moved so far) since it was rendered calls for a full
/// render: half a cell keeps every cell within one of where a fresh render puts it.
const MOVED_CELLS: f64 = 0.5;

/// A full render also re-estimates the floor once the keyframes rendered have grown by this
/// factor since the last one: the floor of the new places is otherwise extrapolated from the
/// old ones (exact on one flat floor), and the full renders cost, summed, what a constant
/// number of renders of the final map costs.
const FLOOR_REFRESH_GROWTH: f64 = 1.5;

/// The navigation map ([`NavigationMap`]) of a walk's keyframes, one per square of `spacing`
/// metres (the first seen in it) plus the newest of each update, and their points thinned to
/// `voxel` for localisation. An update adds the keyframes that came since the last; everything
/// is rendered afresh (floor included) when a rendered keyframe moved by more than half a grid
/// cell (a loop closed) or the keyframes grew by half since the last full render.
pub(crate) struct GrowingMap {
    config: NavigationMapConfig,
    lidar_height: f64,
    spacing: f64,
    /// How far a turn is measured out (metres): the sensor's range.
    range: f64,
    /// Keyframes rendered: index and the pose they were rendered at.
    rendered: Vec<(usize, Pose3)>,
    squares: HashSet<(i64, i64)>,
    /// Keyframes looked at so far.
    seen: usize,
    band: Option<FloorBandAccumulator>,
    /// Keyframes rendered at the last full render.
    rendered_at_full: usize,
    cloud: VoxelCentroids,
    /// Full renders so far.
    full_renders: usize,
    /// Points a full render reads at once, [`BLOCK_POINTS`] (48 MB).
    batch_points: usize,
}

impl GrowingMap {
    /// An empty map; see the type's docs for `spacing`, `voxel` and `range`.
    pub(crate) fn new(
        config: NavigationMapConfig,
        lidar_height: f64,
        spacing: f64,
        voxel: f32,
        range: f64,
    ) -> Self {
        Self {
            config,
            lidar_height,
            spacing,
            range,
            rendered: Vec::new(),
            squares: HashSet::new(),
            seen: 0,
            band: None,
            rendered_at_full: 0,
            cloud: VoxelCentroids::new(voxel),
            full_renders: 0,
            batch_points: BLOCK_POINTS,
        }
    }

    /// Full renders so far.
    pub(crate) fn full_renders(&self) -> usize {
        self.full_renders
    }

    /// The navigation map and the localisation cloud with the keyframes `slam` has now.
    ///
    /// # Errors
    /// [`ExplorationError::Navigation`] with [`NavError::NavigationGrid`] when the grid or the
    /// floor cannot be built (or [`NavError::InvalidConfig`] for bad settings),
    /// [`ExplorationError::Map`] when the map cloud cannot be.
    pub(crate) fn update<R, C, O, E>(
        &mut self,
        slam: &GraphSlam<R, C, O>,
    ) -> Result<NavigationMap, ExplorationError<E>>
    where
        R: MapRegistrator,
        C: MapRegistrator,
        O: Optimizer<Pose3>,
        E: std::error::Error + Send + Sync + 'static,
    {
        let poses: Vec<Pose3> = slam.keyframe_trajectory().iter().map(|k| k.pose).collect();
        self.update_from(&EngineKeyframes { slam, poses })
    }

    /// [`Self::update`] with the walk's keyframes (`map_T_lidar` and points, in order).
    fn update_from<E: std::error::Error + Send + Sync + 'static>(
        &mut self,
        keyframes: &(impl Keyframes + ?Sized),
    ) -> Result<NavigationMap, ExplorationError<E>> {
        let cell = self.config.grid.resolution;
        let limit = MOVED_CELLS * cell;
        let moved = self.rendered.iter().any(|&(k, at)| {
            keyframes.pose(k).is_none_or(|now| {
                let d = at.inverse() * now;
                d.translation.vector.norm() + d.rotation.angle() * self.range > limit
            })
        });
        let grown = self.rendered.len() as f64
            >= FLOOR_REFRESH_GROWTH * self.rendered_at_full.max(1) as f64;
        let grid_error = |e| ExplorationError::Navigation(NavError::NavigationGrid(e));
        if self.band.is_none() || moved || grown {
            self.full_render(keyframes)?;
        } else {
            let fresh = self.pick(keyframes);
            let loaded = load(keyframes, &fresh)?;
            let scans = loaded.scans();
            if let Some(band) = self.band.as_mut() {
                band.add_scan_points(&scans).map_err(grid_error)?;
            }
            self.cloud.add(&scans).map_err(map_error)?;
            self.rendered
                .extend(fresh.iter().zip(&scans).map(|(&k, (pose, _))| (k, *pose)));
        }
        let band = self
            .band
            .as_ref()
            .ok_or(grid_error(gridmap::GridMapError::EmptyCloud))?;
        let occupancy = band.grid().map_err(grid_error)?;
        Ok(NavigationMap::from_parts(occupancy, band.floor().clone()))
    }

    /// The localisation cloud's points within `reach` metres of `at` (horizontally, map frame),
    /// in the order the whole cloud lists them: one pass over its voxels, not the whole cloud
    /// built and then filtered (6 ms a decision on the large building).
    pub(crate) fn cloud_within(&self, at: Vector2<f64>, reach: f64) -> PointCloud {
        self.cloud.within(at, reach)
    }

    /// Everything rendered afresh from `keyframes` at their current poses, their points read a
    /// batch at a time ([`KeyframeBatches`]): the floor from every batch (four passes), the
    /// band's grid grown over every batch, then each batch added to the band and the cloud. The
    /// same floor, grid and cloud as all the keyframes' points read at once and added as one
    /// batch (`FloorMap::estimate_from_scan_passes`, `FloorBandAccumulator::extend_over`).
    fn full_render<E: std::error::Error + Send + Sync + 'static>(
        &mut self,
        keyframes: &(impl Keyframes + ?Sized),
    ) -> Result<(), ExplorationError<E>> {
        let grid_error = |e| ExplorationError::Navigation(NavError::NavigationGrid(e));
        self.config
            .validate()
            .map_err(ExplorationError::Navigation)?;
        self.rendered.clear();
        self.squares.clear();
        self.seen = 0;
        let picked = self.pick(keyframes);
        let poses: Vec<Pose3> = picked
            .iter()
            .map(|&k| keyframes.pose(k).unwrap_or_else(Pose3::identity))
            .collect();
        let hints = floor_hints_below(&poses, self.lidar_height);
        let batches = KeyframeBatches::new(keyframes, &picked, self.batch_points);
        let floor = FloorMap::estimate_from_scan_passes(
            |visit| batches.pass(visit),
            &hints,
            &self.config.floor,
        );
        if let Some(e) = batches.error() {
            return Err(ExplorationError::Map(e));
        }
        let mut band = FloorBandAccumulator::new(
            self.config.grid.clone(),
            floor.map_err(grid_error)?,
            self.config.band.clone(),
        )
        .map_err(grid_error)?;
        let mut extended = Ok(());
        batches.pass(&mut |scans| {
            if extended.is_ok() {
                extended = band.extend_over(scans);
            }
        });
        if let Some(e) = batches.error() {
            return Err(ExplorationError::Map(e));
        }
        extended.map_err(grid_error)?;
        self.cloud.clear();
        let (mut added, mut thinned) = (Ok(()), Ok(()));
        batches.pass(&mut |scans| {
            if added.is_ok() && thinned.is_ok() {
                added = band.add_scan_points(scans);
                thinned = self.cloud.add(scans);
            }
        });
        if let Some(e) = batches.error() {
            return Err(ExplorationError::Map(e));
        }
        added.map_err(grid_error)?;
        thinned.map_err(map_error)?;
        self.band = Some(band);
        self.rendered = picked.iter().zip(&poses).map(|(&k, &p)| (k, p)).collect();
        self.rendered_at_full = self.rendered.len();
        self.full_renders += 1;
        Ok(())
    }

    /// The keyframes from the first not looked at yet that are the first in their square (by
    /// LiDAR position), and the newest when it is not one of them or rendered already.
    fn pick(&mut self, keyframes: &(impl Keyframes + ?Sized)) -> Vec<usize> {
        let mut picked = Vec::new();
        let count = keyframes.count();
        for (k, pose) in (self.seen..count).filter_map(|k| Some((k, keyframes.pose(k)?))) {
            let at = pose.translation.vector / self.spacing;
            if self
                .squares
                .insert((at.x.floor() as i64, at.y.floor() as i64))
            {
                picked.push(k);
            }
        }
        self.seen = count;
        if let Some(newest) = count.checked_sub(1)
            && picked.last() != Some(&newest)
            && self.rendered.last().map(|&(k, _)| k) != Some(newest)
        {
            picked.push(newest);
        }
        picked
    }
}

/// The walk's keyframes as the map is grown from them: each one's pose, and its scan read only
/// when it is rendered (an engine keeps older scans in a file,
/// [`GraphSlam::with_keyframe_store`]).
pub(crate) trait Keyframes {
    /// How many there are.
    fn count(&self) -> usize;
    /// Keyframe `k`'s `map_T_lidar`.
    fn pose(&self, k: usize) -> Option<Pose3>;
    /// Keyframe `k`'s scan (LiDAR frame).
    fn scan(&self, k: usize) -> Result<Cow<'_, PointCloud>, KeyframeCloudError>;
}

impl Keyframes for [(Pose3, &PointCloud)] {
    fn count(&self) -> usize {
        self.len()
    }

    fn pose(&self, k: usize) -> Option<Pose3> {
        self.get(k).map(|(pose, _)| *pose)
    }

    fn scan(&self, k: usize) -> Result<Cow<'_, PointCloud>, KeyframeCloudError> {
        Ok(self
            .get(k)
            .map_or_else(|| Cow::Owned(PointCloud::new()), |(_, c)| Cow::Borrowed(*c)))
    }
}

/// An engine's keyframes, their poses read once.
struct EngineKeyframes<'a, R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>> {
    slam: &'a GraphSlam<R, C, O>,
    poses: Vec<Pose3>,
}

impl<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>> Keyframes
    for EngineKeyframes<'_, R, C, O>
{
    fn count(&self) -> usize {
        self.poses.len()
    }

    fn pose(&self, k: usize) -> Option<Pose3> {
        self.poses.get(k).copied()
    }

    fn scan(&self, k: usize) -> Result<Cow<'_, PointCloud>, KeyframeCloudError> {
        self.slam
            .keyframe_scan(k)
            .map_or_else(|| Ok(Cow::Owned(PointCloud::new())), |s| s.map(|(_, c)| c))
    }
}

/// The poses and points of keyframes `picked` (an update's few new ones), read one at a time
/// into [`ScanBlocks`].
fn load<E: std::error::Error + Send + Sync + 'static>(
    keyframes: &(impl Keyframes + ?Sized),
    picked: &[usize],
) -> Result<ScanBlocks, ExplorationError<E>> {
    let mut blocks = ScanBlocks::default();
    for &k in picked {
        let pose = keyframes.pose(k).unwrap_or_else(Pose3::identity);
        let scan = keyframes.scan(k).map_err(ExplorationError::Map)?;
        blocks.push(pose, scan.points());
    }
    Ok(blocks)
}

/// A cloud error as the exploration names it.
fn map_error<E: std::error::Error + Send + Sync + 'static>(
    e: slam_core::CloudError,
) -> ExplorationError<E> {
    ExplorationError::Map(KeyframeCloudError::Cloud(e))
}

/// Points of placed scans thinned to one centroid per cubic voxel, added scan by scan: the
/// cloud [`PointCloud::voxel_downsample`] gives for the scans merged in the order added.
///
/// The large building's whole map holds about 2 million voxels: their keys are packed into a
/// `u64` and their slots into a `u32` (16-byte index entries, not 32); the rare voxel whose key
/// or slot does not fit is kept in a map of its own, so no two voxels ever share an entry.
pub(crate) struct VoxelCentroids {
    voxel: f32,
    /// Slots in `sums` by packed key ([`packed`]).
    index: FxHashMap<u64, u32>,
    /// Slots of the voxels whose key does not pack or whose slot passed `u32::MAX`.
    far: FxHashMap<[i64; 3], usize>,
    sums: Vec<([f64; 3], u32)>,
}

impl VoxelCentroids {
    pub(crate) fn new(voxel: f32) -> Self {
        Self {
            voxel,
            index: FxHashMap::default(),
            far: FxHashMap::default(),
            sums: Vec::new(),
        }
    }

    pub(crate) fn clear(&mut self) {
        self.index.clear();
        self.far.clear();
        self.sums.clear();
    }

    /// The slot of voxel `key`, a new one at the end of `sums` when it has none yet.
    fn slot(&mut self, key: [i64; 3]) -> usize {
        let packed = packed(key);
        if let Some(&slot) = packed.and_then(|p| self.index.get(&p)) {
            return slot as usize;
        }
        if let Some(&slot) = self.far.get(&key) {
            return slot;
        }
        let next = self.sums.len();
        self.sums.push(([0.0; 3], 0));
        match (packed, u32::try_from(next)) {
            (Some(p), Ok(slot)) => {
                self.index.insert(p, slot);
            }
            _ => {
                self.far.insert(key, next);
            }
        }
        next
    }

    /// Adds each scan's points moved by its pose (non-finite ones skipped), as
    /// [`PointCloud::transformed`] moves them.
    ///
    /// # Errors
    /// [`CloudError::InvalidVoxelSize`] unless the voxel is finite and positive.
    pub(crate) fn add(&mut self, scans: &[(Pose3, &[Point3<f32>])]) -> Result<(), CloudError> {
        if !(self.voxel.is_finite() && self.voxel > 0.0) {
            return Err(CloudError::InvalidVoxelSize { size: self.voxel });
        }
        let inv = 1.0 / f64::from(self.voxel);
        for (pose, points) in scans {
            let t: Isometry3<f32> = nalgebra::convert(*pose);
            for p in points.iter().map(|p| t * p) {
                if !p.iter().all(|v| v.is_finite()) {
                    continue;
                }
                let v = [f64::from(p.x), f64::from(p.y), f64::from(p.z)];
                let slot = self.slot(v.map(|c| (c * inv).floor() as i64));
                let (sum, count) = &mut self.sums[slot];
                for (s, c) in sum.iter_mut().zip(v) {
                    *s += c;
                }
                *count += 1;
            }
        }
        Ok(())
    }

    /// The centroids within `reach` metres of `at` horizontally, in the order their voxels
    /// were first met.
    pub(crate) fn within(&self, at: Vector2<f64>, reach: f64) -> PointCloud {
        // A square distance well inside or outside the reach settles a point; only those near
        // its edge take the (slow, exact) `hypot` the test is defined by.
        let (inner, outer) = (
            (reach * (1.0 - 1e-9)).powi(2),
            (reach * (1.0 + 1e-9)).powi(2),
        );
        // A voxel whose sum lies a metre beyond the reach on either axis (times its count) is
        // out without dividing: most of a large map's voxels.
        let slack = reach + 1.0;
        PointCloud::from_points(
            self.sums
                .iter()
                .filter(|(s, n)| {
                    let n = f64::from(*n);
                    (s[0] - n * at.x).abs() <= n * slack && (s[1] - n * at.y).abs() <= n * slack
                })
                .map(|(s, n)| centroid(s, *n))
                .filter(|p| {
                    let (dx, dy) = (f64::from(p.x) - at.x, f64::from(p.y) - at.y);
                    let d2 = dx * dx + dy * dy;
                    d2 <= inner || (d2 <= outer && dx.hypot(dy) <= reach)
                })
                .collect(),
        )
    }

    /// The centroids, in the order their voxels were first met.
    #[cfg(test)]
    pub(crate) fn cloud(&self) -> PointCloud {
        PointCloud::from_points(self.sums.iter().map(|(s, n)| centroid(s, *n)).collect())
    }
}

/// Voxel coordinates within 2^20 of the origin (105 km at 0.1 m) packed 21 bits an axis;
/// `None` farther out.
fn packed(key: [i64; 3]) -> Option<u64> {
    const HALF: i64 = 1 << 20;
    key.iter().try_fold(0u64, |packed, &c| {
        let offset = u64::try_from(c.checked_add(HALF)?).ok()?;
        (offset < 1 << 21).then_some(packed << 21 | offset)
    })
}

/// The centroid of `n` points summing to `sum`, as the map cloud stores it.
fn centroid(sum: &[f64; 3], n: u32) -> Point3<f32> {
    let n = f64::from(n);
    Point3::new(
        (sum[0] / n) as f32,
        (sum[1] / n) as f32,
        (sum[2] / n) as f32,
    )
}

#[cfg(test)]
#[path = "growing_map_tests.rs"]
mod tests;
