//! The damped Gauss-Newton loop shared by [`GaussNewton`](crate::GaussNewton) and
//! [`LevenbergMarquardt`](crate::LevenbergMarquardt).

use nalgebra::SVector;
use slam_core::{
    Edge, FactorizationFailure, GraphValue, OptimizationReport, OptimizeError, Pose2, Pose3,
    PoseGraph, RobustKernel, StopReason,
};

use crate::linearize::{ErrorModel, Linearize};
use crate::normal_equations::NormalEquations;
use slam_core::InvalidSetting;

/// Stopping and damping settings shared by both optimisers.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct SolverConfig {
    /// Stop after this many iterations (accepted or rejected steps).
    pub max_iterations: usize,
    /// Stop when an accepted step lowers the cost by less than this fraction; default 1e-6
    /// (GTSAM's default is 1e-5).
    pub relative_cost_tolerance: f64,
    /// Stop when the step's largest component is below this (metres or radians).
    pub step_tolerance: f64,
    /// The edge error minimised; the report's costs are in this convention.
    pub error_model: ErrorModel,
}

impl Default for SolverConfig {
    fn default() -> Self {
        Self {
            max_iterations: 100,
            relative_cost_tolerance: 1e-6,
            step_tolerance: 1e-10,
            error_model: ErrorModel::LogMap,
        }
    }
}

impl SolverConfig {
    /// Checks every setting: at least one iteration, tolerances finite and not negative.
    ///
    /// # Errors
    /// [`InvalidSetting`] naming the first bad setting.
    pub fn validate(&self) -> Result<(), InvalidSetting> {
        InvalidSetting::check(
            self.max_iterations >= 1,
            "SolverConfig::max_iterations",
            self.max_iterations as f64,
            "at least 1",
        )?;
        check_tolerances(&[
            (
                "SolverConfig::relative_cost_tolerance",
                self.relative_cost_tolerance,
            ),
            ("SolverConfig::step_tolerance", self.step_tolerance),
        ])
    }
}

/// [`InvalidSetting`] for the first of `settings` (name, value) that is not finite and not
/// negative.
pub(crate) fn check_tolerances(settings: &[(&'static str, f64)]) -> Result<(), InvalidSetting> {
    InvalidSetting::check_non_negative(settings)
}

/// `sum rho(e^T Omega e)` with `poses` in place of the graph's; with `weights` (one per edge),
/// `sum w e^T Omega e` instead (the kernels ignored).
/// Geman-McClure kernels are taken at `gm_scale` times their `c^2` (see [`graduated`]).
pub(crate) fn cost_with<P: Linearize<D>, const D: usize>(
    graph: &PoseGraph<P>,
    poses: &[P],
    model: ErrorModel,
    weights: Option<&[f64]>,
    gm_scale: f64,
) -> f64 {
    let edges = graph.edges().iter();
    match weights {
        None => edges
            .map(|e| {
                let s = chi2(e, poses, model);
                e.kernel.map_or(s, |k| graduated(k, gm_scale).rho(s))
            })
            .sum(),
        Some(w) => edges
            .enumerate()
            .filter(|&(k, _)| w[k] != 0.0)
            .map(|(k, e)| w[k] * chi2(e, poses, model))
            .sum(),
    }
}

/// `e^T Omega e` of edge `e` with `poses` in place of the graph's.
pub(crate) fn chi2<P: Linearize<D>, const D: usize>(
    e: &Edge<P>,
    poses: &[P],
    model: ErrorModel,
) -> f64 {
    let err = P::error(model, &e.measurement, &poses[e.from], &poses[e.to]);
    (err.transpose() * P::info(&e.information) * err)[0]
}

/// The first value that makes the cost of `graph` at `poses` non-finite: a node's pose (set
/// through [`PoseGraph::set_pose`], which does not check), else an edge whose squared error
/// overflows although its numbers are finite (a 1e200 m measurement).
pub(crate) fn non_finite_value<P: Linearize<D>, const D: usize>(
    graph: &PoseGraph<P>,
    poses: &[P],
    model: ErrorModel,
) -> Option<GraphValue> {
    let nodes = graph.nodes();
    if let Some(i) = poses.iter().position(|p| !p.is_finite()) {
        return Some(GraphValue::NodePose { id: nodes[i].id });
    }
    graph
        .edges()
        .iter()
        .position(|e| !chi2(e, poses, model).is_finite())
        .map(|k| {
            let e = &graph.edges()[k];
            GraphValue::EdgeError {
                edge: k,
                from: nodes[e.from].id,
                to: nodes[e.to].id,
            }
        })
}

/// [`OptimizeError::NonFinite`] unless every pose and every edge's squared error of `graph` is
/// finite: a solver started there would end `Ok` with a NaN or infinite cost.
pub(crate) fn check_finite<P: Linearize<D>, const D: usize>(
    graph: &PoseGraph<P>,
    model: ErrorModel,
) -> Result<(), OptimizeError> {
    let poses: Vec<P> = graph.nodes().iter().map(|n| n.pose).collect();
    match non_finite_value(graph, &poses, model) {
        Some(what) => Err(OptimizeError::NonFinite { what }),
        None => Ok(()),
    }
}

/// The IRLS surrogate of a graph with robust kernels, `sum w_k s_k(poses)` with each kernel's
/// weight `w_k = rho'(s_k)` taken at the linearisation point (`at`, the current poses) and held:
/// the weighted least-squares problem a step minimises. Its relative decrease is the stop test
/// of a kernelled graph: a bounded kernel (Geman-McClure) saturates far from the optimum, where
/// the robust cost barely changes while the poses still move by metres.
fn surrogate<P: Linearize<D>, const D: usize>(
    graph: &PoseGraph<P>,
    at: &[P],
    poses: &[P],
    model: ErrorModel,
) -> f64 {
    graph
        .edges()
        .iter()
        .map(|e| {
            let s = chi2(e, poses, model);
            e.kernel.map_or(s, |k| k.weight(chi2(e, at, model)) * s)
        })
        .sum()
}

/// `kernel` with a Geman-McClure scale widened to `c^2 * gm_scale`; other kernels unchanged.
///
/// Geman-McClure is bounded: an edge whose error is far beyond `c` costs almost exactly `c^2`
/// and pulls with a weight of about `c^4 / s^2`. From ring.g2o's own guess (13 m of drift, every
/// loop at `s` of about 17,000 with `c = 1`) the loops' weights are 1e-9 of odometry's, the cost
/// is flat and the odometry-only map a stationary point: no descent method leaves it. So the
/// optimisers graduate it as graduated non-convexity does (Yang et al., RA-L 2020): the scale
/// starts at `2 s_max / c^2` (nearly least squares over every residual) and is divided by 1.4
/// after each accepted step down to 1, where the optimisation then converges as usual.
fn graduated(kernel: RobustKernel, gm_scale: f64) -> RobustKernel {
    match kernel {
        RobustKernel::GemanMcClure { c } if gm_scale > 1.0 => RobustKernel::GemanMcClure {
            c: c * gm_scale.sqrt(),
        },
        k => k,
    }
}

/// The first Geman-McClure scale (see [`graduated`]): `max(1, 2 s / c^2)` over the edges with a
/// Geman-McClure kernel at `poses`.
fn initial_gm_scale<P: Linearize<D>, const D: usize>(
    graph: &PoseGraph<P>,
    poses: &[P],
    model: ErrorModel,
) -> f64 {
    graph
        .edges()
        .iter()
        .filter_map(|e| match e.kernel {
            Some(RobustKernel::GemanMcClure { c }) => Some(2.0 * chi2(e, poses, model) / (c * c)),
            _ => None,
        })
        .fold(1.0, f64::max)
}

/// The IRLS weight of every edge with the Geman-McClure kernels at `gm_scale`.
fn level_weights<P: Linearize<D>, const D: usize>(
    graph: &PoseGraph<P>,
    poses: &[P],
    model: ErrorModel,
    gm_scale: f64,
    out: &mut Vec<f64>,
) {
    out.clear();
    out.extend(graph.edges().iter().map(|e| {
        e.kernel.map_or(1.0, |k| {
            graduated(k, gm_scale).weight(chi2(e, poses, model))
        })
    }));
}

/// Cached structure of an optimiser.
pub(crate) type Cache<const D: usize> = Option<NormalEquations<D>>;

/// A pose type the optimisers solve for: [`Pose3`] (6 degrees of freedom) and [`Pose2`] (3).
/// [`GaussNewton`](crate::GaussNewton) and [`LevenbergMarquardt`](crate::LevenbergMarquardt)
/// implement [`Optimizer<P>`](slam_core::Optimizer) once for every `P: SolverPose`. Sealed: each
/// optimiser keeps a cache slot per pose type.
pub trait SolverPose: sealed::Sealed {}

impl SolverPose for Pose3 {}
impl SolverPose for Pose2 {}

pub(crate) mod sealed {
    use slam_core::{OptimizationReport, OptimizeError, Pose2, Pose3, PoseGraph};

    use super::{Cache, SolverConfig, optimize};
    use crate::gnc::{GncConfig, GncReport, graduate};

    /// The normal equations an optimiser keeps between calls, one slot per pose type.
    #[derive(Default)]
    pub struct Caches {
        se3: Cache<6>,
        se2: Cache<3>,
    }

    /// Nothing of the cached normal equations (their size follows the last graph).
    impl std::fmt::Debug for Caches {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            f.debug_struct("Caches").finish_non_exhaustive()
        }
    }

    /// The loop of [`optimize`] with the cache slot of the pose type.
    pub trait Sealed: slam_core::GraphPose {
        /// The position (metres; z = 0 in SE(2)).
        fn position(&self) -> nalgebra::Vector3<f64>;
        /// The identity pose.
        fn identity_pose() -> Self;
        /// `self * other`.
        fn compose(&self, other: &Self) -> Self;
        /// `self^-1`.
        fn inverse_pose(&self) -> Self;

        /// Run the loop (see [`optimize`]) with this pose type's slot of `caches`.
        fn optimize_cached(
            graph: &mut PoseGraph<Self>,
            caches: &mut Caches,
            config: &SolverConfig,
            levenberg: bool,
            initial_lambda: f64,
        ) -> Result<OptimizationReport, OptimizeError>;

        /// Graduated non-convexity (see [`graduate`]) with this pose type's slot of `caches`.
        fn graduate(
            graph: &mut PoseGraph<Self>,
            caches: &mut Caches,
            config: &GncConfig,
        ) -> Result<GncReport, OptimizeError>;
    }

    /// What the two pose types share: composition, and the loops run with `$slot`, the type's
    /// cache slot.
    macro_rules! shared {
        ($slot:ident) => {
            fn compose(&self, other: &Self) -> Self {
                self * other
            }
            fn inverse_pose(&self) -> Self {
                self.inverse()
            }
            fn optimize_cached(
                graph: &mut PoseGraph<Self>,
                caches: &mut Caches,
                config: &SolverConfig,
                levenberg: bool,
                initial_lambda: f64,
            ) -> Result<OptimizationReport, OptimizeError> {
                optimize(
                    graph,
                    &mut caches.$slot,
                    config,
                    levenberg,
                    initial_lambda,
                    None,
                )
            }
            fn graduate(
                graph: &mut PoseGraph<Self>,
                caches: &mut Caches,
                config: &GncConfig,
            ) -> Result<GncReport, OptimizeError> {
                graduate(graph, &mut caches.$slot, config)
            }
        };
    }

    impl Sealed for Pose3 {
        fn position(&self) -> nalgebra::Vector3<f64> {
            self.translation.vector
        }
        fn identity_pose() -> Self {
            Pose3::identity()
        }
        shared!(se3);
    }

    impl Sealed for Pose2 {
        fn position(&self) -> nalgebra::Vector3<f64> {
            let t = self.translation.vector;
            nalgebra::Vector3::new(t.x, t.y, 0.0)
        }
        fn identity_pose() -> Self {
            Pose2::identity()
        }
        shared!(se2);
    }
}

// One loop with the damping state machine in plain sight; splitting it would hide the control flow.
#[allow(clippy::too_many_lines)]
/// Run the loop. `levenberg` chooses LM (adaptive damping, rejected steps) or GN (no damping
/// unless the factorisation needs it, every step accepted). `weights` (one per edge) replace the
/// edges' kernels: the cost is then `sum w e^T Omega e` (graduated non-convexity's inner
/// problem).
pub(crate) fn optimize<P: Linearize<D>, const D: usize>(
    graph: &mut PoseGraph<P>,
    cache: &mut Cache<D>,
    config: &SolverConfig,
    levenberg: bool,
    initial_lambda: f64,
    weights: Option<&[f64]>,
) -> Result<OptimizationReport, OptimizeError> {
    graph.check_gauge()?;
    let model = config.error_model;
    check_finite(graph, model)?;
    let mut poses: Vec<P> = graph.nodes().iter().map(|n| n.pose).collect();
    let initial_cost = cost_with(graph, &poses, model, weights, 1.0);
    let kernelled = weights.is_none() && graph.edges().iter().any(|e| e.kernel.is_some());
    let mut gm_scale = if weights.is_none() {
        initial_gm_scale(graph, &poses, model)
    } else {
        1.0
    };
    let mut level = Vec::new();
    let ne = match cache.take() {
        Some(ne) if ne.fits(graph) => cache.insert(ne),
        _ => cache.insert(NormalEquations::new(graph)?),
    };
    if ne.dimension() == 0 || graph.edge_count() == 0 {
        return Ok(OptimizationReport {
            iterations: 0,
            initial_cost,
            final_cost: initial_cost,
            stop_reason: StopReason::NothingToDo,
        });
    }
    let n = ne.dimension();
    let mut cost = cost_with(graph, &poses, model, weights, gm_scale);
    let mut lambda = if levenberg { initial_lambda } else { 0.0 };
    let mut nu = 2.0;
    let mut rhs = faer::Mat::<f64>::zeros(n, 1);
    let mut iterations = 0;
    let mut stop = StopReason::MaxIterations;
    let mut relinearize = true;
    let mut diagonal = vec![0.0; n];
    let mut damped = ne.values.clone();
    'outer: while iterations < config.max_iterations {
        if relinearize {
            if gm_scale > 1.0 {
                level_weights(graph, &poses, model, gm_scale, &mut level);
                ne.assemble(graph, model, Some(&level));
            } else {
                ne.assemble(graph, model, weights);
            }
            for (k, d) in diagonal.iter_mut().enumerate() {
                *d = ne.values[ne.diagonal_position(k)].max(1e-9);
            }
            relinearize = false;
        }
        iterations += 1;
        // Damped system: H + lambda * diag(H) (Marquardt's scaling, floored for empty rows).
        damped.copy_from_slice(&ne.values);
        if lambda > 0.0 {
            for (k, &d) in diagonal.iter().enumerate() {
                damped[ne.diagonal_position(k)] += lambda * d;
            }
        }
        if !ne.factorize(&damped) {
            // A non-positive pivot: raise the damping instead of failing.
            lambda = if lambda == 0.0 { 1e-9 } else { lambda * nu };
            nu *= 2.0;
            if lambda > 1e16 {
                stop = StopReason::DampingExhausted;
                break;
            }
            continue;
        }
        for k in 0..n {
            rhs[(k, 0)] = -ne.gradient[k];
        }
        ne.solve_in_place(rhs.as_mut());
        let mut step_max: f64 = 0.0;
        let mut trial = poses.clone();
        for (i, node) in graph.nodes().iter().enumerate() {
            if let Some(v) = ne.variable(i) {
                let d = SVector::<f64, D>::from_fn(|r, _| rhs[(v * D + r, 0)]);
                step_max = step_max.max(d.amax());
                trial[i] = node.pose.retract(&d);
            }
        }
        if !step_max.is_finite() {
            return Err(OptimizeError::Factorization {
                stage: "step solve",
                cause: FactorizationFailure::NonFiniteSolution,
            });
        }
        let new_cost = cost_with(graph, &trial, model, weights, gm_scale);
        if !levenberg
            && !new_cost.is_finite()
            && let Some(what) = non_finite_value(graph, &trial, model)
        {
            // Gauss-Newton takes every step: one that overflows is a divergence, not a result.
            return Err(OptimizeError::NonFinite { what });
        }
        // NaN costs count as worse.
        let improved = new_cost < cost;
        if levenberg && !improved {
            // Rejected: more damping, same linearisation.
            lambda *= nu;
            nu *= 2.0;
            if lambda > 1e16 {
                if gm_scale > 1.0 {
                    // No better point at this scale: go on with the next one.
                    gm_scale = (gm_scale / 1.4).max(1.0);
                    cost = cost_with(graph, &poses, model, weights, gm_scale);
                    (lambda, nu, relinearize) = (initial_lambda, 2.0, true);
                    continue;
                }
                stop = StopReason::DampingExhausted;
                break 'outer;
            }
            continue;
        }
        let decrease = if kernelled {
            let before = surrogate(graph, &poses, &poses, model);
            (before - surrogate(graph, &poses, &trial, model)) / before.max(f64::MIN_POSITIVE)
        } else {
            (cost - new_cost) / cost.max(f64::MIN_POSITIVE)
        };
        for (i, p) in trial.iter().enumerate() {
            graph.set_pose(i, *p);
        }
        poses = trial;
        cost = new_cost;
        relinearize = true;
        if levenberg {
            lambda = (lambda / 10.0).max(1e-15);
            nu = 2.0;
        } else if lambda > 0.0 {
            lambda = 0.0;
        }
        if gm_scale > 1.0 {
            // Graduating a Geman-McClure kernel: one step per scale, no stop test before 1.
            gm_scale = (gm_scale / 1.4).max(1.0);
            cost = cost_with(graph, &poses, model, weights, gm_scale);
            continue;
        }
        if step_max < config.step_tolerance {
            stop = StopReason::StepConverged;
            break;
        }
        if decrease.abs() < config.relative_cost_tolerance || cost == 0.0 {
            stop = StopReason::CostConverged;
            break;
        }
    }
    Ok(OptimizationReport {
        iterations,
        initial_cost,
        final_cost: cost,
        stop_reason: stop,
    })
}
