//! The voxel centroids of a sliding window of placed sources, kept as per-voxel sums so that a
//! source enters and leaves in time proportional to its own points, not the window's.

use nalgebra::{Point3, Vector3};
use rustc_hash::FxHashMap;
use slam_core::Pose3;

/// Integer voxel coordinates.
pub(crate) type VoxelKey = [i64; 3];

/// One source's points as added: each moved point with its voxel's slot.
type Part = Vec<(u32, Vector3<f64>)>;

/// Running sum of one voxel's points.
#[derive(Clone, Copy, Debug)]
struct Cell {
    /// The voxel (to drop it from the key map once it is empty).
    key: VoxelKey,
    sum: Vector3<f64>,
    count: u32,
    /// The voxel's normal as an index of the window last computed or reused it.
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
    /// Each occupied voxel's slot in `slots`.
    cells: FxHashMap<VoxelKey, u32>,
    /// The voxels' sums by slot; a slot on `free` is empty. A source's points and the normals
    /// an index keeps find their voxel by slot, without hashing its key again.
    slots: Vec<Cell>,
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
            slots: Vec::new(),
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
            let (slots, free) = (&mut self.slots, &mut self.free);
            let slot = *self.cells.entry(k).or_insert_with(|| {
                let cell = Cell {
                    key: k,
                    sum: Vector3::zeros(),
                    count: 0,
                    normal: None,
                };
                if let Some(s) = free.pop() {
                    slots[s as usize] = cell;
                    s
                } else {
                    slots.push(cell);
                    // A window holds fewer than 2^32 voxels.
                    (slots.len() - 1) as u32
                }
            });
            let cell = &mut slots[slot as usize];
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
            let cell = &mut self.slots[slot as usize];
            cell.count -= 1;
            if cell.count == 0 {
                self.cells.remove(&cell.key);
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
        let n = self.cells.len();
        let mut snapshot = Snapshot {
            slots: Vec::with_capacity(n),
            centroids: Vec::with_capacity(n),
            kept: Vec::with_capacity(n),
            counts: Vec::with_capacity(n),
        };
        // In slot order, skipping free slots (an empty voxel's count is 0): the sums are read
        // in memory order, where the key map's order read them at random (an OS1-128 window's
        // 27,000 voxels: 1.8 -> 0.5 ms, on the critical path beside the scan's thinning).
        for (slot, c) in (0u32..).zip(&self.slots) {
            if c.count == 0 {
                continue;
            }
            snapshot.slots.push(slot);
            snapshot
                .centroids
                .push(Point3::from(c.sum / f64::from(c.count)));
            snapshot.kept.push(c.normal.filter(|kept| {
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
        if let Some(cell) = self.slots.get_mut(slot as usize) {
            cell.normal = Some(normal);
        }
    }

    /// Number of occupied voxels.
    pub(crate) fn len(&self) -> usize {
        self.cells.len()
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
}
