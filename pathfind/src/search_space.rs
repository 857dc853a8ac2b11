//! Per-cell search state reused across queries: costs, parents and arrival directions in flat
//! arrays, reset in O(1) by a generation counter, and a binary-heap open list with lazy deletion.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use slam_core::{Cell, GridPath};

/// No arrival direction (the start).
pub(crate) const NO_DIRECTION: u8 = 8;

/// An open-list entry. Ordered so that the max-heap pops the smallest `f`, and among equal `f`
/// the largest `g` (deeper nodes first: fewer expansions on ties).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Open {
    f: f64,
    g: f64,
    index: u32,
}

impl PartialEq for Open {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Open {}
impl PartialOrd for Open {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Open {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .f
            .total_cmp(&self.f)
            .then_with(|| self.g.total_cmp(&other.g))
    }
}

/// Search state for one grid size.
pub(crate) struct SearchSpace {
    width: u32,
    g: Vec<f64>,
    parent: Vec<u32>,
    direction: Vec<u8>,
    /// Generation in which `g`, `parent` and `direction` were last written.
    seen: Vec<u32>,
    /// Generation in which the cell was expanded.
    closed: Vec<u32>,
    generation: u32,
    heap: BinaryHeap<Open>,
}

impl SearchSpace {
    pub(crate) fn new(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        Self {
            width,
            g: vec![0.0; n],
            parent: vec![0; n],
            direction: vec![NO_DIRECTION; n],
            seen: vec![0; n],
            closed: vec![0; n],
            generation: 0,
            heap: BinaryHeap::new(),
        }
    }

    #[inline]
    pub(crate) fn index(&self, c: Cell) -> u32 {
        c.y * self.width + c.x
    }

    #[inline]
    pub(crate) fn cell(&self, i: u32) -> Cell {
        Cell::new(i % self.width, i / self.width)
    }

    /// Start a new query.
    pub(crate) fn reset(&mut self) {
        self.heap.clear();
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            // Wrapped after 4 billion queries: clear the stamps once.
            self.seen.fill(0);
            self.closed.fill(0);
            self.generation = 1;
        }
    }

    /// Offer `g` as the cost of reaching cell `i` from `parent`, arriving in `direction`; queue it
    /// with priority `g + h` when it improves.
    #[inline]
    pub(crate) fn relax(&mut self, i: u32, g: f64, h: f64, parent: u32, direction: u8) {
        let k = i as usize;
        if self.seen[k] == self.generation && self.g[k] <= g {
            return;
        }
        if self.closed[k] == self.generation {
            return;
        }
        self.seen[k] = self.generation;
        self.g[k] = g;
        self.parent[k] = parent;
        self.direction[k] = direction;
        self.heap.push(Open {
            f: g + h,
            g,
            index: i,
        });
    }

    /// Pop the best open cell that is not yet expanded, and mark it expanded.
    #[inline]
    pub(crate) fn pop(&mut self) -> Option<(u32, f64, u8)> {
        while let Some(o) = self.heap.pop() {
            let k = o.index as usize;
            if self.closed[k] == self.generation || o.g > self.g[k] {
                continue;
            }
            self.closed[k] = self.generation;
            return Some((o.index, o.g, self.direction[k]));
        }
        None
    }

    /// The path to `goal` by following parents back to `start`.
    pub(crate) fn path(&self, start: u32, goal: u32, expanded: usize) -> GridPath {
        let mut cells = vec![self.cell(goal)];
        let mut i = goal;
        while i != start {
            i = self.parent[i as usize];
            cells.push(self.cell(i));
        }
        cells.reverse();
        GridPath {
            length: self.g[goal as usize],
            cells,
            expanded,
        }
    }
}
