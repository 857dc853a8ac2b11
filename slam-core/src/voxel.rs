//! Voxel-grid downsampling: one point per occupied voxel, at the centroid of the points inside.

use std::cell::RefCell;

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;
use rustc_hash::FxHashMap;

use crate::cloud::PointCloud;
use crate::error::CloudError;

/// Per-voxel running sums.
#[derive(Clone, Copy)]
struct Accumulator {
    sum: Vector3<f64>,
    intensity: f64,
    time: f64,
    count: u32,
    /// The ring of the voxel's first point (rings are labels, not averaged).
    ring: u16,
}

/// Points keyed a chunk when keys are computed on all cores.
const KEY_CHUNK: usize = 4096;

/// Voxels from the origin within which every voxel key fits (2^62, half the keys' range).
const KEYABLE_VOXELS: f64 = 4.611_686_018_427_388e18;

/// 2^63, exact in f64: the first voxel coordinate an i64 key cannot hold.
const TWO_POW_63: f64 = (1u64 << 63) as f64;

/// Integer voxel coordinates of `p`, `Ok(None)` when `p` is not finite, `Err(())` when a finite
/// coordinate is more than 2^63 voxels from the origin.
#[inline]
fn voxel_key(p: &Point3<f32>, inv: f64) -> Result<Option<(i64, i64, i64)>, ()> {
    if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
        return Ok(None);
    }
    let f = |v: f32| {
        let x = f64::from(v) * inv;
        // 2^63 is exact in f64; i64 keys reach every finite point a metre-scale voxel can see
        // (i32 keys lost finite points beyond 2 m at 1 nm voxels).
        if !(-TWO_POW_63..TWO_POW_63).contains(&x) {
            return Err(());
        }
        // Truncate, then step down for negatives: `f64::floor` is a library call on baseline
        // x86-64, and this loop runs for every point of every scan. The step cannot wrap: a
        // truncated value above `x` is negative.
        let t = x as i64;
        Ok(if (t as f64) > x { t - 1 } else { t })
    };
    Ok(Some((f(p.x)?, f(p.y)?, f(p.z)?)))
}

/// Why the packed keys could not be used for a point.
#[derive(Clone, Copy, Debug)]
enum Fallback {
    /// Beyond what packed keys hold: the general keys are needed.
    Wide,
    /// Beyond what any key holds (an error).
    OutOfRange,
}

/// Half the span of a packed axis: 21 bits, offset so that negative voxels fit.
const PACK_HALF: i64 = 1 << 20;

/// Integer voxel coordinates packed 21 bits an axis into one `u64` (a hash key half the size
/// of three `i64` and hashed with one multiply), when each is within `[-2^20, 2^20)`; `None`
/// otherwise, for the caller to key that voxel another way. Distinct coordinates in range give
/// distinct keys.
///
/// ```
/// use slam_core::pack_voxel_key;
///
/// assert_ne!(pack_voxel_key((1, 0, 0)), pack_voxel_key((0, 1, 0)));
/// assert!(pack_voxel_key((-(1 << 20), 0, (1 << 20) - 1)).is_some());
/// assert_eq!(pack_voxel_key((1 << 20, 0, 0)), None);
/// ```
#[inline]
#[must_use]
pub fn pack_voxel_key((x, y, z): (i64, i64, i64)) -> Option<u64> {
    let axis = |v: i64| {
        let u = v.checked_add(PACK_HALF)?;
        u64::try_from(u).ok().filter(|&u| u < (1 << 21))
    };
    Some(axis(x)? | (axis(y)? << 21) | (axis(z)? << 42))
}

/// Half the packed span in voxels, as a float: a coordinate strictly within it floors to a
/// packable voxel.
const PACK_HALF_F64: f64 = PACK_HALF as f64;

/// The packed key of `p`'s voxel: `Ok(None)` when `p` is not finite, [`Fallback::Wide`] when
/// its voxel is beyond what packed keys hold, [`Fallback::OutOfRange`] beyond any key. The same
/// keys as [`voxel_key`] then [`pack`], with one test a point for the usual case: a scan's
/// points are all finite and within 2^20 voxels, and every thinned point passes here.
#[inline]
fn packed_key(p: &Point3<f32>, inv: f64) -> Result<Option<u64>, Fallback> {
    let (x, y, z) = (
        f64::from(p.x) * inv,
        f64::from(p.y) * inv,
        f64::from(p.z) * inv,
    );
    // NaN and infinities fail the comparison too, and take the general path below.
    if x.abs() < PACK_HALF_F64 && y.abs() < PACK_HALF_F64 && z.abs() < PACK_HALF_F64 {
        // Within the span: truncate, step down for negatives (the floor), offset. The casts
        // cannot wrap: each value is below 2^20 in magnitude.
        let axis = |v: f64| {
            let t = v as i64;
            let floor = if (t as f64) > v { t - 1 } else { t };
            (floor + PACK_HALF) as u64
        };
        return Ok(Some(axis(x) | (axis(y) << 21) | (axis(z) << 42)));
    }
    match voxel_key(p, inv) {
        Ok(Some(k)) => pack_voxel_key(k).map(Some).ok_or(Fallback::Wide),
        Ok(None) => Ok(None),
        Err(()) => Err(Fallback::OutOfRange),
    }
}

/// The thinning's working memory: the voxels' index, their sums and each one's first point.
struct Scratch<K> {
    index: FxHashMap<K, u32>,
    acc: Vec<Accumulator>,
    /// The index of each voxel's first point, ascending: the order in which parts of a cloud
    /// thinned apart are merged back.
    first: Vec<u32>,
}

impl<K> Default for Scratch<K> {
    fn default() -> Self {
        Self {
            index: FxHashMap::default(),
            acc: Vec::new(),
            first: Vec::new(),
        }
    }
}

/// Voxels a thread's kept [`Scratch`] may hold room for (about 3 MB): enough for any scan's
/// thinning; what a larger cloud (a whole map) grew it to is given back after its call.
const KEPT_SCRATCH_VOXELS: usize = 1 << 16;

thread_local! {
    /// The packed keys' scratch, kept from cloud to cloud on each thread: a scan's thinning
    /// then allocates nothing but its result. Allocated afresh for every scan, the index and
    /// the sums (about 1 MB for a VLP-16 scan at 5 cm) were the transients that most often
    /// found no hole in the heap below what a walk keeps (its keyframes) and moved its top up,
    /// so that resident memory grew with the walk without being used.
    static PACKED_SCRATCH: RefCell<Scratch<u64>> = RefCell::new(Scratch::default());

    /// The calling thread's scratch for a thinning split across the thread pool: the points'
    /// packed keys and one [`Scratch`] a part, lent to the pool's workers and kept from cloud
    /// to cloud as [`PACKED_SCRATCH`] is.
    static SPLIT_SCRATCH: RefCell<SplitScratch> = RefCell::new(SplitScratch::default());
}

/// Working memory of a thinning split across the thread pool.
#[derive(Default)]
struct SplitScratch {
    keys: Vec<u64>,
    parts: Vec<Scratch<u64>>,
}

/// Clouds of at least this many points are thinned by the thread pool's workers together, each
/// summing the voxels of one part of the key space (a dense scan: 131,072 points at 5 cm). The
/// result is the same to the bit either way; smaller clouds are not worth the hand-over.
const SPLIT_POINTS: usize = 32_768;

/// At most this many parts.
const MAX_PARTS: usize = 8;

/// A stand-in key for a point without a voxel (not finite): packed keys use 63 bits.
const NO_KEY: u64 = u64::MAX;

/// Which of `parts` the packed `key` belongs to: a mix of all its bits, independent of the
/// hash map's own hash, so that a part's voxels still spread over its table.
#[inline]
fn part_of(key: u64, parts: usize) -> usize {
    let mixed = (key ^ (key >> 31)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    // The top 32 bits times the count, shifted down: a part index below `parts`.
    (((mixed >> 32) * parts as u64) >> 32) as usize
}

impl<K: std::hash::Hash + Eq + Copy> Scratch<K> {
    /// Whether this scratch holds room for more than [`KEPT_SCRATCH_VOXELS`] voxels.
    fn oversized(&self) -> bool {
        self.index.capacity().max(self.acc.capacity()) > KEPT_SCRATCH_VOXELS
    }
}

impl SplitScratch {
    /// Whether this scratch holds room for more than a kept [`Scratch`] may, in keys or in any
    /// part.
    fn oversized(&self) -> bool {
        self.keys.capacity() > 4 * KEPT_SCRATCH_VOXELS || self.parts.iter().any(Scratch::oversized)
    }
}

impl PointCloud {
    /// Per-voxel sums of the points into `scratch.acc`, in the order each voxel's first point
    /// comes, with voxels keyed by `key` (`Ok(None)`: a point skipped); the first refusal with
    /// its point's index. `scratch` is cleared first: what it held does not matter.
    fn accumulate<K: std::hash::Hash + Eq + Copy>(
        &self,
        scratch: &mut Scratch<K>,
        key: impl Fn(&Point3<f32>) -> Result<Option<K>, Fallback>,
    ) -> Result<(), (Fallback, usize)> {
        let mut refusal = None;
        let keyed = self
            .points()
            .iter()
            .enumerate()
            .map_while(|(i, p)| match key(p) {
                Ok(k) => Some(k.map(|k| (i, k))),
                Err(f) => {
                    refusal = Some((f, i));
                    None
                }
            })
            .flatten();
        self.accumulate_keyed(scratch, (self.len() / 4).min(1 << 15), keyed);
        refusal.map_or(Ok(()), Err)
    }

    /// Per-voxel sums of the points `keyed` gives (index, voxel key; indices ascending) into
    /// `scratch`, with room for `room` voxels first.
    fn accumulate_keyed<K: std::hash::Hash + Eq + Copy>(
        &self,
        scratch: &mut Scratch<K>,
        room: usize,
        keyed: impl Iterator<Item = (usize, K)>,
    ) {
        let Scratch { index, acc, first } = scratch;
        index.clear();
        acc.clear();
        first.clear();
        // Room for a voxel every four points, up to 32,768 (the callers' `room`): a dense scan
        // thins to about a third of its points at 5 cm, and a table sized for every point
        // spreads the voxels over more memory than the core's cache holds (an OS1-128 sweep of
        // 131,072 points at 5 cm: 3.4 ms against 5.2 ms with room for all). Growing past it
        // rehashes once or twice.
        index.reserve(room);
        acc.reserve(room);
        first.reserve(room);
        let ring = self.ring();
        let intensity = self.intensity();
        let time = self.time();
        let points = self.points();
        // Consecutive points of a scan (one firing's beams near the sensor, neighbours along a
        // ring) often share a voxel: the previous point's voxel is checked before the hash map.
        let mut last: Option<(K, u32)> = None;
        for (i, key) in keyed {
            let slot = match last {
                Some((k, slot)) if k == key => slot,
                _ => *index.entry(key).or_insert_with(|| {
                    acc.push(Accumulator {
                        sum: Vector3::zeros(),
                        intensity: 0.0,
                        time: 0.0,
                        count: 0,
                        ring: ring.map_or(0, |r| r[i]),
                    });
                    // Clouds hold fewer than 2^32 points.
                    first.push(i as u32);
                    (acc.len() - 1) as u32
                }),
            };
            last = Some((key, slot));
            let p = &points[i];
            let a = &mut acc[slot as usize];
            a.sum += Vector3::new(f64::from(p.x), f64::from(p.y), f64::from(p.z));
            a.count += 1;
            if let Some(v) = intensity {
                a.intensity += f64::from(v[i]);
            }
            if let Some(v) = time {
                a.time += f64::from(v[i]);
            }
        }
    }

    /// [`Self::accumulate`] with packed keys, split across the thread pool: every point's key
    /// first (in chunks on all cores), then each part of the key space summed on a worker of
    /// its own, then the parts' centroids merged in the order of their voxels' first points.
    /// The sums of a voxel run over its points in the same order as on one thread, so the
    /// cloud is the same to the bit. `None` when a point needs more than a packed key (the
    /// caller thins on one thread, which finds the refusal).
    fn thin_split(
        &self,
        inv: f64,
        split: &mut SplitScratch,
    ) -> Option<Result<PointCloud, CloudError>> {
        let parts = rayon::current_num_threads().clamp(1, MAX_PARTS);
        let SplitScratch {
            keys,
            parts: scratch,
        } = split;
        // Every key is written below whenever the keys are used (a point without a voxel gets
        // `NO_KEY`), so the last cloud's keys are left to be overwritten, not cleared first.
        keys.resize(self.len(), NO_KEY);
        let packable = keys
            .par_chunks_mut(KEY_CHUNK)
            .zip(self.points().par_chunks(KEY_CHUNK))
            .all(|(keys, points)| {
                keys.iter_mut()
                    .zip(points)
                    .all(|(k, p)| match packed_key(p, inv) {
                        Ok(Some(key)) => {
                            *k = key;
                            true
                        }
                        Ok(None) => {
                            *k = NO_KEY;
                            true
                        }
                        Err(_) => false,
                    })
            });
        if !packable {
            return None;
        }
        scratch.resize_with(parts, Scratch::default);
        let keys = &*keys;
        let room = (self.len() / 4 / parts).min(1 << 15);
        scratch.par_iter_mut().enumerate().for_each(|(part, s)| {
            let mine = keys
                .iter()
                .enumerate()
                .filter(|&(_, &k)| k != NO_KEY && part_of(k, parts) == part)
                .map(|(i, &k)| (i, k));
            self.accumulate_keyed(s, room, mine);
        });
        // Merge the parts by first point: the order one thread would have made.
        let total = scratch.iter().map(|s| s.acc.len()).sum();
        let mut heads = vec![0usize; parts];
        let mut merged = Vec::with_capacity(total);
        for _ in 0..total {
            let (part, _) = scratch
                .iter()
                .zip(&heads)
                .enumerate()
                .filter_map(|(p, (s, &h))| s.first.get(h).map(|&f| (p, f)))
                .min_by_key(|&(_, f)| f)?;
            merged.push(&scratch[part].acc[heads[part]]);
            heads[part] += 1;
        }
        Some(self.centroids(merged.iter().copied()))
    }

    /// The cloud of the voxels' centroids in `acc`, with the channels this cloud has averaged
    /// (the ring: the voxel's first point's).
    fn centroids<'a>(
        &self,
        acc: impl Iterator<Item = &'a Accumulator> + Clone,
    ) -> Result<PointCloud, CloudError> {
        let points = acc
            .clone()
            .map(|a| {
                let c = a.sum / f64::from(a.count);
                Point3::new(c.x as f32, c.y as f32, c.z as f32)
            })
            .collect();
        let mut out = PointCloud::from_points(points);
        if self.ring().is_some() {
            out = out.with_ring(acc.clone().map(|a| a.ring).collect())?;
        }
        if self.intensity().is_some() {
            out = out.with_intensity(
                acc.clone()
                    .map(|a| (a.intensity / f64::from(a.count)) as f32)
                    .collect(),
            )?;
        }
        if self.time().is_some() {
            out = out.with_time(acc.map(|a| (a.time / f64::from(a.count)) as f32).collect())?;
        }
        Ok(out)
    }

    /// [`Self::voxel_downsample`], but a finite point too far out for any voxel key (more than
    /// 2^62 voxels from the origin: a garbled return such as 1e30 m, not a measurement) is
    /// dropped instead of refusing the whole cloud; returns the thinned cloud and how many such
    /// points were dropped, for the caller to report.
    ///
    /// ```
    /// use nalgebra::Point3;
    /// use slam_core::PointCloud;
    /// let cloud = PointCloud::from_points(vec![
    ///     Point3::new(0.01, 0.0, 0.0),
    ///     Point3::new(1e30, 0.0, 0.0),
    /// ]);
    /// assert!(cloud.voxel_downsample(0.1).is_err());
    /// let (down, dropped) = cloud.voxel_downsample_keyable(0.1)?;
    /// assert_eq!((down.len(), dropped), (1, 1));
    /// # Ok::<(), slam_core::CloudError>(())
    /// ```
    ///
    /// # Errors
    /// [`CloudError::InvalidVoxelSize`] unless `voxel_size` is finite and positive.
    pub fn voxel_downsample_keyable(
        &self,
        voxel_size: f32,
    ) -> Result<(PointCloud, usize), CloudError> {
        match self.voxel_downsample(voxel_size) {
            Err(CloudError::VoxelOutOfRange { .. }) => {
                let reach = f64::from(voxel_size) * KEYABLE_VOXELS;
                let far = |p: &Point3<f32>| {
                    p.iter().all(|v| v.is_finite()) && p.iter().any(|v| f64::from(v.abs()) >= reach)
                };
                let dropped = self.points().iter().filter(|p| far(p)).count();
                let near = self.filtered(|_, p| !far(p));
                Ok((near.voxel_downsample(voxel_size)?, dropped))
            }
            other => other.map(|down| (down, 0)),
        }
    }

    /// Downsample to one point per cubic voxel of side `voxel_size` metres, at the centroid of the
    /// voxel's points. Intensity and time are averaged; a voxel keeps its first point's ring.
    /// Output order follows the first point of each voxel, so the result is deterministic.
    /// Non-finite points are skipped. Hash-based, O(N).
    ///
    /// ```
    /// use nalgebra::Point3;
    /// use slam_core::PointCloud;
    /// let cloud = PointCloud::from_points(vec![
    ///     Point3::new(0.01, 0.01, 0.0),
    ///     Point3::new(0.03, 0.01, 0.0),
    ///     Point3::new(0.51, 0.0, 0.0),
    /// ]);
    /// let down = cloud.voxel_downsample(0.1)?;
    /// assert_eq!(down.len(), 2);
    /// assert!((down.points()[0].x - 0.02).abs() < 1e-6);
    /// # Ok::<(), slam_core::CloudError>(())
    /// ```
    ///
    /// # Errors
    /// [`CloudError::InvalidVoxelSize`] unless `voxel_size` is finite and positive,
    /// [`CloudError::VoxelOutOfRange`] for a finite point more than 2^63 voxels from the origin
    /// (never silently dropped).
    pub fn voxel_downsample(&self, voxel_size: f32) -> Result<PointCloud, CloudError> {
        if !(voxel_size.is_finite() && voxel_size > 0.0) {
            return Err(CloudError::InvalidVoxelSize { size: voxel_size });
        }
        let inv = 1.0 / f64::from(voxel_size);
        let out_of_range = |index| CloudError::VoxelOutOfRange {
            index,
            size: voxel_size,
        };
        // Voxel coordinates within 2^20 of the origin (52 km at 5 cm) pack into one u64: the
        // hash map then holds 16-byte entries instead of 32, and a 131,072-point scan at 5 cm,
        // one voxel per point or nearly, runs about twice as fast. Farther clouds take the
        // general keys.
        let packed = |scratch: &mut Scratch<u64>| {
            let summed = self.accumulate(scratch, |p| packed_key(p, inv));
            let out = summed.map(|()| self.centroids(scratch.acc.iter()));
            if scratch.oversized() {
                *scratch = Scratch::default();
            }
            out
        };
        if self.len() >= SPLIT_POINTS && rayon::current_num_threads() > 1 {
            let split = SPLIT_SCRATCH.with(|kept| match kept.try_borrow_mut() {
                Ok(mut split) => {
                    let out = self.thin_split(inv, &mut split);
                    if split.oversized() {
                        *split = SplitScratch::default();
                    }
                    out
                }
                Err(_) => self.thin_split(inv, &mut SplitScratch::default()),
            });
            if let Some(out) = split {
                return out;
            }
        }
        let thinned = PACKED_SCRATCH.with(|kept| match kept.try_borrow_mut() {
            Ok(mut scratch) => packed(&mut scratch),
            Err(_) => packed(&mut Scratch::default()),
        });
        match thinned {
            Ok(out) => out,
            Err((Fallback::OutOfRange, i)) => Err(out_of_range(i)),
            Err((Fallback::Wide, _)) => {
                let mut scratch = Scratch::default();
                self.accumulate(&mut scratch, |p| {
                    voxel_key(p, inv).map_err(|()| Fallback::OutOfRange)
                })
                .map_err(|(_, i)| out_of_range(i))?;
                self.centroids(scratch.acc.iter())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::collections::BTreeMap;

    /// Centroids a `BTreeMap` of voxels gives, sorted.
    fn oracle_centroids(cloud: &PointCloud, voxel: f32) -> Vec<[f32; 3]> {
        let inv = 1.0 / f64::from(voxel);
        let mut oracle: BTreeMap<(i64, i64, i64), (Vector3<f64>, u32)> = BTreeMap::new();
        for p in cloud.points() {
            let k = voxel_key(p, inv).unwrap().unwrap();
            let e = oracle.entry(k).or_insert((Vector3::zeros(), 0));
            e.0 += nalgebra::convert::<_, Vector3<f64>>(p.coords);
            e.1 += 1;
        }
        let mut want: Vec<[f32; 3]> = oracle
            .values()
            .map(|(s, n)| {
                let c = s / f64::from(*n);
                [c.x as f32, c.y as f32, c.z as f32]
            })
            .collect();
        want.sort_by(|a, b| a.partial_cmp(b).unwrap());
        want
    }

    fn sorted_points(cloud: &PointCloud) -> Vec<[f32; 3]> {
        let mut got: Vec<[f32; 3]> = cloud.points().iter().map(|p| [p.x, p.y, p.z]).collect();
        got.sort_by(|a, b| a.partial_cmp(b).unwrap());
        got
    }

    proptest! {
        /// Against a BTreeMap oracle: same voxels, same centroids, same counts.
        #[test]
        fn matches_sorted_map_oracle(
            pts in proptest::collection::vec((-50.0f32..50.0, -50.0f32..50.0, -5.0f32..5.0), 0..500),
            voxel in 0.05f32..3.0,
        ) {
            let cloud = PointCloud::from_points(pts.iter().map(|&(x, y, z)| Point3::new(x, y, z)).collect());
            let down = cloud.voxel_downsample(voxel).unwrap();
            prop_assert_eq!(sorted_points(&down), oracle_centroids(&cloud, voxel));
        }

        /// A walk in steps much shorter than a voxel, as a scan's ring is listed: runs of points
        /// in one voxel, voxels left and entered again later, against the same oracle.
        #[test]
        fn a_walk_through_voxels_matches_the_oracle(
            steps in proptest::collection::vec((-0.06f32..0.06, -0.06f32..0.06, -0.02f32..0.02), 0..800),
            voxel in 0.05f32..0.5,
        ) {
            let mut at = Point3::new(0.0f32, 0.0, 0.0);
            let pts = steps.iter().map(|&(x, y, z)| {
                at += Vector3::new(x, y, z);
                at
            }).collect();
            let cloud = PointCloud::from_points(pts);
            let down = cloud.voxel_downsample(voxel).unwrap();
            prop_assert_eq!(sorted_points(&down), oracle_centroids(&cloud, voxel));
        }
    }

    /// A dense scan-like cloud (rings of points with times, intensities, a few non-finite):
    /// a spiral whose neighbours share voxels as a sweep's do.
    fn dense_cloud(n: usize) -> PointCloud {
        let points = (0..n)
            .map(|i| {
                let a = i as f32 * 0.013;
                let r = 2.0 + (i % 97) as f32 * 0.11;
                if i % 5_000 == 17 {
                    Point3::new(f32::NAN, 0.0, 0.0)
                } else {
                    Point3::new(r * a.cos(), r * a.sin(), (i % 128) as f32 * 0.02 - 1.0)
                }
            })
            .collect();
        PointCloud::from_points(points)
            .with_ring((0..n).map(|i| (i % 128) as u16).collect())
            .unwrap()
            .with_intensity((0..n).map(|i| (i % 251) as f32).collect())
            .unwrap()
            .with_time((0..n).map(|i| i as f32 * 1e-6).collect())
            .unwrap()
    }

    /// The cloud thinned on a pool of `threads` workers.
    fn thinned_on(
        threads: usize,
        cloud: &PointCloud,
        voxel: f32,
    ) -> Result<PointCloud, CloudError> {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| cloud.voxel_downsample(voxel))
    }

    #[test]
    fn a_dense_cloud_thinned_by_several_workers_is_the_one_thread_cloud_to_the_bit() {
        let cloud = dense_cloud(3 * SPLIT_POINTS);
        for voxel in [0.05, 0.25, 1.0] {
            let alone = thinned_on(1, &cloud, voxel).unwrap();
            for threads in [2, 3, 8] {
                let split = thinned_on(threads, &cloud, voxel).unwrap();
                assert_eq!(split, alone, "{threads} workers at {voxel} m");
            }
            // The oracle's voxels and centroids too, and each voxel where its first point is.
            assert_eq!(
                sorted_points(&alone),
                oracle_centroids(&cloud.filtered(|_, p| p.x.is_finite()), voxel)
            );
            let inv = 1.0 / f64::from(voxel);
            let firsts: Vec<usize> = {
                let mut seen = std::collections::HashSet::new();
                cloud
                    .points()
                    .iter()
                    .enumerate()
                    .filter_map(|(i, p)| {
                        voxel_key(p, inv)
                            .unwrap()
                            .filter(|k| seen.insert(*k))
                            .map(|_| i)
                    })
                    .collect()
            };
            let rings = cloud.ring().unwrap();
            let want: Vec<u16> = firsts.iter().map(|&i| rings[i]).collect();
            assert_eq!(
                alone.ring().unwrap(),
                &want[..],
                "voxels in the order of their first points"
            );
        }
    }

    /// The split's key buffer is kept from cloud to cloud on a thread: a cloud with points
    /// that have no voxel, thinned after a larger one whose points all had one, is thinned as
    /// on one thread (no key of the earlier cloud is taken for those points).
    #[test]
    fn a_cloud_thinned_after_a_larger_one_keeps_none_of_its_keys() {
        let finite = dense_cloud(4 * SPLIT_POINTS).filtered(|_, p| p.x.is_finite());
        let mut gappy = dense_cloud(3 * SPLIT_POINTS);
        for (i, p) in gappy.points_mut().iter_mut().enumerate() {
            if i % 7 == 3 {
                *p = Point3::new(f32::NAN, 0.0, 0.0);
            }
        }
        for voxel in [0.05, 0.25] {
            let alone = thinned_on(1, &gappy, voxel).unwrap();
            let after = rayon::ThreadPoolBuilder::new()
                .num_threads(2)
                .build()
                .unwrap()
                .install(|| {
                    finite.voxel_downsample(voxel).unwrap();
                    gappy.voxel_downsample(voxel)
                })
                .unwrap();
            assert_eq!(after, alone, "at {voxel} m");
        }
    }

    #[test]
    fn a_dense_cloud_beyond_packed_keys_is_thinned_or_refused_as_on_one_thread() {
        // 1e6 m at 5 cm is 2e7 voxels out: past the packed keys, within the general ones.
        let mut far = dense_cloud(2 * SPLIT_POINTS);
        far.points_mut()[40_000] = Point3::new(1e6, 0.0, 0.0);
        assert_eq!(
            thinned_on(2, &far, 0.05).unwrap(),
            thinned_on(1, &far, 0.05).unwrap()
        );
        // Beyond any key: the same error with the same point either way.
        let mut out = dense_cloud(2 * SPLIT_POINTS);
        out.points_mut()[50_000] = Point3::new(0.0, 3.0e38, 0.0);
        for threads in [1, 2] {
            assert!(matches!(
                thinned_on(threads, &out, 1e-3),
                Err(CloudError::VoxelOutOfRange { index: 50_000, .. })
            ));
        }
    }

    #[test]
    fn rejects_bad_sizes_and_skips_nan() {
        let c = PointCloud::from_points(vec![Point3::new(f32::NAN, 0.0, 0.0), Point3::origin()])
            .with_intensity(vec![5.0, 1.0])
            .unwrap();
        assert!(c.voxel_downsample(0.0).is_err());
        assert!(c.voxel_downsample(f32::NAN).is_err());
        let d = c.voxel_downsample(1.0).unwrap();
        assert_eq!(d.len(), 1);
        assert_eq!(d.intensity(), Some(&[1.0][..]));
    }

    #[test]
    fn tiny_voxels_keep_far_finite_points() {
        // At 1 nm voxels a point 5 m out is 5e9 voxels away: past i32, which dropped it.
        let pts = vec![Point3::new(5.0, -7.0, 1.0), Point3::new(0.0, 0.0, 0.0)];
        let down = PointCloud::from_points(pts.clone())
            .voxel_downsample(1e-9)
            .unwrap();
        assert_eq!(down.points(), &pts[..]);
        // Floor, not truncation, on the negative side: -0.5 voxels is voxel -1, not 0.
        let inv = 1.0 / 1e-9f64;
        assert_eq!(
            voxel_key(&Point3::new(-0.5e-9, 0.0, 0.0), inv),
            Ok(Some((-1, 0, 0)))
        );
    }

    #[test]
    fn out_of_range_finite_point_is_an_error() {
        let c = PointCloud::from_points(vec![Point3::origin(), Point3::new(0.0, 3.0e38, 0.0)]);
        assert!(matches!(
            c.voxel_downsample(1e-3),
            Err(CloudError::VoxelOutOfRange { index: 1, .. })
        ));
    }

    #[test]
    fn points_beyond_any_voxel_key_are_dropped_and_counted_not_the_cloud() {
        let c = PointCloud::from_points(vec![
            Point3::new(0.01, 0.0, 0.0),
            Point3::new(0.03, 0.0, 0.0),
            Point3::new(f32::NAN, 0.0, 0.0),
            Point3::new(0.0, -1e30, 0.0),
            Point3::new(2e12, 0.0, 0.0),
            Point3::new(0.5, 0.0, 0.0),
        ])
        .with_time(vec![0.0, 0.2, 0.1, 0.1, 0.1, 0.3])
        .unwrap();
        // At 1 mm voxels 2e12 m is 2e15 voxels out (a key); 1e30 m is not.
        let (down, dropped) = c.voxel_downsample_keyable(1e-3).unwrap();
        assert_eq!(
            dropped, 1,
            "the NaN is not counted, the far finite point is"
        );
        assert_eq!(down.len(), 4);
        // The rest thins as without the far point (times averaged as usual).
        let without = c.filtered(|i, _| i != 3).voxel_downsample(1e-3).unwrap();
        assert_eq!(down, without);
        // A clean cloud: the plain thinning, nothing dropped.
        let clean = c.filtered(|i, _| i < 2);
        assert_eq!(
            clean.voxel_downsample_keyable(0.1).unwrap(),
            (clean.voxel_downsample(0.1).unwrap(), 0)
        );
        assert!(c.voxel_downsample_keyable(0.0).is_err());
    }
}
