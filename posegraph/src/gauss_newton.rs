//! Gauss-Newton.

use slam_core::{OptimizationReport, OptimizeError, Optimizer, Pose2, Pose3, PoseGraph};

use crate::solver::{Cache, SolverConfig, optimize};

/// Gauss-Newton on the sparse normal equations: every step is taken; a factorisation that meets a
/// non-positive pivot is retried with a small damping. Fast near the optimum, may diverge from a
/// poor start (use [`LevenbergMarquardt`](crate::LevenbergMarquardt) there). The sparse pattern
/// and the symbolic Cholesky are kept between calls while the graph's structure is unchanged.
#[derive(Default)]
pub struct GaussNewton {
    /// Stopping rules.
    pub config: SolverConfig,
    cache3: Cache<6>,
    cache2: Cache<3>,
}

impl GaussNewton {
    /// Gauss-Newton with the given stopping rules.
    #[must_use]
    pub fn new(config: SolverConfig) -> Self {
        Self {
            config,
            cache3: None,
            cache2: None,
        }
    }
}

impl Optimizer<Pose3> for GaussNewton {
    fn optimize(
        &mut self,
        graph: &mut PoseGraph<Pose3>,
    ) -> Result<OptimizationReport, OptimizeError> {
        optimize(graph, &mut self.cache3, &self.config, false, 0.0)
    }
}

impl Optimizer<Pose2> for GaussNewton {
    fn optimize(
        &mut self,
        graph: &mut PoseGraph<Pose2>,
    ) -> Result<OptimizationReport, OptimizeError> {
        optimize(graph, &mut self.cache2, &self.config, false, 0.0)
    }
}
