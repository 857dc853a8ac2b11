//! The voxel centroids of a sliding window of placed sources, kept as per-voxel sums so that a
//! source enters and leaves in time proportional to its own points, not the window's.

use nalgebra::{Point3, Vector3};
use rustc_hash::FxHashMap;
use slam_core::{Pose3, pack_voxel_key};

/// Integer voxel coordinates.
pub(crate) type VoxelKey = [i64; 3];

/// One source's points as added: each moved point with its voxel's slot.
type Part = Vec<(u32, Vector3<f64>)>;

/// Running sum of one voxel's points: what adding, removing and a snapshot read, kept apart
/// from the voxel's key and kept normal so that a window's sums stay in the core's cache (an
/// OS1-128 window: 28,000 voxels).
#[derive(Clone, Copy, Debug)]
struct Sum {
    sum: Vector3<f64>,
    count: u32,
}

/// The rest of a voxel: its key (to drop it from the key map once it is empty) and the normal
/// an index of the window last computed or reused for it.
#[derive(Clone, Copy, Debug)]
struct Meta {
    key: VoxelKey,
    normal: Option<KeptNormal>,
}

/// A voxel's normal kept from one index of the window for the next.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct KeptNormal {
    /// The normal (`None`: the neighbourhood was not plane-like enough).
    pub(crate) normal: Option<Vector3<f64>>,
    /// The voxel's point count when the normal was computed.
    pub(crate) count: u32,
    /// Indexes it has been reused by since.
    pub(crate) reused: u32,
}

/// A kept normal is reused by at most this many indexes of the window in a row, then computed
/// afresh: the neighbours it came from move as keyframes enter and leave the window.
pub(crate) const MAX_NORMAL_REUSE: u32 = 8;

/// The window's centroids with their voxels and the normals kept for them.
pub(crate) struct Snapshot {
    /// Per centroid: its voxel's slot in the window, valid until the window next changes.
    pub(crate) slots: Vec<u32>,
    pub(crate) centroids: Vec<Point3<f64>>,
    /// Per centroid: the voxel's kept normal when it may be reused (its count within a factor
    /// two of the count it was computed at, reused fewer than [`MAX_NORMAL_REUSE`] times).
    pub(crate) kept: Vec<Option<KeptNormal>>,
    /// Per centroid: the voxel's point count.
    pub(crate) counts: Vec<u32>,
}

/// Points of sources placed in the world, thinned to one centroid per cubic voxel: the same
/// points (up to rounding and order) as merging the window's sources and voxel-averaging the
/// result, which is what a local map rebuilt whole holds.
#[derive(Clone, Debug)]
pub(crate) struct VoxelWindow {
    /// One over the voxel size.
    inv: f64,
    /// Each occupied voxel's slot, keyed by its coordinates packed into 21 bits each when they
    /// fit (half the table's memory and one multiply to hash) ...
    cells: FxHashMap<u64, u32>,
    /// ... and by the coordinates themselves when they do not (a voxel more than 2^20 voxels
    /// from the origin, 210 km at 0.2 m).
    far_cells: FxHashMap<VoxelKey, u32>,
    /// The voxels' sums by slot; a slot on `free` is empty. A source's points and the normals
    /// an index keeps find their voxel by slot, without hashing its key again.
    sums: Vec<Sum>,
    /// The voxels' keys and kept normals, by the same slots.
    metas: Vec<Meta>,
    free: Vec<u32>,
    /// Each key's moved points with their voxels, to subtract exactly what was added.
    parts: FxHashMap<u32, Part>,
}

impl VoxelWindow {
    /// An empty window with voxels of `voxel` metres (finite and positive, checked by the
    /// caller's configuration).
    pub(crate) fn new(voxel: f32) -> Self {
        Self {
            inv: 1.0 / f64::from(voxel),
            cells: FxHashMap::default(),
            far_cells: FxHashMap::default(),
            sums: Vec::new(),
            metas: Vec::new(),
            free: Vec::new(),
            parts: FxHashMap::default(),
        }
    }

    /// Adds `points` moved by `pose` under `key`, replacing what `key` held. Points that are
    /// not finite once moved (a non-finite pose) are left out: they have no voxel.
    pub(crate) fn add(&mut self, key: u32, points: &[Point3<f64>], pose: &Pose3) {
        self.remove(key);
        let inv = self.inv;
        // `as` saturates: a point 2^63 voxels out shares the edge voxel, where f32 k-d tree
        // coordinates could not tell it apart anyway.
        let voxel = |v: f64| (v * inv).floor() as i64;
        let mut part = Vec::with_capacity(points.len());
        for p in points {
            let w = (pose * p).coords;
            if !w.iter().all(|v| v.is_finite()) {
                continue;
            }
            let k = [voxel(w.x), voxel(w.y), voxel(w.z)];
            let (sums, metas, free) = (&mut self.sums, &mut self.metas, &mut self.free);
            let new_slot = || {
                let (sum, meta) = (
                    Sum {
                        sum: Vector3::zeros(),
                        count: 0,
                    },
                    Meta {
                        key: k,
                        normal: None,
                    },
                );
                if let Some(s) = free.pop() {
                    sums[s as usize] = sum;
                    metas[s as usize] = meta;
                    s
                } else {
                    sums.push(sum);
                    metas.push(meta);
                    // A window holds fewer than 2^32 voxels.
                    (sums.len() - 1) as u32
                }
            };
            let slot = match pack_voxel_key((k[0], k[1], k[2])) {
                Some(p) => *self.cells.entry(p).or_insert_with(new_slot),
                None => *self.far_cells.entry(k).or_insert_with(new_slot),
            };
            let cell = &mut self.sums[slot as usize];
            cell.sum += w;
            cell.count += 1;
            part.push((slot, w));
        }
        self.parts.insert(key, part);
    }

    /// Removes what was added under `key` (nothing when it holds nothing). A voxel left empty
    /// is dropped, so no rounding lingers in it.
    pub(crate) fn remove(&mut self, key: u32) {
        let Some(part) = self.parts.remove(&key) else {
            return;
        };
        for (slot, w) in part {
            // A part's slots stay occupied while it is in the window.
            let cell = &mut self.sums[slot as usize];
            cell.count -= 1;
            if cell.count == 0 {
                let key = self.metas[slot as usize].key;
                match pack_voxel_key((key[0], key[1], key[2])) {
                    Some(p) => self.cells.remove(&p),
                    None => self.far_cells.remove(&key),
                };
                self.free.push(slot);
            } else {
                cell.sum -= w;
            }
        }
    }

    /// The voxel centroids.
    #[cfg(test)]
    pub(crate) fn centroids(&self) -> Vec<Point3<f64>> {
        self.snapshot().centroids
    }

    /// The voxel centroids with their keys, counts and reusable normals.
    pub(crate) fn snapshot(&self) -> Snapshot {
        let n = self.len();
        let mut snapshot = Snapshot {
            slots: Vec::with_capacity(n),
            centroids: Vec::with_capacity(n),
            kept: Vec::with_capacity(n),
            counts: Vec::with_capacity(n),
        };
        // In slot order, skipping free slots (an empty voxel's count is 0): the sums are read
        // in memory order, where the key map's order read them at random (an OS1-128 window's
        // 27,000 voxels: 1.8 -> 0.5 ms, on the critical path beside the scan's thinning).
        for ((slot, c), m) in (0u32..).zip(&self.sums).zip(&self.metas) {
            if c.count == 0 {
                continue;
            }
            snapshot.slots.push(slot);
            snapshot
                .centroids
                .push(Point3::from(c.sum / f64::from(c.count)));
            snapshot.kept.push(m.normal.filter(|kept| {
                kept.reused < MAX_NORMAL_REUSE
                    && c.count <= kept.count.saturating_mul(2)
                    && kept.count <= c.count.saturating_mul(2)
            }));
            snapshot.counts.push(c.count);
        }
        snapshot
    }

    /// Keeps `normal` for the voxel in `slot` of a [`Snapshot`] taken since the window last
    /// changed.
    pub(crate) fn keep_normal(&mut self, slot: u32, normal: KeptNormal) {
        if let Some(meta) = self.metas.get_mut(slot as usize) {
            meta.normal = Some(normal);
        }
    }

    /// Number of occupied voxels.
    pub(crate) fn len(&self) -> usize {
        self.cells.len() + self.far_cells.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use slam_core::PointCloud;

    fn sorted(mut v: Vec<Point3<f64>>) -> Vec<Point3<f64>> {
        v.sort_by(|a, b| {
            a.iter()
                .zip(b.iter())
                .map(|(x, y)| x.total_cmp(y))
                .find(|o| o.is_ne())
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        v
    }

    /// The window after adds and removes holds the centroids that voxelising the remaining
    /// sources merged (the independent whole computation) gives.
    #[test]
    fn a_slid_window_holds_the_centroids_of_its_sources_merged() {
        let parts: Vec<(Vec<Point3<f64>>, Pose3)> = (0..6)
            .map(|k| {
                let pts = (0..400)
                    .map(|i| {
                        let f = f64::from(i);
                        Point3::new((f * 0.37).sin() * 3.0, (f * 0.11).cos() * 2.0, f * 0.004)
                    })
                    .collect();
                let pose = Pose3::new(
                    Vector3::new(0.13 * f64::from(k), -0.07 * f64::from(k), 0.01),
                    Vector3::new(0.0, 0.0, 0.05 * f64::from(k)),
                );
                (pts, pose)
            })
            .collect();
        let mut window = VoxelWindow::new(0.25);
        for (k, (pts, pose)) in (0u32..).zip(&parts) {
            window.add(k, pts, pose);
            if let Some(old) = k.checked_sub(3) {
                window.remove(old);
            }
        }
        // Re-adding a key replaces it.
        window.add(5, &parts[5].0, &parts[5].1);
        let merged: Vec<Point3<f32>> = parts[3..]
            .iter()
            .flat_map(|(pts, pose)| pts.iter().map(move |p| (pose * p).cast::<f32>()))
            .collect();
        let whole = PointCloud::from_points(merged)
            .voxel_downsample(0.25)
            .unwrap();
        let whole: Vec<Point3<f64>> = whole.points().iter().map(|p| p.cast()).collect();
        let (got, want) = (sorted(window.centroids()), sorted(whole));
        assert_eq!(got.len(), want.len());
        assert_eq!(window.len(), want.len());
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).norm() < 1e-5, "{g} vs {w}");
        }
        for k in 3..6 {
            window.remove(k);
        }
        assert_eq!(window.len(), 0);
    }

    /// Voxels more than 2^20 voxels out (keyed unpacked) and near ones (keyed packed) are
    /// kept, averaged and dropped alike: against a brute-force grouping of the points by their
    /// integer voxel coordinates.
    #[test]
    fn far_voxels_are_kept_as_near_ones_are() {
        let near: Vec<Point3<f64>> = (0..300)
            .map(|i| {
                let f = f64::from(i);
                Point3::new((f * 0.37).sin() * 3.0, (f * 0.11).cos() * 2.0, f * 0.004)
            })
            .collect();
        // 1,000 km out on x and -300 km on z: beyond 2^20 voxels of 0.25 m on both axes.
        let far: Vec<Point3<f64>> = near
            .iter()
            .map(|p| Point3::new(p.x + 1.0e6, p.y, p.z - 3.0e5))
            .collect();
        let brute = |pts: &[Point3<f64>]| {
            let mut groups: std::collections::BTreeMap<[i64; 3], (Vector3<f64>, f64)> =
                std::collections::BTreeMap::new();
            for p in pts {
                let k = [p.x, p.y, p.z].map(|v| (v * 4.0).floor() as i64);
                let g = groups.entry(k).or_insert((Vector3::zeros(), 0.0));
                g.0 += p.coords;
                g.1 += 1.0;
            }
            sorted(groups.values().map(|(s, n)| Point3::from(s / *n)).collect())
        };
        let mut window = VoxelWindow::new(0.25);
        window.add(0, &near, &Pose3::identity());
        window.add(1, &far, &Pose3::identity());
        let all: Vec<Point3<f64>> = near.iter().chain(&far).copied().collect();
        let (got, want) = (sorted(window.centroids()), brute(&all));
        assert_eq!(got.len(), want.len());
        assert!(got.iter().zip(&want).all(|(g, w)| (g - w).norm() < 1e-6));
        assert!(!window.far_cells.is_empty() && !window.cells.is_empty());
        window.remove(0);
        let (got, want) = (sorted(window.centroids()), brute(&far));
        assert_eq!(got.len(), want.len());
        assert!(got.iter().zip(&want).all(|(g, w)| (g - w).norm() < 1e-6));
        window.remove(1);
        assert_eq!(window.len(), 0);
    }
}
