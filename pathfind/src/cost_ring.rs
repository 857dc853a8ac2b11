//! A monotone bucket queue for integer priorities (Dial 1969, with buckets of a power-of-two
//! width kept in a ring), for searches whose successors' priorities lie within a known window
//! ahead of the one being expanded. Within a bucket the entries are sorted by their exact key
//! (the priority, then the tie-break) when it becomes the current bucket, so pops come out in
//! exact key order: the buckets only spare a heap's logarithmic sifting.

use crate::bucket_ring::{BucketRing, Keyed};

/// Words of the ring's occupancy bits.
const RING_WORDS: usize = 8;
/// Buckets in the ring.
pub(crate) const RING: usize = RING_WORDS * 64;

/// An entry: the smallest `(f, tie)` pops first.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Entry {
    /// The priority.
    pub(crate) f: u64,
    /// Tie-break among equal priorities (smaller first).
    pub(crate) tie: u32,
    /// The cell.
    pub(crate) index: u32,
}

impl Keyed for Entry {
    type Key = (u64, u32);
    #[inline]
    fn key(&self) -> (u64, u32) {
        (self.f, self.tie)
    }
}

/// The ring. Precondition: every pushed priority lies in `[f_min, f_min + window)`, where
/// `f_min` is the priority last popped (or the first pushed after a clear) and `window` the width
/// given to [`CostRing::new`].
pub(crate) struct CostRing {
    ring: BucketRing<Entry, RING_WORDS>,
    /// A bucket holds the priorities with the same `f >> shift`.
    shift: u32,
}

impl CostRing {
    /// A ring for priorities that never run `window` or more ahead of the current minimum, with
    /// buckets `2^min_shift` wide or wider.
    pub(crate) fn new(window: u64, min_shift: u32) -> Self {
        let mut shift = min_shift.min(63);
        while shift < 63 && (window >> shift) >= (RING - 8) as u64 {
            shift += 1;
        }
        Self {
            ring: BucketRing::default(),
            shift,
        }
    }

    /// Drop every entry.
    pub(crate) fn clear(&mut self) {
        self.ring.clear();
    }

    /// Queue `index` with priority `f` and tie-break `tie`.
    #[inline]
    pub(crate) fn push(&mut self, f: u64, tie: u32, index: u32) {
        self.ring.push(f >> self.shift, Entry { f, tie, index });
    }

    /// The entry with the smallest `(f, tie)`.
    #[inline]
    pub(crate) fn pop(&mut self) -> Option<Entry> {
        self.ring.pop().map(|(_, e)| e)
    }
}

#[cfg(test)]
mod tests {
    use std::cmp::Reverse;

    use super::*;

    /// Pops in key order against a sorted list, with pushes within the window of the last pop.
    #[test]
    fn pops_in_key_order() {
        let mut s = 7u64;
        let mut rnd = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        for (window, min_shift) in [(3u64 << 20, 14), (6 << 20, 14), (300 << 20, 14), (1000, 0)] {
            let mut ring = CostRing::new(window, min_shift);
            let mut reference: Vec<(u64, u32, u32)> = Vec::new();
            let mut last = 0u64;
            ring.push(0, 0, 0);
            reference.push((0, 0, 0));
            for i in 1..20_000u32 {
                if rnd() % 3 == 0 {
                    reference.sort_unstable_by_key(|e| Reverse((e.0, e.1)));
                    let want = reference.pop();
                    let got = ring.pop().map(|e| (e.f, e.tie, e.index));
                    assert_eq!(got.map(|g| (g.0, g.1)), want.map(|w| (w.0, w.1)));
                    if let Some(g) = got {
                        last = g.0;
                    }
                } else {
                    let f = last + rnd() % window;
                    let tie = (rnd() % 4) as u32;
                    ring.push(f, tie, i);
                    reference.push((f, tie, i));
                }
            }
            ring.clear();
            assert!(ring.pop().is_none());
        }
    }
}
