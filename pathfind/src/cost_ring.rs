//! A monotone bucket queue for integer priorities (Dial 1969, with buckets of a power-of-two
//! width kept in a ring), for searches whose successors' priorities lie within a known window
//! ahead of the one being expanded. Within a bucket the entries are sorted by their exact key
//! (the priority, then the tie-break) when it becomes the current bucket, so pops come out in
//! exact key order: the buckets only spare a heap's logarithmic sifting.

use std::cmp::Reverse;

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

impl Entry {
    #[inline]
    fn key(&self) -> (u64, u32) {
        (self.f, self.tie)
    }
}

/// The ring. Precondition: every pushed priority lies in `[f_min, f_min + window)`, where
/// `f_min` is the priority last popped (or the first pushed after a clear) and `window` the width
/// given to [`CostRing::new`].
pub(crate) struct CostRing {
    buckets: Vec<Vec<Entry>>,
    /// Bit `s % 64` of word `s / 64` set when ring slot `s` holds entries.
    occupied: [u64; RING_WORDS],
    /// A bucket holds the priorities with the same `f >> shift`.
    shift: u32,
    /// Absolute number of the current bucket.
    base: u64,
    /// Whether the current bucket is sorted (descending: its minimum pops off the end).
    sorted: bool,
    /// Whether nothing was pushed since the last clear (the next push sets `base`).
    fresh: bool,
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
            buckets: (0..RING).map(|_| Vec::new()).collect(),
            occupied: [0; RING_WORDS],
            shift,
            base: 0,
            sorted: false,
            fresh: true,
        }
    }

    #[inline]
    fn slot(bucket: u64) -> usize {
        (bucket % RING as u64) as usize
    }

    /// Drop every entry.
    pub(crate) fn clear(&mut self) {
        for (w, word) in self.occupied.iter_mut().enumerate() {
            while *word != 0 {
                let s = w * 64 + word.trailing_zeros() as usize;
                *word &= *word - 1;
                self.buckets[s].clear();
            }
        }
        self.sorted = false;
        self.fresh = true;
    }

    /// Queue `index` with priority `f` and tie-break `tie`.
    #[inline]
    pub(crate) fn push(&mut self, f: u64, tie: u32, index: u32) {
        let bucket = f >> self.shift;
        if self.fresh {
            self.fresh = false;
            self.base = bucket;
        }
        debug_assert!(
            bucket >= self.base && bucket - self.base < RING as u64,
            "priority outside the ring's window"
        );
        let s = Self::slot(bucket);
        let entry = Entry { f, tie, index };
        let list = &mut self.buckets[s];
        if self.sorted && bucket == self.base {
            let at = list.partition_point(|q| q.key() > entry.key());
            list.insert(at, entry);
        } else {
            list.push(entry);
        }
        self.occupied[s / 64] |= 1 << (s % 64);
    }

    /// Buckets from the current one to the next occupied one; `None` when the ring is empty.
    #[inline]
    fn distance_to_next(&self) -> Option<u64> {
        let b = Self::slot(self.base);
        let (w, bit) = (b / 64, b % 64);
        let here = self.occupied[w] >> bit;
        if here != 0 {
            return Some(u64::from(here.trailing_zeros()));
        }
        for k in 1..=RING_WORDS {
            let word = self.occupied[(w + k) % RING_WORDS];
            if word != 0 {
                let slot = ((w + k) % RING_WORDS) * 64 + word.trailing_zeros() as usize;
                return Some(((slot + RING - b) % RING) as u64);
            }
        }
        None
    }

    /// The entry with the smallest `(f, tie)`.
    #[inline]
    pub(crate) fn pop(&mut self) -> Option<Entry> {
        let step = self.distance_to_next()?;
        if step != 0 {
            self.base += step;
            self.sorted = false;
        }
        let s = Self::slot(self.base);
        let list = &mut self.buckets[s];
        if !self.sorted {
            if list.len() > 1 {
                list.sort_unstable_by_key(|q| Reverse(q.key()));
            }
            self.sorted = true;
        }
        let q = list.pop()?;
        if list.is_empty() {
            self.occupied[s / 64] &= !(1 << (s % 64));
            self.sorted = false;
        }
        Some(q)
    }
}

#[cfg(test)]
mod tests {
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
