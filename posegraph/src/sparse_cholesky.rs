//! faer's sparse Cholesky with everything that does not depend on the values kept between
//! factorisations: the fill-reducing ordering (approximate minimum degree on the graph of
//! variables, expanded to their `D` scalar unknowns), the symbolic factorisation (supernodal),
//! the factor's value array and the scratch memory. A numeric factorisation then allocates
//! nothing.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::linalg::{SupernodalThreshold, amd};
use faer::sparse::{FaerError, SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side, Spec};
use slam_core::{FactorizationFailure, OptimizeError};

/// A reusable sparse `L L^T` of matrices with one upper-triangular pattern.
pub(crate) struct SparseCholesky {
    symbolic: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    scratch: MemBuffer,
}

/// faer's error in `stage` as ours (its variants carry nothing more than their name).
fn sparse_error(stage: &'static str, e: FaerError) -> OptimizeError {
    let cause = match e {
        FaerError::OutOfMemory => FactorizationFailure::OutOfMemory,
        FaerError::IndexOverflow => FactorizationFailure::IndexOverflow,
        _ => FactorizationFailure::Unrecognised,
    };
    OptimizeError::Factorization { stage, cause }
}

/// A failed scratch allocation in `stage`.
fn allocation_error(stage: &'static str) -> OptimizeError {
    OptimizeError::Factorization {
        stage,
        cause: FactorizationFailure::OutOfMemory,
    }
}

impl SparseCholesky {
    /// The symbolic factorisation of `pattern` (upper triangle, `D` unknowns per variable),
    /// ordered by AMD on `blocks` (the upper pattern of the variables' graph, `n / D` square),
    /// with scratch for solves of up to `max_rhs` columns.
    pub(crate) fn try_new<const D: usize>(
        pattern: SymbolicSparseColMatRef<'_, usize>,
        blocks: SymbolicSparseColMatRef<'_, usize>,
        max_rhs: usize,
    ) -> Result<Self, OptimizeError> {
        let nb = blocks.nrows();
        let (mut fwd_b, mut inv_b) = (vec![0usize; nb], vec![0usize; nb]);
        let mut amd_mem = MemBuffer::try_new(amd::order_scratch::<usize>(nb, blocks.compute_nnz()))
            .map_err(|_| allocation_error("ordering scratch"))?;
        amd::order(
            &mut fwd_b,
            &mut inv_b,
            blocks,
            amd::Control::default(),
            MemStack::new(&mut amd_mem),
        )
        .map_err(|e| sparse_error("ordering", e))?;
        let n = nb * D;
        let mut fwd = vec![0usize; n];
        for (new, &old) in fwd_b.iter().enumerate() {
            for r in 0..D {
                fwd[new * D + r] = old * D + r;
            }
        }
        let mut inv = vec![0usize; n];
        for (new, &old) in fwd.iter().enumerate() {
            inv[old] = new;
        }
        let perm = faer::perm::PermRef::new_checked(&fwd, &inv, n);
        let symbolic = factorize_symbolic_cholesky(
            pattern,
            Side::Upper,
            SymmetricOrdering::Custom(perm),
            // Supernodal always: each variable's D columns share one pattern, so supernodes are
            // at least D wide. faer's automatic choice picked the simplicial code for
            // parking-garage, which was then 2x slower (it recomputes row patterns each time).
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..CholeskySymbolicParams::default()
            },
        )
        .map_err(|e| sparse_error("symbolic Cholesky", e))?;
        let scratch = MemBuffer::try_new(StackReq::or(
            symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Spec::default()),
            symbolic.solve_in_place_scratch::<f64>(max_rhs, Par::Seq),
        ))
        .map_err(|_| allocation_error("Cholesky scratch"))?;
        Ok(Self {
            l_values: vec![0.0; symbolic.len_val()],
            symbolic,
            scratch,
        })
    }

    /// Factorise `matrix` (upper triangle, the pattern of [`Self::try_new`]); `false` when a
    /// pivot is not positive (the matrix is not positive definite to working precision).
    pub(crate) fn factorize(&mut self, matrix: SparseColMatRef<'_, usize, f64>) -> bool {
        self.symbolic
            .factorize_numeric_llt(
                &mut self.l_values,
                matrix,
                Side::Upper,
                LltRegularization::default(),
                Par::Seq,
                MemStack::new(&mut self.scratch),
                Spec::default(),
            )
            .is_ok()
    }

    /// Solve `A x = rhs` in place with the last successful factorisation.
    pub(crate) fn solve_in_place(&mut self, rhs: MatMut<'_, f64>) {
        LltRef::new(&self.symbolic, &self.l_values).solve_in_place_with_conj(
            Conj::No,
            rhs,
            Par::Seq,
            MemStack::new(&mut self.scratch),
        );
    }
}
