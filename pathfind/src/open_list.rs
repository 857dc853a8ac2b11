//! Open lists for the best-first searches: a binary heap for the jump-point planners (successors
//! can lie any distance ahead) and a ring of buckets for the cell-by-cell searches, whose
//! successors' priorities lie within a fixed window ahead of the one being expanded.

use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

use crate::cost::{Cost, FRACTION_BITS};

/// An open-list entry: the smallest `(f, tie)` pops first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Open {
    /// Priority `g + h`.
    pub(crate) f: Cost,
    /// Tie-break among equal `f` (smaller first).
    pub(crate) tie: u32,
    /// The cell.
    pub(crate) index: u32,
}

impl Open {
    /// The order of the entries (smaller pops first): `f`, then `tie`.
    #[inline]
    fn key(&self) -> u128 {
        u128::from(self.f) << 32 | u128::from(self.tie)
    }
}

impl PartialOrd for Open {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Open {
    fn cmp(&self, other: &Self) -> Ordering {
        other.key().cmp(&self.key())
    }
}

/// A priority queue of cells (smallest `(f, tie)` first).
pub(crate) trait OpenList: Default {
    /// Drop every entry.
    fn clear(&mut self);
    /// Queue an entry.
    fn push(&mut self, open: Open);
    /// The entry with the smallest `(f, tie)`.
    fn pop(&mut self) -> Option<Open>;
}

/// A binary heap: any priorities.
#[derive(Default)]
pub(crate) struct KeyHeap(BinaryHeap<Open>);

impl OpenList for KeyHeap {
    #[inline]
    fn clear(&mut self) {
        self.0.clear();
    }
    #[inline]
    fn push(&mut self, open: Open) {
        self.0.push(open);
    }
    #[inline]
    fn pop(&mut self) -> Option<Open> {
        self.0.pop()
    }
}

/// Bucket of priority `f`: 64 buckets per cell (`f >> BUCKET_SHIFT`).
const BUCKET_SHIFT: u32 = FRACTION_BITS - 6;
/// The bits of `f` below its bucket.
const IN_BUCKET: Cost = (1 << BUCKET_SHIFT) - 1;

/// An entry of a ring bucket: the order within the bucket in one word (the bits of `f` below the
/// bucket, then the tie-break), so the sorting compares a single `u64`.
#[derive(Clone, Copy, Debug)]
struct Queued {
    key: u64,
    index: u32,
}
/// Words of the ring's occupancy bits.
const RING_WORDS: usize = 4;
/// Buckets in the ring.
const RING: usize = RING_WORDS * 64;

/// A monotone bucket queue (Dial 1969, with buckets 1/64 of a cell wide kept in a ring).
///
/// Precondition: every pushed priority `f` lies in `[f_min, f_min + 3)`, where `f_min` is the
/// priority last popped, or the first one pushed after a clear (the start, whose `f` is the
/// smallest of the search). A* with a consistent heuristic meets it on this grid: a successor's `f`
/// exceeds its parent's by at most twice the step cost, 2 sqrt(2) < 3, so the window spans at
/// most 193 of the 256 buckets. Within a bucket the entries are sorted by key when the bucket
/// becomes the current one (and inserted in order after that), so pops come out in exact key
/// order: the buckets only spare the heap's logarithmic sifting.
pub(crate) struct BucketRing {
    buckets: [Vec<Queued>; RING],
    /// Bit `s % 64` of word `s / 64` set when ring slot `s` holds entries.
    occupied: [u64; RING_WORDS],
    /// Absolute number of the current bucket (`floor(f * 64)` of the smallest entries).
    base: u64,
    /// Whether the current bucket is sorted (descending, so that its minimum pops off the end).
    sorted: bool,
    /// Whether nothing was pushed since the last clear (the next push sets `base`).
    fresh: bool,
}

impl Default for BucketRing {
    fn default() -> Self {
        Self {
            buckets: std::array::from_fn(|_| Vec::new()),
            occupied: [0; RING_WORDS],
            base: 0,
            sorted: false,
            fresh: true,
        }
    }
}

impl BucketRing {
    #[inline]
    fn slot(bucket: u64) -> usize {
        (bucket % RING as u64) as usize
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
        // The following words, wrapping round to the low bits of the current word last.
        for k in 1..=RING_WORDS {
            let word = self.occupied[(w + k) % RING_WORDS];
            if word != 0 {
                let slot = ((w + k) % RING_WORDS) * 64 + word.trailing_zeros() as usize;
                return Some(((slot + RING - b) % RING) as u64);
            }
        }
        None
    }
}

impl OpenList for BucketRing {
    fn clear(&mut self) {
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

    // Hot path: LLVM outlines it with plain `#[inline]` (measured; a call per neighbour).
    #[allow(clippy::inline_always)]
    #[inline(always)]
    fn push(&mut self, open: Open) {
        let bucket = open.f >> BUCKET_SHIFT;
        if self.fresh {
            self.fresh = false;
            self.base = bucket;
        }
        debug_assert!(
            bucket >= self.base && bucket - self.base < RING as u64,
            "priority outside the ring's window"
        );
        let s = Self::slot(bucket);
        let list = &mut self.buckets[s];
        let entry = Queued {
            key: (open.f & IN_BUCKET) << 32 | u64::from(open.tie),
            index: open.index,
        };
        if self.sorted && bucket == self.base {
            // Descending order: insert after every larger key.
            let at = list.partition_point(|q| q.key > entry.key);
            list.insert(at, entry);
        } else {
            list.push(entry);
        }
        self.occupied[s / 64] |= 1 << (s % 64);
    }

    // Hot path: LLVM outlines it with plain `#[inline]` (measured; a call per neighbour).
    #[allow(clippy::inline_always)]
    #[inline(always)]
    fn pop(&mut self) -> Option<Open> {
        let step = self.distance_to_next()?;
        if step != 0 {
            self.base += step;
            self.sorted = false;
        }
        let s = Self::slot(self.base);
        let list = &mut self.buckets[s];
        if !self.sorted {
            if list.len() > 1 {
                list.sort_unstable_by_key(|q| Reverse(q.key));
            }
            self.sorted = true;
        }
        let q = list.pop()?;
        if list.is_empty() {
            self.occupied[s / 64] &= !(1 << (s % 64));
            self.sorted = false;
        }
        Some(Open {
            f: self.base << BUCKET_SHIFT | q.key >> 32,
            tie: q.key as u32,
            index: q.index,
        })
    }
}
