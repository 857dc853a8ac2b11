//! `NeighbourCache`: the k nearest target points of each source point, reused across the
//! matchings of one alignment while it provably still holds them.
//!
//! A search for `kept > k` neighbours at `a` also proves that no other target point lies nearer
//! to `a` than the farthest one kept, `clear`. After the pose moves the point to `b`, every point
//! not kept is at least `clear - |b - a|` from `b` (triangle inequality), so if the k-th nearest
//! kept point is within that, the k nearest kept points are the k nearest of the whole target:
//! exact, at the cost of `kept` distances instead of a search. Otherwise it searches again.

use nalgebra::Point3;

/// A target point found by a search.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Candidate {
    /// Squared distance to the query (metres²).
    pub(crate) d2: f32,
    /// The point.
    pub(crate) p: [f32; 3],
    /// Its index in the target, where the target has one (0 otherwise).
    pub(crate) id: u32,
}

/// A target that answers k-nearest queries.
pub(crate) trait NearestSearch {
    /// The `n` points nearest `q` within `max_distance`, nearest first, into `out` (cleared).
    fn nearest_into(&self, q: &Point3<f64>, n: usize, max_distance: f64, out: &mut Vec<Candidate>);
}

/// What one lookup found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Neighbours {
    /// Fewer than k target points within reach.
    TooFew,
    /// The same k points as the slot's previous answer.
    Unchanged,
    /// A different set of k points.
    Changed,
}

/// One source point's kept neighbours.
#[derive(Clone, Copy, Debug)]
struct Slot {
    /// Where the point was when they were searched for.
    at: Point3<f64>,
    /// No target point that is not kept lies nearer to `at` than this (metres).
    clear: f64,
    /// How many are kept (`kept`, or fewer when fewer lie within reach).
    count: usize,
    /// Which kept points made the previous answer (bit per kept point); 0 when none.
    chosen: u32,
}

/// Per-point neighbour lists for one alignment, indexed by a point's slot number.
pub(crate) struct NeighbourCache {
    k: usize,
    kept: usize,
    max_distance: f64,
    /// Searches look this far first, and as far as `SEARCH_SLACK * max_distance` only when
    /// fewer than k points lie this near: a k-d tree prunes much more with a small bound.
    first_radius: f64,
    slots: Vec<Option<Slot>>,
    /// `kept` candidates per slot.
    pool: Vec<Candidate>,
    found: Vec<Candidate>,
    order: Vec<(f32, usize)>,
}

impl NeighbourCache {
    /// A cache of `slots` points answering `k` nearest within `max_distance`, keeping `kept`
    /// (more than `k`, at most 32) per search.
    pub(crate) fn new(slots: usize, k: usize, kept: usize, max_distance: f64) -> Self {
        let kept = kept.clamp(k + 1, 32);
        Self {
            k,
            kept,
            max_distance,
            first_radius: f64::INFINITY,
            slots: vec![None; slots],
            pool: vec![Candidate::default(); slots * kept],
            found: Vec::with_capacity(kept + 1),
            order: Vec::with_capacity(kept),
        }
    }

    /// Search within `radius` first (and farther only when fewer than k lie that near).
    pub(crate) fn with_first_radius(mut self, radius: f64) -> Self {
        self.first_radius = radius;
        self
    }

    /// Answers within `max_distance` from now on, searching `first_radius` away first. What a
    /// slot holds stays true: its kept points and the radius clear of any other do not depend
    /// on the reach.
    pub(crate) fn set_reach(&mut self, max_distance: f64, first_radius: f64) {
        self.max_distance = max_distance;
        self.first_radius = first_radius;
    }

    /// The `k` points of `target` nearest `p` within reach for point `slot`, into `out`
    /// (cleared; in no particular order), and whether they changed since this slot's previous
    /// answer.
    pub(crate) fn nearest<T: NearestSearch + ?Sized>(
        &mut self,
        slot: usize,
        target: &T,
        p: &Point3<f64>,
        out: &mut Vec<Candidate>,
    ) -> Neighbours {
        out.clear();
        let Some(entry) = self.slots.get(slot).copied() else {
            return Neighbours::TooFew;
        };
        let reach2 = self.max_distance * self.max_distance;
        if let Some(s) = entry {
            let kept = &self.pool[slot * self.kept..slot * self.kept + s.count];
            let margin = s.clear - (p - s.at).norm();
            if margin > 0.0 {
                self.order.clear();
                self.order
                    .extend(kept.iter().enumerate().filter_map(|(i, c)| {
                        let d = [
                            f64::from(c.p[0]) - p.x,
                            f64::from(c.p[1]) - p.y,
                            f64::from(c.p[2]) - p.z,
                        ];
                        let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                        (d2 <= reach2).then_some((d2 as f32, i))
                    }));
                if self.order.len() >= self.k {
                    self.order
                        .select_nth_unstable_by(self.k - 1, |a, b| a.0.total_cmp(&b.0));
                    let kth = f64::from(self.order[self.k - 1].0);
                    if kth <= margin * margin {
                        let chosen = self.order[..self.k]
                            .iter()
                            .fold(0u32, |m, &(_, i)| m | (1 << i));
                        out.extend(
                            self.order[..self.k]
                                .iter()
                                .map(|&(d2, i)| Candidate { d2, ..kept[i] }),
                        );
                        if let Some(Some(s)) = self.slots.get_mut(slot) {
                            let same = s.chosen == chosen;
                            s.chosen = chosen;
                            if same {
                                return Neighbours::Unchanged;
                            }
                        }
                        return Neighbours::Changed;
                    }
                } else if margin >= self.max_distance {
                    // No point that is not kept lies within reach, and fewer than k kept do.
                    if let Some(Some(s)) = self.slots.get_mut(slot) {
                        s.chosen = 0;
                    }
                    return Neighbours::TooFew;
                }
            }
        }
        // Search again, keeping more than asked for and looking further than the reach, so that
        // a point with too few neighbours can be answered again without a search.
        let wide = SEARCH_SLACK * self.max_distance;
        let mut search_distance = self.first_radius.min(wide);
        target.nearest_into(p, self.kept, search_distance, &mut self.found);
        if self.found.len() < self.k && search_distance < wide {
            search_distance = wide;
            target.nearest_into(p, self.kept, search_distance, &mut self.found);
        }
        let count = self.found.len().min(self.kept);
        self.pool[slot * self.kept..slot * self.kept + count].copy_from_slice(&self.found[..count]);
        let clear = if count == self.kept {
            f64::from(self.found[count - 1].d2).sqrt()
        } else {
            // Every point within the search distance is kept.
            search_distance
        };
        // `found` is nearest first: the first k are the answer when the k-th is within reach.
        let enough = count >= self.k && f64::from(self.found[self.k - 1].d2) <= reach2;
        self.slots[slot] = Some(Slot {
            at: *p,
            clear,
            count,
            chosen: if enough { (1u32 << self.k) - 1 } else { 0 },
        });
        if !enough {
            return Neighbours::TooFew;
        }
        out.extend_from_slice(&self.found[..self.k]);
        // A fresh search renumbers the kept points: report a change (at worst a needless refit).
        Neighbours::Changed
    }
}

/// Searches look this many times the reach away.
const SEARCH_SLACK: f64 = 1.5;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::voxel_hash_map::VoxelHashMap;
    use proptest::prelude::*;
    use proptest::test_runner::TestCaseError;

    /// Whether the cache's answer `out` for `p` holds the same distances as the fresh search's
    /// `fresh` (to rounding); why not otherwise.
    fn same_distances(
        out: &[Candidate],
        fresh: &[Candidate],
        p: &Point3<f64>,
    ) -> Result<(), String> {
        let mut got: Vec<f64> = out
            .iter()
            .map(|c| {
                (Point3::new(f64::from(c.p[0]), f64::from(c.p[1]), f64::from(c.p[2])) - p)
                    .norm_squared()
            })
            .collect();
        let mut want: Vec<f64> = fresh.iter().map(|c| f64::from(c.d2)).collect();
        got.sort_by(f64::total_cmp);
        want.sort_by(f64::total_cmp);
        let same =
            got.len() == want.len() && got.iter().zip(&want).all(|(g, w)| (g - w).abs() < 1e-5);
        if same {
            Ok(())
        } else {
            Err(format!("{got:?} vs {want:?}"))
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Walked in small and large steps, every answer (reused or searched) is the set of k
        /// nearest points a fresh search finds, and "unchanged" only repeats the previous set.
        #[test]
        fn answers_equal_a_fresh_search(
            points in prop::collection::vec((0.0..3.0f64, 0.0..3.0f64, 0.0..0.5f64), 10..600),
            steps in prop::collection::vec((-0.05..0.05f64, -0.05..0.05f64, -0.05..0.05f64), 1..40),
            start in (0.0..3.0f64, 0.0..3.0f64, 0.0..0.5f64),
            k in 1usize..7,
            first_radius in prop::sample::select(vec![0.05, 0.2, 0.5, f64::INFINITY]),
        ) {
            let mut map = VoxelHashMap::new(0.4, 0.0).unwrap();
            for &(x, y, z) in &points {
                map.insert(0, &Point3::new(x, y, z));
            }
            let mut cache = NeighbourCache::new(2, k, 2 * k, 1.0).with_first_radius(first_radius);
            let mut p = Point3::new(start.0, start.1, start.2);
            let (mut out, mut fresh) = (Vec::new(), Vec::new());
            let mut last: Option<Vec<f64>> = None;
            for (i, &(dx, dy, dz)) in steps.iter().enumerate() {
                // Every seventh step jumps half a metre.
                let jump = if i % 7 == 6 { 10.0 } else { 1.0 };
                p += nalgebra::Vector3::new(dx, dy, dz) * jump;
                let answer = cache.nearest(1, &map, &p, &mut out);
                map.nearest_into(&p, k, 1.0, &mut fresh);
                if answer == Neighbours::TooFew {
                    prop_assert!(fresh.len() < k);
                    last = None;
                    continue;
                }
                let key = |c: &Candidate| f64::from(c.p[0]) * 1e6 + f64::from(c.p[1]) * 1e3 + f64::from(c.p[2]);
                same_distances(&out, &fresh, &p).map_err(|e| TestCaseError::fail(format!("step {i}: {e}")))?;
                let mut ids: Vec<f64> = out.iter().map(key).collect();
                ids.sort_by(f64::total_cmp);
                if answer == Neighbours::Unchanged {
                    prop_assert_eq!(Some(&ids), last.as_ref(), "step {}: unchanged, but not the previous set", i);
                }
                last = Some(ids);
            }
        }

        /// A cache carried from one reach to another (wide stages narrowing to the fine one, a
        /// recheck, the sweep) answers every step as a fresh search within the current reach.
        #[test]
        fn answers_equal_a_fresh_search_as_the_reach_changes(
            points in prop::collection::vec((0.0..3.0f64, 0.0..3.0f64, 0.0..0.5f64), 10..600),
            steps in prop::collection::vec(
                ((-0.05..0.05f64, -0.05..0.05f64, -0.05..0.05f64), 0usize..5),
                1..40,
            ),
            start in (0.0..3.0f64, 0.0..3.0f64, 0.0..0.5f64),
            k in 1usize..5,
        ) {
            const REACHES: [f64; 5] = [0.1, 0.3, 0.5, 1.0, 3.0];
            let mut map = VoxelHashMap::new(0.4, 0.0).unwrap();
            for &(x, y, z) in &points {
                map.insert(0, &Point3::new(x, y, z));
            }
            let mut cache = NeighbourCache::new(1, k, 2 * k, 1.0).with_first_radius(0.5);
            let mut p = Point3::new(start.0, start.1, start.2);
            let (mut out, mut fresh) = (Vec::new(), Vec::new());
            for (i, &((dx, dy, dz), r)) in steps.iter().enumerate() {
                let reach = REACHES[r];
                cache.set_reach(reach, (0.5 * reach).max(0.2));
                p += nalgebra::Vector3::new(dx, dy, dz);
                let answer = cache.nearest(0, &map, &p, &mut out);
                map.nearest_into(&p, k, reach, &mut fresh);
                if answer == Neighbours::TooFew {
                    prop_assert!(fresh.len() < k, "step {}: too few at reach {}", i, reach);
                    continue;
                }
                same_distances(&out, &fresh, &p)
                    .map_err(|e| TestCaseError::fail(format!("step {i} at reach {reach}: {e}")))?;
            }
        }
    }
}
