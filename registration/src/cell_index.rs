//! `CellIndex`: a fixed target's points sorted into cubic cells, for exact k-nearest queries
//! within a short radius.
//!
//! A registration against a fixed map asks, for every scan point, for the few map points within
//! some tens of centimetres. A k-d tree over a building's map (hundreds of thousands of points)
//! descends a dozen levels and backtracks through leaves of tens of points for each such query;
//! here a query reads the few cells its sphere overlaps, found by hashing, and each cell's points
//! lie together in one array.

use nalgebra::Point3;
use rustc_hash::FxHashMap;

use crate::neighbour_cache::Candidate;

/// Queries whose sphere overlaps more cells than this, or more than this many along one axis,
/// are left to the caller's other search.
const MAX_CELLS_PER_QUERY: i64 = 512;
const MAX_CELLS_PER_AXIS: usize = 16;

/// Points in cubic cells: each cell's points stored contiguously, a hash from cell to its span.
pub(crate) struct CellIndex {
    cell: f64,
    inv_cell: f64,
    /// Packed cell key to the cell's span in `points` and `ids`.
    spans: FxHashMap<u64, (u32, u32)>,
    points: Vec<[f32; 3]>,
    ids: Vec<u32>,
}

/// Integer cell of `v` at `inv` cells per metre, or `None` beyond what an `i32` numbers.
#[allow(clippy::cast_possible_truncation)]
fn cell_of(v: f64, inv: f64) -> Option<i32> {
    let x = v * inv;
    if !(x >= f64::from(i32::MIN) && x < f64::from(i32::MAX) + 1.0) {
        return None;
    }
    // Truncate, then step down for negatives: `f64::floor` is a library call on baseline x86-64.
    let t = x as i32;
    Some(if f64::from(t) > x { t - 1 } else { t })
}

/// A cell's packed key: 21 bits per axis; cells 2^21 apart share a key, and the distance test
/// rejects the far ones.
fn pack(x: i32, y: i32, z: i32) -> u64 {
    axis_key(x) | (axis_key(y) << 21) | (axis_key(z) << 42)
}

/// One axis' 21 bits of a cell's key.
#[allow(clippy::cast_sign_loss)]
fn axis_key(v: i32) -> u64 {
    u64::from(v as u32 & 0x1F_FFFF)
}

impl CellIndex {
    /// The index of `points` (ids are their positions) in cells of `cell` metres; `None` when
    /// `cell` is not positive and finite, there are more points than a `u32` numbers, or a point
    /// lies beyond the cells an `i32` numbers.
    pub(crate) fn new(points: &[Point3<f64>], cell: f64) -> Option<Self> {
        if !(cell.is_finite() && cell > 0.0) || u32::try_from(points.len()).is_err() {
            return None;
        }
        let inv_cell = 1.0 / cell;
        let mut keyed = Vec::with_capacity(points.len());
        for (i, p) in points.iter().enumerate() {
            let key = pack(
                cell_of(p.x, inv_cell)?,
                cell_of(p.y, inv_cell)?,
                cell_of(p.z, inv_cell)?,
            );
            #[allow(clippy::cast_possible_truncation)]
            keyed.push((key, i as u32));
        }
        keyed.sort_unstable();
        let mut spans = FxHashMap::default();
        spans.reserve(points.len() / 4);
        let mut start = 0usize;
        for (end, w) in keyed.windows(2).enumerate() {
            if w[0].0 != w[1].0 {
                #[allow(clippy::cast_possible_truncation)]
                spans.insert(w[0].0, (start as u32, end as u32 + 1));
                start = end + 1;
            }
        }
        if let Some(&(key, _)) = keyed.last() {
            #[allow(clippy::cast_possible_truncation)]
            spans.insert(key, (start as u32, keyed.len() as u32));
        }
        #[allow(clippy::cast_possible_truncation)]
        let stored = keyed
            .iter()
            .map(|&(_, i)| {
                let p = points[i as usize];
                [p.x as f32, p.y as f32, p.z as f32]
            })
            .collect();
        Some(Self {
            cell,
            inv_cell,
            spans,
            points: stored,
            ids: keyed.iter().map(|&(_, i)| i).collect(),
        })
    }

    /// The `n` points nearest `q` within `max_distance`, nearest first, into `out` (cleared);
    /// `false` (and `out` empty) when the sphere overlaps too many cells for this index, so the
    /// caller searches otherwise.
    #[allow(clippy::cast_possible_truncation)]
    pub(crate) fn nearest_into(
        &self,
        q: &Point3<f64>,
        n: usize,
        max_distance: f64,
        out: &mut Vec<Candidate>,
    ) -> bool {
        out.clear();
        if n == 0 || max_distance.is_nan() || max_distance <= 0.0 {
            return true;
        }
        if !q.coords.iter().all(|v| v.is_finite()) {
            return true;
        }
        let range = |v: f64| {
            Some((
                cell_of(v - max_distance, self.inv_cell)?,
                cell_of(v + max_distance, self.inv_cell)?,
            ))
        };
        let (Some((x0, x1)), Some((y0, y1)), Some((z0, z1))) = (range(q.x), range(q.y), range(q.z))
        else {
            return false;
        };
        let spans = [
            i64::from(x1) - i64::from(x0) + 1,
            i64::from(y1) - i64::from(y0) + 1,
            i64::from(z1) - i64::from(z0) + 1,
        ];
        #[allow(clippy::cast_possible_wrap)]
        if spans.iter().any(|&s| s > MAX_CELLS_PER_AXIS as i64)
            || spans.iter().product::<i64>() > MAX_CELLS_PER_QUERY
        {
            return false;
        }
        let qf = [q.x as f32, q.y as f32, q.z as f32];
        let mut bound = (max_distance * max_distance) as f32;
        // Per axis: each cell's squared gap to the query (0 for the query's own) and its part
        // of the packed key.
        let mut gaps = [[0f32; MAX_CELLS_PER_AXIS]; 3];
        let mut parts = [[0u64; MAX_CELLS_PER_AXIS]; 3];
        let mut own = [0usize; 3];
        for (a, (lo, hi, v)) in [(x0, x1, q.x), (y0, y1, q.y), (z0, z1, q.z)]
            .into_iter()
            .enumerate()
        {
            for (i, c) in (lo..=hi).enumerate() {
                let low = f64::from(c) * self.cell;
                let gap = if v < low {
                    low - v
                } else if v >= low + self.cell {
                    v - low - self.cell
                } else {
                    own[a] = i;
                    0.0
                };
                gaps[a][i] = (gap * gap) as f32;
                parts[a][i] = axis_key(c) << (21 * a);
            }
        }
        let (nx, ny, nz) = (
            (x1 - x0) as usize + 1,
            (y1 - y0) as usize + 1,
            (z1 - z0) as usize + 1,
        );
        // The query's own cell first: its points usually set a tight bound at once.
        self.scan_cell(
            parts[0][own[0]] | parts[1][own[1]] | parts[2][own[2]],
            qf,
            n,
            &mut bound,
            out,
        );
        for z in 0..nz {
            let gz = gaps[2][z];
            if gz > bound {
                continue;
            }
            for y in 0..ny {
                let gyz = gaps[1][y] + gz;
                if gyz > bound {
                    continue;
                }
                let key_yz = parts[1][y] | parts[2][z];
                for x in 0..nx {
                    if gaps[0][x] + gyz > bound || (x, y, z) == (own[0], own[1], own[2]) {
                        continue;
                    }
                    self.scan_cell(parts[0][x] | key_yz, qf, n, &mut bound, out);
                }
            }
        }
        true
    }

    /// Offers the points of cell `key` to the `n` best in `out` (sorted, nearest first), whose
    /// entry bound `bound` tightens once `out` holds `n`.
    fn scan_cell(
        &self,
        key: u64,
        q: [f32; 3],
        n: usize,
        bound: &mut f32,
        out: &mut Vec<Candidate>,
    ) {
        let Some(&(start, end)) = self.spans.get(&key) else {
            return;
        };
        let (start, end) = (start as usize, end as usize);
        for (p, &id) in self.points[start..end].iter().zip(&self.ids[start..end]) {
            let d = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
            let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            if d2 > *bound {
                continue;
            }
            if out.len() == n {
                out.pop();
            }
            out.push(Candidate { d2, p: *p, id });
            let mut i = out.len() - 1;
            while i > 0 && out[i - 1].d2 > d2 {
                out.swap(i - 1, i);
                i -= 1;
            }
            if out.len() == n {
                *bound = out[n - 1].d2;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The `n` nearest within `r` by comparing every point, nearest first.
    fn brute(points: &[Point3<f64>], q: &Point3<f64>, n: usize, r: f64) -> Vec<(f32, u32)> {
        #[allow(clippy::cast_possible_truncation)]
        let qf = [q.x as f32, q.y as f32, q.z as f32];
        let mut all: Vec<(f32, u32)> = points
            .iter()
            .enumerate()
            .filter_map(|(i, p)| {
                #[allow(clippy::cast_possible_truncation)]
                let d = [p.x as f32 - qf[0], p.y as f32 - qf[1], p.z as f32 - qf[2]];
                let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                #[allow(clippy::cast_possible_truncation)]
                (d2 <= (r * r) as f32).then_some((d2, u32::try_from(i).unwrap_or(0)))
            })
            .collect();
        all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        all.truncate(n);
        all
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Planes and scatter around the origin, queried near and far with several counts and
        /// radii: the distances found are a brute-force search's, nearest first, and each id
        /// names a point at that distance.
        #[test]
        fn answers_equal_a_brute_force_search(
            scatter in proptest::collection::vec((-3.0f64..3.0, -3.0f64..3.0, -1.0f64..2.0), 1..300),
            queries in proptest::collection::vec((-4.0f64..4.0, -4.0f64..4.0, -1.5f64..2.5), 1..40),
            cell in 0.05f64..1.0,
            n in 1usize..12,
            r in 0.05f64..1.5,
        ) {
            let mut points: Vec<Point3<f64>> =
                scatter.iter().map(|&(x, y, z)| Point3::new(x, y, z)).collect();
            for i in 0..30 {
                for j in 0..30 {
                    let (a, b) = (f64::from(i) * 0.1 - 1.5, f64::from(j) * 0.1 - 1.5);
                    points.push(Point3::new(a, b, 0.0));
                    points.push(Point3::new(a, 1.2, b + 1.0));
                }
            }
            let index = CellIndex::new(&points, cell).unwrap();
            let mut out = Vec::new();
            for &(x, y, z) in &queries {
                let q = Point3::new(x, y, z);
                let want = brute(&points, &q, n, r);
                if !index.nearest_into(&q, n, r, &mut out) {
                    // Too many cells for this index: the caller searches otherwise.
                    prop_assert!(r / cell > 3.0);
                    continue;
                }
                let got: Vec<f32> = out.iter().map(|c| c.d2).collect();
                let wanted: Vec<f32> = want.iter().map(|w| w.0).collect();
                prop_assert_eq!(got, wanted);
                for c in &out {
                    let p = points[c.id as usize];
                    #[allow(clippy::cast_possible_truncation)]
                    let stored = [p.x as f32, p.y as f32, p.z as f32];
                    // Bit for bit: the stored coordinates are the point's own.
                    prop_assert_eq!(c.p.map(f32::to_bits), stored.map(f32::to_bits));
                }
            }
        }
    }

    #[test]
    fn refuses_what_it_cannot_number_and_answers_nothing_for_bad_queries() {
        assert!(CellIndex::new(&[Point3::new(1e12, 0.0, 0.0)], 1e-3).is_none());
        assert!(CellIndex::new(&[Point3::origin()], 0.0).is_none());
        assert!(CellIndex::new(&[Point3::origin()], f64::NAN).is_none());
        let index = CellIndex::new(&[Point3::origin(), Point3::new(0.1, 0.0, 0.0)], 0.25).unwrap();
        let mut out = vec![Candidate::default()];
        assert!(index.nearest_into(&Point3::new(f64::NAN, 0.0, 0.0), 2, 1.0, &mut out));
        assert!(out.is_empty());
        assert!(index.nearest_into(&Point3::origin(), 0, 1.0, &mut out));
        assert!(out.is_empty());
        // Far beyond the numbered cells: left to the caller.
        assert!(!index.nearest_into(&Point3::new(1e300, 0.0, 0.0), 2, 1.0, &mut out));
        // A sphere over too many cells: left to the caller.
        assert!(!index.nearest_into(&Point3::origin(), 2, 100.0, &mut out));
        assert!(index.nearest_into(&Point3::new(0.04, 0.0, 0.0), 2, 0.5, &mut out));
        assert_eq!(out.iter().map(|c| c.id).collect::<Vec<_>>(), vec![0, 1]);
    }
}
