//! The sparse normal equations `H dx = -b` of a pose graph: a CSC pattern (upper triangle, every
//! diagonal entry present for damping) built once per graph structure, with faer's symbolic
//! Cholesky computed once and reused for every numeric factorisation.

use faer::MatMut;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use nalgebra::{SMatrix, SVector};
use slam_core::{GraphPose, OptimizeError, PoseGraph};

use crate::linearize::{ErrorModel, Linearize};
use crate::sparse_cholesky::SparseCholesky;

/// Whether `graph` starts with nodes of these `fixed` flags and edges with these `ends` (node
/// indices): the same structure, possibly grown.
pub(crate) fn grows_from<P: GraphPose>(
    fixed: &[bool],
    ends: &[(usize, usize)],
    graph: &PoseGraph<P>,
) -> bool {
    graph.node_count() >= fixed.len()
        && graph.edge_count() >= ends.len()
        && fixed.iter().zip(graph.nodes()).all(|(&f, n)| f == n.fixed)
        && ends
            .iter()
            .zip(graph.edges())
            .all(|(&(a, b), e)| a == e.from && b == e.to)
}

/// Where each edge's blocks go in the value array.
#[derive(Clone, Copy, Debug)]
struct EdgeSlots {
    /// Variable of the edge's `from` node (`None` when fixed).
    a: Option<usize>,
    /// Variable of the edge's `to` node.
    b: Option<usize>,
    /// Rank of the lower variable among the higher one's column neighbours (both free).
    rank_lo: usize,
}

/// The pattern and symbolic factorisation for one graph structure.
pub(crate) struct NormalEquations<const D: usize> {
    /// The structure the pattern was built for: each node's fixed flag and each edge's endpoint
    /// indices. Compared whole, so a second graph of the same size with other edges gets its own
    /// pattern instead of filling this one's slots.
    fixed: Vec<bool>,
    ends: Vec<(usize, usize)>,
    /// Variable of each node (`None` for fixed nodes).
    var_of_node: Vec<Option<usize>>,
    n_vars: usize,
    col_ptr: Vec<usize>,
    /// Neighbour count (including itself) of each variable's column block.
    neighbours: Vec<usize>,
    edges: Vec<EdgeSlots>,
    symbolic_pattern: SymbolicSparseColMat<usize>,
    cholesky: SparseCholesky,
    /// Numeric values (upper triangle, CSC order).
    pub(crate) values: Vec<f64>,
    /// Right-hand side `b = J^T W e`.
    pub(crate) gradient: Vec<f64>,
}

impl<const D: usize> NormalEquations<D> {
    /// Whether this pattern still fits `graph`.
    pub(crate) fn fits<P: GraphPose>(&self, graph: &PoseGraph<P>) -> bool {
        self.fixed.len() == graph.node_count()
            && self.ends.len() == graph.edge_count()
            && grows_from(&self.fixed, &self.ends, graph)
    }

    /// Build the pattern and the symbolic factorisation for `graph`, with `D` unknowns per free
    /// node (the pose's degrees of freedom for the optimisers, fewer for the chordal relaxation).
    pub(crate) fn new<P: GraphPose>(graph: &PoseGraph<P>) -> Result<Self, OptimizeError> {
        let mut var_of_node = Vec::with_capacity(graph.node_count());
        let mut n_vars = 0;
        for n in graph.nodes() {
            if n.fixed {
                var_of_node.push(None);
            } else {
                var_of_node.push(Some(n_vars));
                n_vars += 1;
            }
        }
        // Upper-triangle neighbours of each variable: lower-numbered variables sharing an edge.
        let mut lower: Vec<Vec<usize>> = vec![Vec::new(); n_vars];
        for e in graph.edges() {
            if let (Some(a), Some(b)) = (var_of_node[e.from], var_of_node[e.to]) {
                let (lo, hi) = if a < b { (a, b) } else { (b, a) };
                lower[hi].push(lo);
            }
        }
        for l in &mut lower {
            l.sort_unstable();
            l.dedup();
        }
        let n = n_vars * D;
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        let mut neighbours = Vec::with_capacity(n_vars);
        col_ptr.push(0);
        for (j, l) in lower.iter().enumerate() {
            neighbours.push(l.len() + 1);
            for c in 0..D {
                for &i in l {
                    row_idx.extend((0..D).map(|r| i * D + r));
                }
                row_idx.extend((0..=c).map(|r| j * D + r));
                col_ptr.push(row_idx.len());
            }
        }
        let edges = graph
            .edges()
            .iter()
            .map(|e| {
                let (a, b) = (var_of_node[e.from], var_of_node[e.to]);
                let rank_lo = match (a, b) {
                    (Some(a), Some(b)) => {
                        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
                        lower[hi].binary_search(&lo).unwrap_or(0)
                    }
                    _ => 0,
                };
                EdgeSlots { a, b, rank_lo }
            })
            .collect();
        let nnz = row_idx.len();
        let symbolic_pattern =
            SymbolicSparseColMat::new_checked(n, n, col_ptr.clone(), None, row_idx);
        // The variables' graph (upper triangle) for the fill-reducing ordering.
        let mut block_ptr = Vec::with_capacity(n_vars + 1);
        let mut block_idx = Vec::new();
        block_ptr.push(0);
        for (j, l) in lower.iter().enumerate() {
            block_idx.extend_from_slice(l);
            block_idx.push(j);
            block_ptr.push(block_idx.len());
        }
        let blocks = SymbolicSparseColMat::new_checked(n_vars, n_vars, block_ptr, None, block_idx);
        // Up to D right-hand sides (the chordal relaxation solves for D columns at once).
        let cholesky = SparseCholesky::try_new::<D>(symbolic_pattern.as_ref(), blocks.as_ref(), D)?;
        Ok(Self {
            fixed: graph.nodes().iter().map(|n| n.fixed).collect(),
            ends: graph.edges().iter().map(|e| (e.from, e.to)).collect(),
            var_of_node,
            n_vars,
            col_ptr,
            neighbours,
            edges,
            symbolic_pattern,
            cholesky,
            values: vec![0.0; nnz],
            gradient: vec![0.0; n],
        })
    }

    /// Number of scalar unknowns.
    pub(crate) fn dimension(&self) -> usize {
        self.n_vars * D
    }

    /// The variable of node `i`.
    pub(crate) fn variable(&self, node: usize) -> Option<usize> {
        self.var_of_node[node]
    }

    /// Factorise the matrix with `values` on this pattern (`values` itself, or a damped copy);
    /// `false` on a non-positive pivot.
    pub(crate) fn factorize(&mut self, values: &[f64]) -> bool {
        let matrix = SparseColMatRef::new(self.symbolic_pattern.as_ref(), values);
        self.cholesky.factorize(matrix)
    }

    /// Solve with the last successful factorisation, in place (up to `D` columns).
    pub(crate) fn solve_in_place(&mut self, rhs: MatMut<'_, f64>) {
        self.cholesky.solve_in_place(rhs);
    }

    /// Position of entry (row `i*D + r`, column `j*D + c`) for `i <= j`, `rank` = rank of `i` in
    /// column block `j` (the diagonal block is last).
    #[inline]
    fn pos(&self, rank: usize, r: usize, j: usize, c: usize) -> usize {
        self.col_ptr[j * D + c] + rank * D + r
    }

    /// Position of the diagonal entry of unknown `k`.
    #[inline]
    pub(crate) fn diagonal_position(&self, k: usize) -> usize {
        let (j, c) = (k / D, k % D);
        self.pos(self.neighbours[j] - 1, c, j, c)
    }

    /// The variables of edge `k`'s two nodes (`None` for a fixed node).
    #[inline]
    pub(crate) fn edge_variables(&self, k: usize) -> (Option<usize>, Option<usize>) {
        let s = &self.edges[k];
        (s.a, s.b)
    }

    /// Set `values` and `gradient` to zero.
    pub(crate) fn clear(&mut self) {
        self.values.iter_mut().for_each(|v| *v = 0.0);
        self.gradient.iter_mut().for_each(|v| *v = 0.0);
    }

    /// Add edge `k`'s blocks `J^T Omega J` (Jacobians `ja`, `jb` of its two nodes) to `values`;
    /// a fixed node's blocks are skipped.
    #[inline]
    pub(crate) fn add_hessian(
        &mut self,
        k: usize,
        ja: &SMatrix<f64, D, D>,
        jb: &SMatrix<f64, D, D>,
        omega: &SMatrix<f64, D, D>,
    ) {
        let slots = self.edges[k];
        for (v, j) in [(slots.a, ja), (slots.b, jb)] {
            if let Some(v) = v {
                let h: SMatrix<f64, D, D> = j.transpose() * omega * j;
                let diag_rank = self.neighbours[v] - 1;
                for c in 0..D {
                    for r in 0..=c {
                        let p = self.pos(diag_rank, r, v, c);
                        self.values[p] += h[(r, c)];
                    }
                }
            }
        }
        if let (Some(va), Some(vb)) = (slots.a, slots.b) {
            let (jlo, hi, jhi) = if va < vb { (ja, vb, jb) } else { (jb, va, ja) };
            let h: SMatrix<f64, D, D> = jlo.transpose() * omega * jhi;
            for c in 0..D {
                for r in 0..D {
                    let p = self.pos(slots.rank_lo, r, hi, c);
                    self.values[p] += h[(r, c)];
                }
            }
        }
    }

    /// Add a between-edge `k` whose Jacobians are `-jb` (for `a`) and `jb` (for `b`), with
    /// (weighted) information `omega` and `oe = omega e`: the three Hessian blocks are `h`, `h`
    /// and `-h` for `h = jb^T omega jb`, one product instead of three.
    #[inline]
    fn add_between(
        &mut self,
        k: usize,
        jb: &SMatrix<f64, D, D>,
        omega: &SMatrix<f64, D, D>,
        oe: &SVector<f64, D>,
    ) {
        let slots = self.edges[k];
        let jt = jb.transpose();
        let g: SVector<f64, D> = jt * oe;
        let h: SMatrix<f64, D, D> = jt * (omega * jb);
        for (v, sign) in [(slots.a, -1.0), (slots.b, 1.0)] {
            if let Some(v) = v {
                for r in 0..D {
                    self.gradient[v * D + r] += sign * g[r];
                }
                let diag_rank = self.neighbours[v] - 1;
                for c in 0..D {
                    let start = self.pos(diag_rank, 0, v, c);
                    for r in 0..=c {
                        self.values[start + r] += h[(r, c)];
                    }
                }
            }
        }
        if let (Some(va), Some(vb)) = (slots.a, slots.b) {
            let hi = va.max(vb);
            for c in 0..D {
                let start = self.pos(slots.rank_lo, 0, hi, c);
                for r in 0..D {
                    self.values[start + r] -= h[(r, c)];
                }
            }
        }
    }

    /// Fill `values` and `gradient` at the current poses for `model`: robust kernels as IRLS
    /// weights, or, with `weights` (one per edge), those weights instead of the kernels.
    pub(crate) fn assemble<P: Linearize<D>>(
        &mut self,
        graph: &PoseGraph<P>,
        model: ErrorModel,
        weights: Option<&[f64]>,
    ) {
        self.clear();
        let nodes = graph.nodes();
        for (k, e) in graph.edges().iter().enumerate() {
            let (err, jb) = P::linearize(
                model,
                &e.measurement,
                &nodes[e.from].pose,
                &nodes[e.to].pose,
            );
            let mut omega = P::info(&e.information);
            let mut oe: SVector<f64, D> = omega * err;
            if let Some(w) = weights {
                let w = w[k];
                if w == 0.0 {
                    // An edge weighted out adds nothing (its entries stay in the pattern).
                    continue;
                }
                omega *= w;
                oe *= w;
            } else if let Some(kernel) = e.kernel {
                let w = kernel.weight(err.dot(&oe));
                omega *= w;
                oe *= w;
            }
            self.add_between(k, &jb, &omega, &oe);
        }
    }
}
