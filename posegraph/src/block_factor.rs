//! A sparse Cholesky factor `H = L L^T` in `D x D` blocks (one block row and column per free
//! node) that can re-eliminate part of itself: the variables whose rows of `H` changed, with all
//! their ancestors in the elimination tree, are re-ordered and re-factored while every other
//! column is kept. This is iSAM2's partial re-elimination (Kaess et al., IJRR 2012, Alg. 5) in
//! column form: a column of `L` depends only on the columns eliminated before it in its own
//! subtree, so the unaffected subtrees ("orphans") stay valid when the affected top of the tree
//! is eliminated again, after them, in a new order.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::SymbolicSparseColMat;
use faer::sparse::linalg::amd;
use nalgebra::{SMatrix, SVector};

/// A `D x D` block.
type Block<const D: usize> = SMatrix<f64, D, D>;

/// No parent, no position.
const NONE: usize = usize::MAX;

/// The linear system `H dx = -g` in blocks, indexed by node.
pub(crate) struct BlockSystem<const D: usize> {
    /// `H_vv`.
    pub(crate) diagonal: Vec<Block<D>>,
    /// For column `v`: `(w, H_wv)` for each free neighbour `w`.
    pub(crate) off: Vec<Vec<(usize, Block<D>)>>,
    /// `g_v`.
    pub(crate) gradient: Vec<SVector<f64, D>>,
}

impl<const D: usize> BlockSystem<D> {
    /// An empty system.
    pub(crate) fn new() -> Self {
        Self {
            diagonal: Vec::new(),
            off: Vec::new(),
            gradient: Vec::new(),
        }
    }

    /// Room for `n` nodes.
    pub(crate) fn grow(&mut self, n: usize) {
        self.diagonal.resize(n, Block::<D>::zeros());
        self.off.resize_with(n, Vec::new);
        self.gradient.resize(n, SVector::zeros());
    }
}

/// A variable whose pivot block was not positive definite.
#[derive(Clone, Copy, Debug)]
pub(crate) struct NotPositiveDefinite;

/// The factor, indexed by node (fixed nodes have no column).
pub(crate) struct BlockFactor<const D: usize> {
    /// Elimination position of each node (`NONE` when not eliminated yet). Positions only grow:
    /// re-eliminated variables get new ones after every other.
    pos: Vec<usize>,
    next_pos: usize,
    /// Eliminated variables in order.
    order: Vec<usize>,
    parent: Vec<usize>,
    children: Vec<Vec<usize>>,
    /// Rows below the diagonal of each column (ancestors of the column, in no set order) ...
    pattern: Vec<Vec<usize>>,
    /// ... and their blocks `L[r, j]`.
    below: Vec<Vec<Block<D>>>,
    /// `L_jj^-1`.
    diagonal_inverse: Vec<Block<D>>,
    /// The columns whose pattern holds this row.
    rows: Vec<Vec<usize>>,
    /// The forward solve's `y` (`L y = -g`).
    y: Vec<SVector<f64, D>>,
    /// The columns re-eliminated since the last solve.
    fresh: Vec<bool>,
    /// Scratch: membership of the affected set (in a solve: the steps that moved), slots of a column's rows, a marker.
    affected: Vec<bool>,
    slot: Vec<usize>,
    stamp: Vec<usize>,
    clock: usize,
}

impl<const D: usize> BlockFactor<D> {
    /// An empty factor.
    pub(crate) fn new() -> Self {
        Self {
            pos: Vec::new(),
            next_pos: 0,
            order: Vec::new(),
            parent: Vec::new(),
            children: Vec::new(),
            pattern: Vec::new(),
            below: Vec::new(),
            diagonal_inverse: Vec::new(),
            rows: Vec::new(),
            y: Vec::new(),
            fresh: Vec::new(),
            affected: Vec::new(),
            slot: Vec::new(),
            stamp: Vec::new(),
            clock: 0,
        }
    }

    /// Room for `n` nodes.
    pub(crate) fn grow(&mut self, n: usize) {
        self.pos.resize(n, NONE);
        self.parent.resize(n, NONE);
        self.children.resize_with(n, Vec::new);
        self.pattern.resize_with(n, Vec::new);
        self.below.resize_with(n, Vec::new);
        self.diagonal_inverse.resize(n, Block::<D>::zeros());
        self.rows.resize_with(n, Vec::new);
        self.y.resize(n, SVector::zeros());
        self.fresh.resize(n, false);
        self.affected.resize(n, false);
        self.slot.resize(n, 0);
        self.stamp.resize(n, 0);
    }

    /// Re-eliminate the variables `touched` (whose blocks of `system` changed, or new ones) and
    /// all their ancestors; `last` (a few of them, usually the newest) go last in the new order,
    /// the rest in approximate minimum degree order. Returns how many variables were
    /// re-eliminated.
    pub(crate) fn refactor(
        &mut self,
        system: &BlockSystem<D>,
        touched: &[usize],
        last: &[usize],
    ) -> Result<usize, NotPositiveDefinite> {
        // The affected set: the touched variables and their ancestors.
        let mut set = Vec::new();
        for &t in touched {
            let mut v = t;
            while v != NONE && !self.affected[v] {
                self.affected[v] = true;
                set.push(v);
                v = self.parent[v];
            }
        }
        let orphans: Vec<usize> = set
            .iter()
            .flat_map(|&a| self.children[a].iter().copied())
            .filter(|&c| !self.affected[c])
            .collect();
        let new_order = self.ordering(system, &set, &orphans, last);
        for &a in &new_order {
            self.fresh[a] = true;
            self.pos[a] = self.next_pos;
            self.next_pos += 1;
        }
        let affected = &self.affected;
        self.order.retain(|&v| !affected[v]);
        self.order.extend_from_slice(&new_order);
        for &a in &set {
            self.children[a].clear();
            let affected = &self.affected;
            self.rows[a].retain(|&k| !affected[k]);
        }
        for &o in &orphans {
            let p = self.first_in_order(&self.pattern[o]);
            self.parent[o] = p;
            self.children[p].push(o);
        }
        let result = self.eliminate(system, &new_order);
        for &a in &set {
            self.affected[a] = false;
        }
        result.map(|()| set.len())
    }

    /// The variable of `list` eliminated first (`NONE` for an empty list).
    fn first_in_order(&self, list: &[usize]) -> usize {
        list.iter()
            .copied()
            .min_by_key(|&r| self.pos[r])
            .unwrap_or(NONE)
    }

    /// The new order of the affected `set`: approximate minimum degree on its graph (the edges
    /// of `system` among it, and a clique over each orphan's rows, which its elimination
    /// joined), then `last`.
    fn ordering(
        &mut self,
        system: &BlockSystem<D>,
        set: &[usize],
        orphans: &[usize],
        last: &[usize],
    ) -> Vec<usize> {
        self.clock += 1;
        let tail_mark = self.clock;
        let mut tail = Vec::with_capacity(last.len());
        for &v in last {
            if self.affected[v] && self.stamp[v] != tail_mark {
                self.stamp[v] = tail_mark;
                tail.push(v);
            }
        }
        let head: Vec<usize> = set
            .iter()
            .copied()
            .filter(|&v| self.stamp[v] != tail_mark)
            .collect();
        let mut out = self.minimum_degree(system, &head, orphans, tail_mark);
        out.extend_from_slice(&tail);
        out
    }

    /// `head` in approximate minimum degree order (nodes stamped `skip` left out of the graph);
    /// `head` as it is when the ordering cannot be made.
    fn minimum_degree(
        &mut self,
        system: &BlockSystem<D>,
        head: &[usize],
        orphans: &[usize],
        skip: usize,
    ) -> Vec<usize> {
        let m = head.len();
        if m <= 2 {
            return head.to_vec();
        }
        for (i, &v) in head.iter().enumerate() {
            self.slot[v] = i;
        }
        let inside = |v: usize, this: &Self| this.affected[v] && this.stamp[v] != skip;
        let mut upper: Vec<Vec<usize>> = vec![Vec::new(); m];
        let link = |a: usize, b: usize, upper: &mut Vec<Vec<usize>>| {
            let (lo, hi) = if a < b { (a, b) } else { (b, a) };
            if lo != hi {
                upper[hi].push(lo);
            }
        };
        for (i, &v) in head.iter().enumerate() {
            for &(w, _) in &system.off[v] {
                if inside(w, self) {
                    link(i, self.slot[w], &mut upper);
                }
            }
        }
        for &o in orphans {
            let members: Vec<usize> = self.pattern[o]
                .iter()
                .copied()
                .filter(|&r| inside(r, self))
                .map(|r| self.slot[r])
                .collect();
            for (x, &a) in members.iter().enumerate() {
                for &b in &members[x + 1..] {
                    link(a, b, &mut upper);
                }
            }
        }
        let mut col_ptr = Vec::with_capacity(m + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for (j, l) in upper.iter_mut().enumerate() {
            l.sort_unstable();
            l.dedup();
            row_idx.extend_from_slice(l);
            row_idx.push(j);
            col_ptr.push(row_idx.len());
        }
        let nnz = row_idx.len();
        let graph = SymbolicSparseColMat::new_checked(m, m, col_ptr, None, row_idx);
        let (mut fwd, mut inv) = (vec![0usize; m], vec![0usize; m]);
        let Ok(mut mem) = MemBuffer::try_new(amd::order_scratch::<usize>(m, nnz)) else {
            return head.to_vec();
        };
        match amd::order(
            &mut fwd,
            &mut inv,
            graph.as_ref(),
            amd::Control::default(),
            MemStack::new(&mut mem),
        ) {
            Ok(_) => fwd.iter().map(|&i| head[i]).collect(),
            Err(_) => head.to_vec(),
        }
    }

    /// The symbolic and numeric elimination of `new_order` (positions already given), with the
    /// forward solve.
    fn eliminate(
        &mut self,
        system: &BlockSystem<D>,
        new_order: &[usize],
    ) -> Result<(), NotPositiveDefinite> {
        let mut work: Vec<Block<D>> = Vec::new();
        for &a in new_order {
            // Symbolic: the later neighbours in H and the children's rows after `a`.
            self.clock += 1;
            let mark = self.clock;
            let pa = self.pos[a];
            let mut pattern = std::mem::take(&mut self.pattern[a]);
            pattern.clear();
            self.stamp[a] = mark;
            for &(w, _) in &system.off[a] {
                if self.pos[w] != NONE && self.pos[w] > pa && self.stamp[w] != mark {
                    self.stamp[w] = mark;
                    pattern.push(w);
                }
            }
            for &c in &self.children[a] {
                for &r in &self.pattern[c] {
                    if self.pos[r] > pa && self.stamp[r] != mark {
                        self.stamp[r] = mark;
                        pattern.push(r);
                    }
                }
            }
            let p = self.first_in_order(&pattern);
            self.parent[a] = p;
            if p != NONE {
                self.children[p].push(a);
            }
            for &r in &pattern {
                self.rows[r].push(a);
            }
            // Numeric (left-looking): H's column, less the earlier columns with a row at `a`.
            work.clear();
            work.resize(pattern.len() + 1, Block::<D>::zeros());
            self.slot[a] = 0;
            for (i, &r) in pattern.iter().enumerate() {
                self.slot[r] = i + 1;
            }
            work[0] = system.diagonal[a];
            for &(w, h) in &system.off[a] {
                if self.stamp[w] == mark && w != a {
                    work[self.slot[w]] += h;
                }
            }
            let mut rhs = -system.gradient[a];
            for &k in &self.rows[a] {
                let (pk, bk) = (&self.pattern[k], &self.below[k]);
                let Some(at) = pk.iter().position(|&r| r == a) else {
                    continue;
                };
                let lak = bk[at];
                rhs -= lak * self.y[k];
                let lak_t = lak.transpose();
                for (&r, l) in pk.iter().zip(bk) {
                    if self.pos[r] >= pa {
                        work[self.slot[r]] -= l * lak_t;
                    }
                }
            }
            let pivot = (work[0] + work[0].transpose()) * 0.5;
            let chol = pivot.cholesky().ok_or(NotPositiveDefinite)?;
            let inverse = chol
                .l()
                .solve_lower_triangular(&Block::<D>::identity())
                .ok_or(NotPositiveDefinite)?;
            let inverse_t = inverse.transpose();
            self.diagonal_inverse[a] = inverse;
            self.y[a] = inverse * rhs;
            let mut below = std::mem::take(&mut self.below[a]);
            below.clear();
            below.extend(work[1..].iter().map(|w| w * inverse_t));
            self.below[a] = below;
            self.pattern[a] = pattern;
        }
        Ok(())
    }

    /// Back substitution `L^T dx = y` from the root down, "wildfire" style (iSAM2's partial
    /// state update, Alg. 7): a column is solved again when it was re-eliminated or one of its
    /// rows' steps moved by more than `threshold` (0: any change; `None`: every column is solved);
    /// the others keep their step.
    /// `dx` is indexed by node; the nodes solved again are appended to `solved`.
    pub(crate) fn solve(
        &mut self,
        dx: &mut [SVector<f64, D>],
        threshold: Option<f64>,
        solved: &mut Vec<usize>,
    ) {
        let start = solved.len();
        for &j in self.order.iter().rev() {
            let moved = &self.affected;
            if threshold.is_some() && !self.fresh[j] && !self.pattern[j].iter().any(|&r| moved[r]) {
                continue;
            }
            let mut v = self.y[j];
            for (&r, l) in self.pattern[j].iter().zip(&self.below[j]) {
                v -= l.transpose() * dx[r];
            }
            let new = self.diagonal_inverse[j].transpose() * v;
            // `affected` is free outside `refactor`: it marks the steps that moved.
            if (new - dx[j]).amax() > threshold.unwrap_or(0.0) || !new.iter().all(|x| x.is_finite())
            {
                self.affected[j] = true;
            }
            dx[j] = new;
            solved.push(j);
        }
        for &j in &solved[start..] {
            self.affected[j] = false;
            self.fresh[j] = false;
        }
    }
}
