//! Levenberg-Marquardt.

use slam_core::{OptimizationReport, OptimizeError, Optimizer, PoseGraph};

use crate::solver::sealed::Caches;
use crate::solver::{SolverConfig, SolverPose};

/// Levenberg-Marquardt: Gauss-Newton steps on `H + lambda diag(H)`; a step that raises the cost is
/// rejected and the damping raised (times 2, 4, 8, ...), an accepted one lowers it (divided by 10).
/// The small initial damping makes the first steps nearly Gauss-Newton steps; rejections raise it
/// where the start is poor.
/// The sparse pattern and the symbolic Cholesky are kept between calls while the graph's structure
/// is unchanged.
#[derive(Debug)]
pub struct LevenbergMarquardt {
    /// Stopping rules.
    pub config: SolverConfig,
    /// Initial damping (relative to the diagonal), default 1e-8 (1e-5 took 8 iterations instead
    /// of 5 on parking-garage and `input_M3500_g2o`, the same optimum).
    pub initial_lambda: f64,
    caches: Caches,
}

impl Default for LevenbergMarquardt {
    fn default() -> Self {
        Self::new(SolverConfig::default())
    }
}

impl LevenbergMarquardt {
    /// LM with the given stopping rules.
    #[must_use]
    pub fn new(config: SolverConfig) -> Self {
        Self {
            config,
            initial_lambda: 1e-8,
            caches: Caches::default(),
        }
    }
}

impl<P: SolverPose> Optimizer<P> for LevenbergMarquardt {
    fn optimize(&mut self, graph: &mut PoseGraph<P>) -> Result<OptimizationReport, OptimizeError> {
        P::optimize_cached(
            graph,
            &mut self.caches,
            &self.config,
            true,
            self.initial_lambda,
        )
    }
}
