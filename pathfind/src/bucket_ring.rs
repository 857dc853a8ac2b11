//! A monotone bucket queue (Dial 1969) with its buckets kept in a ring, for searches whose
//! successors' priorities lie within a known window ahead of the one being expanded. The caller
//! says which bucket an entry goes to; within a bucket the entries are sorted by their exact key
//! when it becomes the current bucket (and inserted in order after that), so pops come out in
//! exact key order: the buckets only spare a heap's logarithmic sifting.

use std::cmp::Reverse;

/// An entry of a [`BucketRing`]: the smallest key pops first.
pub(crate) trait Keyed: Copy {
    /// The order within a bucket.
    type Key: Ord + Copy;
    /// This entry's key.
    fn key(&self) -> Self::Key;
}

/// The ring of `WORDS * 64` buckets. Precondition: every pushed bucket lies in
/// `[b_min, b_min + WORDS * 64)`, where `b_min` is the bucket last popped from (or the first
/// pushed after a clear).
pub(crate) struct BucketRing<E, const WORDS: usize> {
    buckets: Box<[Vec<E>]>,
    /// Bit `s % 64` of word `s / 64` set when ring slot `s` holds entries.
    occupied: [u64; WORDS],
    /// Absolute number of the current bucket.
    base: u64,
    /// Whether the current bucket is sorted (descending: its minimum pops off the end).
    sorted: bool,
    /// Whether nothing was pushed since the last clear (the next push sets `base`).
    fresh: bool,
}

impl<E: Keyed, const WORDS: usize> Default for BucketRing<E, WORDS> {
    fn default() -> Self {
        Self {
            buckets: (0..WORDS * 64).map(|_| Vec::new()).collect(),
            occupied: [0; WORDS],
            base: 0,
            sorted: false,
            fresh: true,
        }
    }
}

impl<E: Keyed, const WORDS: usize> BucketRing<E, WORDS> {
    /// Buckets in the ring.
    pub(crate) const SLOTS: usize = WORDS * 64;

    #[inline]
    fn slot(bucket: u64) -> usize {
        (bucket % Self::SLOTS as u64) as usize
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

    /// Queue `entry` in absolute bucket `bucket`.
    // Hot path: LLVM outlines it with plain `#[inline]` (measured; a call per neighbour).
    #[allow(clippy::inline_always)]
    #[inline(always)]
    pub(crate) fn push(&mut self, bucket: u64, entry: E) {
        if self.fresh {
            self.fresh = false;
            self.base = bucket;
        }
        debug_assert!(
            bucket >= self.base && bucket - self.base < Self::SLOTS as u64,
            "priority outside the ring's window"
        );
        let s = Self::slot(bucket);
        let list = &mut self.buckets[s];
        if self.sorted && bucket == self.base {
            // Descending order: insert after every larger key.
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
        // The following words, wrapping round to the low bits of the current word last.
        for k in 1..=WORDS {
            let word = self.occupied[(w + k) % WORDS];
            if word != 0 {
                let slot = ((w + k) % WORDS) * 64 + word.trailing_zeros() as usize;
                return Some(((slot + Self::SLOTS - b) % Self::SLOTS) as u64);
            }
        }
        None
    }

    /// The entry with the smallest key of the lowest occupied bucket, with that bucket.
    // Hot path: LLVM outlines it with plain `#[inline]` (measured; a call per neighbour).
    #[allow(clippy::inline_always)]
    #[inline(always)]
    pub(crate) fn pop(&mut self) -> Option<(u64, E)> {
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
        Some((self.base, q))
    }
}
