//! Per-cell search state reused across queries: one packed record per cell (cost, parent,
//! arrival direction, generation stamps), reset in O(1) by a generation counter, and an open list
//! of fixed-point priorities ([`crate::cost`]) with lazy deletion (a binary heap, or a ring of
//! buckets for the cell-by-cell searches; see [`crate::open_list`]), plus a stack for cells whose
//! `f` equals the `f` being expanded.
//!
//! The stack is sound because the heuristics used here are consistent: `f` never decreases along
//! an expansion order, so any open cell with the current minimum `f` may be expanded next, and a
//! successor with that same `f` has the larger `g` (the preferred tie-break). Such successors (a
//! walk straight at the goal) skip the open list entirely.

use slam_core::{Cell, GridPath};

use crate::cost::{Cost, whole_cells};
use crate::movement::path_cost;
use crate::open_list::{KeyHeap, Open, OpenList};

/// No arrival direction (the start).
pub(crate) const NO_DIRECTION: u8 = 8;

/// One cell's search record, 16 bytes so that four share a cache line.
#[derive(Clone, Copy, Debug)]
struct NodeState {
    g: Cost,
    parent: u32,
    /// `generation << STAMP_SHIFT | closed << 4 | direction`: `g`, `parent` and `direction` are
    /// valid when the generation is the current one; `closed` says the cell was expanded then.
    stamp: u32,
}

const STAMP_SHIFT: u32 = 5;
const CLOSED_BIT: u32 = 1 << 4;
const DIRECTION_MASK: u32 = 0xF;
/// Generations run from 1 to this value, then the stamps are cleared once.
const MAX_GENERATION: u32 = u32::MAX >> STAMP_SHIFT;

/// Move `generation`, the stamp that marks a search record as written by the current query, on
/// to a new query. Generations run from 1 to `max`; past it every record's stamp is cleared once
/// by `clear_stamp` (so that no old stamp can match) and the count starts again.
pub(crate) fn next_generation<N>(
    generation: &mut u32,
    max: u32,
    nodes: &mut [N],
    clear_stamp: impl Fn(&mut N),
) {
    if *generation >= max {
        nodes.iter_mut().for_each(clear_stamp);
        *generation = 0;
    }
    *generation += 1;
}

/// Search state for one grid size, with open list `Q`.
pub(crate) struct SearchSpace<Q = KeyHeap> {
    width: u32,
    nodes: Vec<NodeState>,
    generation: u32,
    open: Q,
    /// Cells queued with `f` equal to `current_f`; expanded before anything on the open list.
    same_f: Vec<u32>,
    /// `f` of the last cell taken off the open list.
    current_f: Cost,
}

impl<Q: OpenList> SearchSpace<Q> {
    pub(crate) fn new(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        let empty = NodeState {
            g: 0,
            parent: 0,
            stamp: 0,
        };
        Self {
            width,
            nodes: vec![empty; n],
            generation: 0,
            open: Q::default(),
            same_f: Vec::new(),
            current_f: 0,
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

    /// Start a new query at cell `start`, whose heuristic is `h`: its `f`, the smallest of the
    /// search, is the first on the open list.
    pub(crate) fn start(&mut self, start: u32, h: Cost) {
        self.reset();
        self.nodes[start as usize] = NodeState {
            g: 0,
            parent: start,
            stamp: self.generation << STAMP_SHIFT | u32::from(NO_DIRECTION),
        };
        self.open.push(Open {
            f: h,
            tie: u32::MAX,
            index: start,
        });
    }

    /// Forget the last query.
    fn reset(&mut self) {
        self.open.clear();
        self.same_f.clear();
        self.current_f = 0;
        // After 134 million queries the stamps are cleared once.
        next_generation(&mut self.generation, MAX_GENERATION, &mut self.nodes, |n| {
            n.stamp = 0;
        });
    }

    /// Offer `g` as the cost of reaching cell `i` from `parent`, arriving in `direction`; queue it
    /// with priority `g + h()` when it improves (the heuristic is evaluated only then).
    // Hot path: LLVM outlines it with plain `#[inline]` (measured; a call per neighbour).
    #[allow(clippy::inline_always)]
    #[inline(always)]
    pub(crate) fn relax(
        &mut self,
        i: u32,
        g: Cost,
        h: impl FnOnce() -> Cost,
        parent: u32,
        direction: u8,
    ) {
        let generation = self.generation;
        let n = &mut self.nodes[i as usize];
        if n.stamp >> STAMP_SHIFT == generation && (n.g <= g || n.stamp & CLOSED_BIT != 0) {
            return;
        }
        *n = NodeState {
            g,
            parent,
            stamp: generation << STAMP_SHIFT | u32::from(direction),
        };
        let f = g + h();
        // `f` never decreases along the expansions (consistent heuristic, exact integer costs),
        // so `f <= current_f` means equal.
        if f <= self.current_f {
            self.same_f.push(i);
        } else {
            self.open.push(Open {
                f,
                // Among equal `f`, the larger `g` first.
                tie: u32::MAX - whole_cells(g),
                index: i,
            });
        }
    }

    /// Mark cell `i` expanded unless it already was in this query; returns its cost and arrival
    /// direction.
    // Hot path: LLVM outlines it with plain `#[inline]` (measured; a call per neighbour).
    #[allow(clippy::inline_always)]
    #[inline(always)]
    fn close(&mut self, i: u32) -> Option<(Cost, u8)> {
        let n = &mut self.nodes[i as usize];
        if n.stamp & CLOSED_BIT != 0 {
            return None;
        }
        n.stamp |= CLOSED_BIT;
        Some((n.g, (n.stamp & DIRECTION_MASK) as u8))
    }

    /// Pop the best open cell that is not yet expanded, and mark it expanded.
    // Hot path: LLVM outlines it with plain `#[inline]` (measured; a call per neighbour).
    #[allow(clippy::inline_always)]
    #[inline(always)]
    pub(crate) fn pop(&mut self) -> Option<(u32, Cost, u8)> {
        // Every queued cell was stamped in this generation, so only the closed bit needs a look.
        while let Some(i) = self.same_f.pop() {
            if let Some((g, d)) = self.close(i) {
                return Some((i, g, d));
            }
        }
        while let Some(o) = self.open.pop() {
            if let Some((g, d)) = self.close(o.index) {
                self.current_f = o.f;
                return Some((o.index, g, d));
            }
        }
        None
    }

    /// The path to `goal` by following parents back to `start`.
    pub(crate) fn path(&self, start: u32, goal: u32, expanded: usize) -> GridPath {
        let mut cells = vec![self.cell(goal)];
        let mut i = goal;
        while i != start {
            i = self.nodes[i as usize].parent;
            cells.push(self.cell(i));
        }
        cells.reverse();
        GridPath {
            // Summed in floating point step by step (the costs above are fixed point).
            length: path_cost(&cells),
            cells,
            expanded,
        }
    }
}
