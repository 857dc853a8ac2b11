//! `VoxelHashMap`: points hashed into cubic cells for exact k-nearest queries, grown and shrunk
//! one owner (a keyframe) at a time. The spatial index of LOAM's local map: a sliding window of
//! keyframes is updated in place instead of rebuilding a k-d tree per keyframe, and a query near
//! the map reads one or a few small cells instead of descending a tree.

use nalgebra::Point3;
use rustc_hash::FxHashMap;
use slam_core::RegistrationError;
use std::collections::hash_map::Entry as MapEntry;

use crate::config::{NON_NEGATIVE, POSITIVE, check};
use crate::neighbour_cache::{Candidate, NearestSearch};

/// One stored point: f32 coordinates (half the memory traffic of f64; a local map spans far less
/// than the kilometres where f32 would lose millimetres) and the owner that added it.
#[derive(Clone, Copy, Debug)]
struct Entry {
    p: [f32; 3],
    owner: u32,
}

/// What one owner put in the map: the cells it added points to (possibly since overwritten by a
/// newer owner), and the voxels it stands in for.
#[derive(Clone, Debug, Default)]
struct Touched {
    cells: Vec<u64>,
    standins: Vec<u64>,
}

/// Points in cubic cells of a hash map, for exact k-nearest-neighbour queries within a radius.
///
/// Points may be thinned on insertion to one per `thin` voxel, and removed by owner. A voxel
/// keeps the point of the oldest owner that saw it, so that a sliding window of scans stays
/// anchored to its oldest scan instead of chaining each scan to the previous one; when that
/// owner is removed, the newest other owner that saw the voxel takes over, so the voxels held
/// are always those some remaining owner saw. Voxels are keyed map-wide (21 bits per axis: two
/// voxels 2^21 voxels apart, 105 km at 5 cm, would count as one), so an insertion finds its
/// voxel in one lookup. A query searches the query's cell and
/// then rings of cells around it, skipping every cell farther than the current k-th neighbour, and
/// stops as soon as no unsearched cell can hold a nearer point: the answer equals a brute-force
/// search's (ties aside).
///
/// ```
/// use nalgebra::Point3;
/// use registration::VoxelHashMap;
///
/// let mut map = VoxelHashMap::new(0.25, 0.0)?;
/// for i in 0..10 {
///     map.insert(7, &Point3::new(f64::from(i) * 0.1, 0.0, 0.0));
/// }
/// let mut near = Vec::new();
/// map.nearest_k(&Point3::new(0.42, 0.0, 0.0), 2, 1.0, &mut near);
/// assert_eq!(near.len(), 2);
/// assert!((near[0].1.x - 0.4).abs() < 1e-6 && (near[1].1.x - 0.5).abs() < 1e-6);
/// assert_eq!(map.remove_owner(7), 10);
/// assert!(map.is_empty());
/// # Ok::<(), slam_core::RegistrationError>(())
/// ```
#[derive(Clone)]
pub struct VoxelHashMap {
    cell: f64,
    inv_cell: f64,
    thin: f64,
    inv_thin: f64,
    cells: FxHashMap<u64, Vec<Entry>>,
    /// With thinning: the owner whose point holds each voxel (the point is in `cells`). Keyed
    /// by voxel, so an insertion finds its voxel in one lookup instead of a scan of its cell.
    held: FxHashMap<u64, u32>,
    /// With thinning, for voxels held by an older owner: the newest other owner's point.
    standins: FxHashMap<u64, Entry>,
    owners: FxHashMap<u32, Touched>,
    len: usize,
}

impl std::fmt::Debug for VoxelHashMap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("VoxelHashMap")
            .field("cell", &self.cell)
            .field("thin", &self.thin)
            .field("cells", &self.cells.len())
            .field("owners", &self.owners.len())
            .field("len", &self.len)
            .finish_non_exhaustive()
    }
}

/// 21 bits per axis: cell indices wrap beyond ±10^6 cells (±250 km at 25 cm). A wrapped key only
/// shares a cell with far points, which the distance test then rejects.
fn pack(c: [i32; 3]) -> u64 {
    let axis = |v: i32| u64::from(v as u32 & 0x1F_FFFF);
    axis(c[0]) | (axis(c[1]) << 21) | (axis(c[2]) << 42)
}

/// Integer cell of `v` at `inv` cells per metre; saturating at the ends of `i32`, so absurd
/// coordinates stay finite (and fall in the end cells, which the distance test sorts out).
fn cell_of(v: f64, inv: f64) -> i32 {
    // Truncate, then step down for negatives: `f64::floor` is a library call on baseline x86-64.
    let x = v * inv;
    let t = x as i32;
    if f64::from(t) > x {
        t.saturating_sub(1)
    } else {
        t
    }
}

/// The cell `o` cells from `base` on each axis. Wrapping: keys keep 21 bits per axis anyway
/// ([`pack`]), and wrapping in `i32` is wrapping modulo 2^21 too, so a cell next to the last one
/// is the one a wrapped key names.
fn offset(base: [i32; 3], o: [i32; 3]) -> [i32; 3] {
    std::array::from_fn(|a| base[a].wrapping_add(o[a]))
}

/// `cell - base` modulo 2^21, in `[-2^20, 2^20)`: the offset between the cells' keys.
fn key_offset(cell: i32, base: i32) -> i32 {
    cell.wrapping_sub(base).wrapping_shl(11) >> 11
}

/// Rings searched at most: beyond 2^20 cells the 21-bit keys wrap round, and a map has far fewer
/// cells than such a ring would visit, so the search reads every cell before (see
/// [`VoxelHashMap::nearest_k`]).
const MAX_RING: i32 = 1 << 20;

/// The `k` best (smallest squared distance) candidates seen so far, sorted ascending.
struct Best<'a> {
    k: usize,
    items: &'a mut Vec<Candidate>,
}

impl Best<'_> {
    fn full(&self) -> bool {
        self.items.len() == self.k
    }

    /// The squared distance a candidate must beat.
    fn bound(&self, max_d2: f32) -> f32 {
        if self.full() {
            self.items.last().map_or(max_d2, |l| l.d2.min(max_d2))
        } else {
            max_d2
        }
    }

    fn offer(&mut self, d2: f32, p: [f32; 3]) {
        if self.full() {
            self.items.pop();
        }
        // Insertion by swaps: k is small, and a `Vec::insert` would call memmove.
        self.items.push(Candidate { d2, p, id: 0 });
        let mut i = self.items.len() - 1;
        while i > 0 && self.items[i - 1].d2 > d2 {
            self.items.swap(i - 1, i);
            i -= 1;
        }
    }
}

impl VoxelHashMap {
    /// An empty map with search cells of `cell` metres, thinning to one point per `thin` metres
    /// (0 keeps every point). With thinning on, the cell is rounded to a whole number of thinning
    /// voxels so each voxel lies in one cell. A cell of two to five times the typical distance to
    /// the k-th neighbour is fastest.
    ///
    /// # Errors
    /// [`RegistrationError::InvalidConfig`] when `cell` is not positive and finite, `thin` is
    /// negative or not finite.
    pub fn new(cell: f64, thin: f64) -> Result<Self, RegistrationError> {
        check(
            cell.is_finite() && cell > 0.0,
            "VoxelHashMap::new cell",
            cell,
            POSITIVE,
        )?;
        check(
            thin.is_finite() && thin >= 0.0,
            "VoxelHashMap::new thin",
            thin,
            NON_NEGATIVE,
        )?;
        let cell = if thin > 0.0 {
            thin * (cell / thin).round().max(1.0)
        } else {
            cell
        };
        Ok(Self {
            cell,
            inv_cell: 1.0 / cell,
            thin,
            inv_thin: if thin > 0.0 { 1.0 / thin } else { 0.0 },
            cells: FxHashMap::default(),
            held: FxHashMap::default(),
            standins: FxHashMap::default(),
            owners: FxHashMap::default(),
            len: 0,
        })
    }

    /// Makes room for about `points` more points (fewer rehashes when a whole map is built at
    /// once; a thinned map's voxels are counted as points).
    pub fn reserve(&mut self, points: usize) {
        if self.thin > 0.0 {
            self.held.reserve(points);
        }
        // A cell holds tens of points on a surface.
        self.cells.reserve(points / 16);
    }

    /// Side of a search cell (metres), after rounding to the thinning voxel.
    #[must_use]
    pub fn cell_size(&self) -> f64 {
        self.cell
    }

    /// Points stored.
    #[must_use]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether no point is stored.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Every stored point, in no particular order.
    pub fn points(&self) -> impl Iterator<Item = Point3<f64>> + '_ {
        self.cells.values().flatten().map(|e| widen(e.p))
    }

    /// Adds `p` for `owner`. With thinning, a voxel keeps the point of the oldest owner that
    /// saw it (the first point within one owner) and remembers the newest other owner's point
    /// as a stand-in for when the oldest is removed. Non-finite points, and points beyond the
    /// cells (or thinning voxels) an `i32` numbers (2^31 cells from the origin: 859,000 km at
    /// 0.4 m), are skipped; returns whether `p` was kept (searchable or as a stand-in).
    pub fn insert(&mut self, owner: u32, p: &Point3<f64>) -> bool {
        let q = [p.x as f32, p.y as f32, p.z as f32];
        if !self.numbered(q) {
            return false;
        }
        let key = self.cell_key(q);
        let entry = Entry { p: q, owner };
        if self.thin > 0.0 {
            let voxel = self.voxel_key(q);
            match self.held.entry(voxel) {
                MapEntry::Occupied(held) => {
                    if *held.get() == owner {
                        return false;
                    }
                    self.standins.insert(voxel, entry);
                    let touched = self.owners.entry(owner).or_default();
                    touched.standins.push(voxel);
                    // A stand-in may come to hold the voxel: its owner's removal visits the cell.
                    touch(touched, key);
                    return true;
                }
                MapEntry::Vacant(free) => {
                    free.insert(owner);
                }
            }
        }
        self.cells.entry(key).or_default().push(entry);
        self.len += 1;
        touch(self.owners.entry(owner).or_default(), key);
        true
    }

    /// The key of the thinning voxel holding `p`.
    fn voxel_key(&self, p: [f32; 3]) -> u64 {
        grid_key(p, self.inv_thin)
    }

    /// The key of the cell holding `p`.
    fn cell_key(&self, p: [f32; 3]) -> u64 {
        grid_key(p, self.inv_cell)
    }

    /// Removes every point `owner` added; a voxel it held passes to its stand-in, the newest
    /// other owner that saw it. Returns how many searchable points were removed, net of
    /// stand-ins that took their place.
    pub fn remove_owner(&mut self, owner: u32) -> usize {
        let Some(touched) = self.owners.remove(&owner) else {
            return 0;
        };
        for voxel in touched.standins {
            if self.standins.get(&voxel).is_some_and(|e| e.owner == owner) {
                self.standins.remove(&voxel);
            }
        }
        let mut keys = touched.cells;
        keys.sort_unstable();
        keys.dedup();
        let before = self.len;
        for key in keys {
            let Some(mut entries) = self.cells.remove(&key) else {
                continue;
            };
            let mut removed = 0;
            entries.retain_mut(|e| {
                if e.owner != owner {
                    return true;
                }
                if self.thin > 0.0 {
                    let voxel = self.voxel_key(e.p);
                    if let Some(standin) = self.standins.remove(&voxel) {
                        self.held.insert(voxel, standin.owner);
                        *e = standin;
                        return true;
                    }
                    self.held.remove(&voxel);
                }
                removed += 1;
                false
            });
            self.len -= removed;
            if !entries.is_empty() {
                self.cells.insert(key, entries);
            }
        }
        before - self.len
    }

    /// Whether every coordinate of `q` is finite and lies inside the cells and thinning voxels an
    /// `i32` numbers, where a cell's points lie within its bounds (the search's pruning relies on
    /// it; beyond, cell indices saturate).
    fn numbered(&self, q: [f32; 3]) -> bool {
        let inv = self.inv_cell.max(self.inv_thin);
        let limit = f64::from(i32::MAX) - 1.0;
        q.iter()
            .all(|&v| v.is_finite() && (f64::from(v) * inv).abs() < limit)
    }

    /// The `k` points nearest `q` within `max_distance`, nearest first, as (squared distance,
    /// point) in `out` (cleared first; fewer than `k` when fewer lie within reach). A query
    /// beyond the numbered cells (see [`VoxelHashMap::insert`]) reads every point.
    pub fn nearest_k(
        &self,
        q: &Point3<f64>,
        k: usize,
        max_distance: f64,
        out: &mut Vec<(f64, Point3<f64>)>,
    ) {
        out.clear();
        if k == 0 || self.len == 0 || max_distance.is_nan() || max_distance <= 0.0 {
            return;
        }
        let mut items = Vec::with_capacity(k + 1);
        self.search(q, k, max_distance, &mut items);
        out.extend(items.iter().map(|c| (f64::from(c.d2), widen(c.p))));
    }

    /// The point nearest `q` within `max_distance`, with its squared distance.
    #[must_use]
    pub fn nearest(&self, q: &Point3<f64>, max_distance: f64) -> Option<(f64, Point3<f64>)> {
        let mut out = Vec::with_capacity(1);
        self.nearest_k(q, 1, max_distance, &mut out);
        out.first().copied()
    }

    /// Every stored point outside the rings `0..ring` around cell `base`: those whose key is none
    /// of theirs, so offsets modulo 2^21 (a cell 2^21 cells away shares a key).
    fn entries_outside(&self, base: [i32; 3], ring: i32) -> impl Iterator<Item = &Entry> + '_ {
        self.cells.values().flatten().filter(move |e| {
            let w = widen(e.p);
            let o = [
                key_offset(cell_of(w.x, self.inv_cell), base[0]),
                key_offset(cell_of(w.y, self.inv_cell), base[1]),
                key_offset(cell_of(w.z, self.inv_cell), base[2]),
            ];
            !o.iter().all(|v| v.abs() < ring)
        })
    }

    /// The search behind [`VoxelHashMap::nearest_k`], into a caller's buffer.
    pub(crate) fn search(
        &self,
        q: &Point3<f64>,
        k: usize,
        max_distance: f64,
        items: &mut Vec<Candidate>,
    ) {
        items.clear();
        if k == 0
            || self.len == 0
            || max_distance.is_nan()
            || max_distance <= 0.0
            || !q.coords.iter().all(|v| v.is_finite())
        {
            return;
        }
        let qf = [q.x as f32, q.y as f32, q.z as f32];
        let max_d2 = (max_distance * max_distance) as f32;
        let mut best = Best { k, items };
        let offer = |best: &mut Best<'_>, e: &Entry| {
            let d = [e.p[0] - qf[0], e.p[1] - qf[1], e.p[2] - qf[2]];
            let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            // Full: only a strictly nearer point enters. Not full: any within reach.
            let enters = if best.full() {
                d2 < best.bound(max_d2)
            } else {
                d2 <= max_d2
            };
            if enters {
                best.offer(d2, e.p);
            }
        };
        if !self.numbered(qf) {
            // Beyond the numbered cells the cell geometry does not hold: compare every point.
            for e in self.cells.values().flatten() {
                offer(&mut best, e);
            }
            return;
        }
        let w = widen(qf);
        let base = [
            cell_of(w.x, self.inv_cell),
            cell_of(w.y, self.inv_cell),
            cell_of(w.z, self.inv_cell),
        ];
        // The query's offset inside its cell, in metres from the low and the high face.
        let lo: [f64; 3] = std::array::from_fn(|a| w[a] - f64::from(base[a]) * self.cell);
        let hi: [f64; 3] = std::array::from_fn(|a| self.cell - lo[a]);
        let scan = |best: &mut Best<'_>, key: u64| {
            if let Some(entries) = self.cells.get(&key) {
                for e in entries {
                    offer(best, e);
                }
            }
        };
        scan(&mut best, pack(base));
        // Squared distance from the query to the cell at offset `o` along one axis.
        let gap = |a: usize, o: i32| -> f64 {
            match o {
                0 => 0.0,
                o if o > 0 => f64::from(o - 1) * self.cell + hi[a],
                o => f64::from(-o - 1) * self.cell + lo[a],
            }
        };
        let nearest_face = lo.iter().chain(&hi).fold(f64::INFINITY, |m, &v| m.min(v));
        if nearest_face * nearest_face > f64::from(best.bound(max_d2)) {
            return;
        }
        // Ring 1, nearest cells first so that the bound tightens before the far ones: offsets
        // are listed towards the query's nearer face (+1) or the farther one (-1) per axis.
        let near: [i32; 3] = std::array::from_fn(|a| if lo[a] < hi[a] { -1 } else { 1 });
        for rel in RING_ONE_NEAR_FIRST {
            let o: [i32; 3] = std::array::from_fn(|a| rel[a] * near[a]);
            let (gx, gy, gz) = (gap(0, o[0]), gap(1, o[1]), gap(2, o[2]));
            if (gx * gx + gy * gy + gz * gz) as f32 > best.bound(max_d2) {
                continue;
            }
            scan(&mut best, pack(offset(base, o)));
        }
        // Saturating: an infinite `max_distance` reaches every cell.
        let reach = ((max_distance * self.inv_cell).ceil() as i32)
            .saturating_add(1)
            .min(MAX_RING);
        for ring in 2..=reach {
            // Every cell outside the rings searched so far is at least this far.
            let outside = f64::from(ring - 1) * self.cell + nearest_face;
            if outside * outside > f64::from(best.bound(max_d2)) {
                break;
            }
            // A far reach over a sparse map: reading every occupied cell once is cheaper than
            // enumerating the remaining rings.
            // (2r + 1)^3 - (2r - 1)^3 cells, written so that it cannot overflow for r <= 2^20.
            let shell = 24 * i64::from(ring) * i64::from(ring) + 2;
            if usize::try_from(shell).unwrap_or(usize::MAX) > self.cells.len() {
                for e in self.entries_outside(base, ring) {
                    offer(&mut best, e);
                }
                break;
            }
            for dz in -ring..=ring {
                for dy in -ring..=ring {
                    let on_shell = dz.abs() == ring || dy.abs() == ring;
                    // Inside the shell only the two cells at dx = ±ring are new.
                    let step = if on_shell { 1 } else { (2 * ring) as usize };
                    for dx in (-ring..=ring).step_by(step) {
                        let (gx, gy, gz) = (gap(0, dx), gap(1, dy), gap(2, dz));
                        let d2 = gx * gx + gy * gy + gz * gz;
                        if d2 as f32 > best.bound(max_d2) {
                            continue;
                        }
                        scan(&mut best, pack(offset(base, [dx, dy, dz])));
                    }
                }
            }
        }
    }
}

impl NearestSearch for VoxelHashMap {
    fn nearest_into(&self, q: &Point3<f64>, n: usize, max_distance: f64, out: &mut Vec<Candidate>) {
        self.search(q, n, max_distance, out);
    }
}

/// The 26 neighbours of a cell, relative to the query (+1: towards its nearer face on that axis,
/// -1: the farther), roughly nearest first (the order only affects speed): cells touching only nearer
/// faces (faces, then edges, then the corner) first, then those across a farther face (at least
/// half a cell away).
const RING_ONE_NEAR_FIRST: [[i32; 3]; 26] = [
    [1, 0, 0],
    [0, 1, 0],
    [0, 0, 1],
    [1, 1, 0],
    [1, 0, 1],
    [0, 1, 1],
    [1, 1, 1],
    [-1, 0, 0],
    [0, -1, 0],
    [0, 0, -1],
    [-1, 1, 0],
    [-1, 0, 1],
    [1, -1, 0],
    [0, -1, 1],
    [1, 0, -1],
    [0, 1, -1],
    [-1, 1, 1],
    [1, -1, 1],
    [1, 1, -1],
    [-1, -1, 0],
    [-1, 0, -1],
    [0, -1, -1],
    [-1, -1, 1],
    [-1, 1, -1],
    [1, -1, -1],
    [-1, -1, -1],
];

/// The packed key of the grid box holding `p`, at `inv` boxes per metre.
fn grid_key(p: [f32; 3], inv: f64) -> u64 {
    let w = widen(p);
    pack([cell_of(w.x, inv), cell_of(w.y, inv), cell_of(w.z, inv)])
}

/// Records that an owner put a point in cell `key` (once per run of points in one cell).
fn touch(touched: &mut Touched, key: u64) {
    if touched.cells.last() != Some(&key) {
        touched.cells.push(key);
    }
}

fn widen(p: [f32; 3]) -> Point3<f64> {
    Point3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))
}

#[cfg(test)]
mod tests {
    use super::{cell_of, offset, pack};

    #[test]
    fn cells_saturate_and_offsets_wrap_as_the_keys_do() {
        // `t - 1` at i32::MIN wrapped to i32::MAX in release builds (and panicked in debug).
        assert_eq!(cell_of(-3e9, 1.0), i32::MIN);
        assert_eq!(cell_of(f64::NEG_INFINITY, 1.0), i32::MIN);
        assert_eq!(cell_of(3e9, 1.0), i32::MAX);
        assert_eq!(cell_of(-2.5, 1.0), -3);
        // The cell after the last one is the first one modulo 2^21, as its packed key says.
        let last = [i32::MAX, 0, i32::MIN];
        assert_eq!(
            pack(offset(last, [1, 0, -1])),
            pack([i32::MIN, 0, i32::MAX])
        );
    }
}
