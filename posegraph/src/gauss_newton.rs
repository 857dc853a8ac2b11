//! Gauss-Newton.

use slam_core::{OptimizationReport, OptimizeError, Optimizer, PoseGraph};

use crate::solver::sealed::Caches;
use crate::solver::{SolverConfig, SolverPose};

/// Gauss-Newton on the sparse normal equations: every step is taken; a factorisation that meets a
/// non-positive pivot is retried with a small damping. Fast near the optimum, may diverge from a
/// poor start (use [`LevenbergMarquardt`](crate::LevenbergMarquardt) there). The sparse pattern
/// and the symbolic Cholesky are kept between calls while the graph's structure is unchanged.
#[derive(Debug, Default)]
pub struct GaussNewton {
    /// Stopping rules.
    pub config: SolverConfig,
    caches: Caches,
}

impl GaussNewton {
    /// Gauss-Newton with the given stopping rules.
    #[must_use]
    pub fn new(config: SolverConfig) -> Self {
        Self {
            config,
            caches: Caches::default(),
        }
    }
}

impl<P: SolverPose> Optimizer<P> for GaussNewton {
    fn optimize(&mut self, graph: &mut PoseGraph<P>) -> Result<OptimizationReport, OptimizeError> {
        P::optimize_cached(graph, &mut self.caches, &self.config, false, 0.0)
    }
}
