//! Open lists for the best-first searches: a binary heap for the jump-point planners (successors
//! can lie any distance ahead) and a ring of buckets for the cell-by-cell searches, whose
//! successors' priorities lie within a fixed window ahead of the one being expanded.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use crate::bucket_ring::{BucketRing, Keyed};
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

impl Keyed for Queued {
    type Key = u64;
    #[inline]
    fn key(&self) -> u64 {
        self.key
    }
}

/// A monotone bucket queue with buckets 1/64 of a cell wide.
///
/// Precondition: every pushed priority `f` lies in `[f_min, f_min + 3)`, where `f_min` is the
/// priority last popped, or the first one pushed after a clear (the start, whose `f` is the
/// smallest of the search). A* with a consistent heuristic meets it on this grid: a successor's `f`
/// exceeds its parent's by at most twice the step cost, 2 sqrt(2) < 3, so the window spans at
/// most 193 of the 256 buckets.
#[derive(Default)]
pub(crate) struct CellRing(BucketRing<Queued, 4>);

impl OpenList for CellRing {
    fn clear(&mut self) {
        self.0.clear();
    }

    // Hot path: LLVM outlines it with plain `#[inline]` (measured; a call per neighbour).
    #[allow(clippy::inline_always)]
    #[inline(always)]
    fn push(&mut self, open: Open) {
        let entry = Queued {
            key: (open.f & IN_BUCKET) << 32 | u64::from(open.tie),
            index: open.index,
        };
        self.0.push(open.f >> BUCKET_SHIFT, entry);
    }

    // Hot path: LLVM outlines it with plain `#[inline]` (measured; a call per neighbour).
    #[allow(clippy::inline_always)]
    #[inline(always)]
    fn pop(&mut self) -> Option<Open> {
        let (bucket, q) = self.0.pop()?;
        Some(Open {
            f: bucket << BUCKET_SHIFT | q.key >> 32,
            tie: q.key as u32,
            index: q.index,
        })
    }
}
