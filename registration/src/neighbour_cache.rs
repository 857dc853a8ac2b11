//! `NeighbourCache`: the k nearest target points of each source feature, reused across the
//! matchings of one alignment while it provably still holds them.
//!
//! A search for `kept > k` neighbours at `a` also proves that no other target point lies nearer
//! to `a` than the farthest one kept, `clear`. After the pose moves the feature to `b`, every
//! point not kept is at least `clear - |b - a|` from `b` (triangle inequality), so if the k-th
//! nearest kept point is within that, the k nearest kept points are the k nearest of the whole
//! target: exact, at the cost of `kept` distances instead of a search. Otherwise it searches again.

use nalgebra::Point3;

use crate::voxel_hash_map::VoxelHashMap;

/// What one slot's lookup found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Neighbours {
    /// Fewer than k target points within reach.
    TooFew,
    /// The same k points as the slot's previous answer (not written to the output again).
    Unchanged,
    /// A new set of k points, written to the output.
    Found,
}

/// One source feature's kept neighbours.
#[derive(Clone, Copy, Debug)]
struct Slot {
    /// Where the feature was when they were searched for.
    at: Point3<f64>,
    /// No target point that is not kept lies nearer to `at` than this (metres).
    clear: f64,
    /// How many are kept (`kept`, or fewer when fewer lie within reach).
    count: usize,
    /// Which kept points made the previous answer (bit per kept point); 0 when none.
    chosen: u32,
}

/// Per-feature neighbour lists for one alignment, indexed by a feature's slot number.
pub(crate) struct NeighbourCache {
    k: usize,
    kept: usize,
    max_distance: f64,
    slots: Vec<Option<Slot>>,
    /// `kept` points per slot.
    pool: Vec<[f32; 3]>,
    found: Vec<(f32, [f32; 3])>,
    order: Vec<(f32, usize)>,
}

impl NeighbourCache {
    /// A cache of `slots` features answering `k` nearest within `max_distance`, keeping `kept`
    /// (more than `k`, at most 32) per search.
    pub(crate) fn new(slots: usize, k: usize, kept: usize, max_distance: f64) -> Self {
        let kept = kept.clamp(k + 1, 32);
        Self {
            k,
            kept,
            max_distance,
            slots: vec![None; slots],
            pool: vec![[0.0; 3]; slots * kept],
            found: Vec::with_capacity(kept + 1),
            order: Vec::with_capacity(kept),
        }
    }

    /// The `k` points of `map` nearest `p` within reach for feature `slot`, written to `out`
    /// unless they are the same as this slot's previous answer.
    #[allow(clippy::cast_possible_truncation)]
    pub(crate) fn nearest(
        &mut self,
        slot: usize,
        map: &VoxelHashMap,
        p: &Point3<f64>,
        out: &mut Vec<Point3<f64>>,
    ) -> Neighbours {
        let Some(entry) = self.slots.get(slot).copied() else {
            return Neighbours::TooFew;
        };
        let reach2 = self.max_distance * self.max_distance;
        if let Some(s) = entry {
            let kept = &self.pool[slot * self.kept..slot * self.kept + s.count];
            self.order.clear();
            self.order.extend(kept.iter().enumerate().map(|(i, q)| {
                let d = [
                    f64::from(q[0]) - p.x,
                    f64::from(q[1]) - p.y,
                    f64::from(q[2]) - p.z,
                ];
                ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) as f32, i)
            }));
            if self.order.len() >= self.k {
                self.order
                    .select_nth_unstable_by(self.k - 1, |a, b| a.0.total_cmp(&b.0));
                let kth = f64::from(self.order[self.k - 1].0);
                let margin = s.clear - (p - s.at).norm();
                if kth <= reach2 && margin > 0.0 && kth <= margin * margin {
                    let chosen = self.order[..self.k]
                        .iter()
                        .fold(0u32, |m, &(_, i)| m | (1 << i));
                    if chosen == s.chosen {
                        return Neighbours::Unchanged;
                    }
                    out.clear();
                    out.extend(self.order[..self.k].iter().map(|&(_, i)| widen(kept[i])));
                    if let Some(Some(s)) = self.slots.get_mut(slot) {
                        s.chosen = chosen;
                    }
                    return Neighbours::Found;
                }
            }
        }
        // Search again, keeping more than asked for.
        map.search(p, self.kept, self.max_distance, &mut self.found);
        let count = self.found.len();
        for (dst, (_, q)) in self.pool[slot * self.kept..].iter_mut().zip(&self.found) {
            *dst = *q;
        }
        let clear = if count == self.kept {
            f64::from(self.found[count - 1].0).sqrt()
        } else {
            // Every point within reach is kept.
            self.max_distance
        };
        let enough = count >= self.k;
        // `found` is nearest first: the first k are the answer.
        self.slots[slot] = Some(Slot {
            at: *p,
            clear,
            count,
            chosen: if enough { (1u32 << self.k) - 1 } else { 0 },
        });
        if !enough {
            return Neighbours::TooFew;
        }
        out.clear();
        out.extend(self.found[..self.k].iter().map(|(_, q)| widen(*q)));
        Neighbours::Found
    }
}

fn widen(p: [f32; 3]) -> Point3<f64> {
    Point3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Walked in small and large steps, every answer (reused or searched) is the set of k
        /// nearest points a fresh search finds.
        #[test]
        fn answers_equal_a_fresh_search(
            points in prop::collection::vec((0.0..3.0f64, 0.0..3.0f64, 0.0..0.5f64), 10..600),
            steps in prop::collection::vec((-0.05..0.05f64, -0.05..0.05f64, -0.05..0.05f64), 1..40),
            start in (0.0..3.0f64, 0.0..3.0f64, 0.0..0.5f64),
            k in 3usize..7,
        ) {
            let mut map = VoxelHashMap::new(0.4, 0.0).unwrap();
            for &(x, y, z) in &points {
                map.insert(0, &Point3::new(x, y, z));
            }
            let mut cache = NeighbourCache::new(2, k, 2 * k, 1.0);
            let mut p = Point3::new(start.0, start.1, start.2);
            let (mut out, mut fresh) = (Vec::new(), Vec::new());
            let mut last: Option<Vec<Point3<f64>>> = None;
            for (i, &(dx, dy, dz)) in steps.iter().enumerate() {
                // Every seventh step jumps half a metre.
                let jump = if i % 7 == 6 { 10.0 } else { 1.0 };
                p += nalgebra::Vector3::new(dx, dy, dz) * jump;
                let answer = cache.nearest(1, &map, &p, &mut out);
                map.nearest_k(&p, k, 1.0, &mut fresh);
                let mut want: Vec<f64> = fresh.iter().map(|(d2, _)| *d2).collect();
                match answer {
                    Neighbours::TooFew => {
                        prop_assert!(fresh.len() < k);
                        last = None;
                        continue;
                    }
                    Neighbours::Unchanged => {
                        let prev = last.clone();
                        prop_assert!(prev.is_some(), "unchanged without a previous answer");
                        out = prev.unwrap_or_default();
                    }
                    Neighbours::Found => {}
                }
                let mut got: Vec<f64> = out.iter().map(|q| (q - p).norm_squared()).collect();
                got.sort_by(f64::total_cmp);
                want.sort_by(f64::total_cmp);
                prop_assert_eq!(got.len(), want.len());
                for (g, w) in got.iter().zip(&want) {
                    prop_assert!((g - w).abs() < 1e-5, "step {}: {:?} vs {:?}", i, got, want);
                }
                last = Some(out.clone());
            }
        }
    }
}
