//! The cells expanded by the current query, one bit per cell in the grid's own layout, so that the
//! cell-by-cell searches drop expanded neighbours with a few word operations instead of reading
//! their search records (which the closed flag in the records would need, with a branch each).

use slam_core::{BitGrid, Cell};

use crate::movement::legal_steps_avoiding;

/// Expanded cells as the blocked cells of a grid of the same size.
pub(crate) struct ClosedSet {
    bits: BitGrid,
    /// The cells set in this query, cleared one by one at the next reset.
    set: Vec<Cell>,
}

impl ClosedSet {
    /// An empty set for grids the size of `grid`.
    pub(crate) fn new(grid: &BitGrid) -> Self {
        let mut set = Self {
            bits: grid.clone(),
            set: Vec::new(),
        };
        set.clear_all();
        set
    }

    /// Clear every word (keeping the padding bits past the east edge set).
    /// This set made empty over `grid` (the same as [`ClosedSet::new`]), in the same memory
    /// when it has room.
    pub(crate) fn renew(&mut self, grid: &BitGrid) {
        self.bits.clone_from(grid);
        self.set.clear();
        self.clear_all();
    }

    fn clear_all(&mut self) {
        for y in 0..self.bits.height() {
            self.bits.row_words_mut(y).fill(0);
        }
        self.bits.restore_padding();
    }

    /// Empty the set: cell by cell when it holds few cells, else every word at once (a cell costs a
    /// read-modify-write of its word, a word of a plain fill far less).
    pub(crate) fn reset(&mut self) {
        if self.set.len() * 8 >= self.bits.words().len() {
            self.set.clear();
            self.clear_all();
            return;
        }
        for c in self.set.drain(..) {
            self.bits.row_words_mut(c.y)[(c.x / 64) as usize] &= !(1u64 << (c.x % 64));
        }
    }

    /// Add `c`, a cell on the grid not yet in the set.
    #[inline]
    pub(crate) fn insert(&mut self, c: Cell) {
        self.bits.row_words_mut(c.y)[(c.x / 64) as usize] |= 1u64 << (c.x % 64);
        self.set.push(c);
    }

    /// The legal steps from free cell `c` of `grid` (bits as in
    /// [`legal_steps`](crate::movement::legal_steps)) into cells not in the set.
    #[inline]
    pub(crate) fn legal_open_steps(&self, grid: &BitGrid, c: Cell) -> u8 {
        legal_steps_avoiding(grid, &self.bits, c)
    }
}
