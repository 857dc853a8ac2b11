//! Graduated non-convexity (Yang, Antonante, Tzoumas, Carlone, "Graduated Non-Convexity for
//! Robust Spatial Perception: From Non-Minimal Solvers to Global Outlier Rejection", RA-L 5(2),
//! 2020) over the Levenberg-Marquardt loop of this crate.
//!
//! Each outer iteration fixes the control parameter `mu`, sets every candidate edge's weight to
//! the closed-form minimiser of the surrogate loss's Black-Rangarajan dual (paper, eq. 9 for
//! Geman-McClure and eq. 11 for truncated least squares) at the current residuals, and takes a
//! few weighted least-squares steps from the current poses; then `mu` moves one step towards the
//! real loss. The sparse pattern, the ordering and the symbolic Cholesky are made once per graph
//! structure and shared by every inner solve (only the values change with the weights).

use slam_core::{OptimizationReport, OptimizeError, Optimizer, PoseGraph, StopReason};

use crate::gnc_loss::{GncLoss, chi2_quantile};
use crate::linearize::Linearize;
use crate::loop_support::supported;
use crate::solver::sealed::Caches;
use crate::solver::{Cache, SolverConfig, SolverPose, check_finite, chi2, optimize};
use slam_core::InvalidSetting;

/// Which edges graduated non-convexity takes as inliers without testing them (weight 1 always):
/// odometry, whose errors are small and which keeps the graph connected.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(tag = "kind", content = "flags", deny_unknown_fields)
)]
pub enum KnownInliers {
    /// Edges between nodes whose ids differ by one (odometry, when nodes are numbered in the
    /// order they were made, as g2o files and the SLAM engine number them).
    #[default]
    ConsecutiveIds,
    /// Edges without a robust kernel: the caller marks the candidates (loop closures) by giving
    /// them a kernel, which graduated non-convexity then replaces by its own loss.
    WithoutKernel,
    /// One flag per edge, in [`PoseGraph::edges`] order (`true`: known inlier). Edges past the
    /// end of the list are candidates.
    Flags(Vec<bool>),
    /// None: every edge is a candidate.
    None,
}

impl KnownInliers {
    /// Whether edge `k` of `graph` is a known inlier.
    fn contains<P: slam_core::GraphPose>(&self, graph: &PoseGraph<P>, k: usize) -> bool {
        let e = &graph.edges()[k];
        match self {
            Self::ConsecutiveIds => graph.nodes()[e.from].id.abs_diff(graph.nodes()[e.to].id) == 1,
            Self::WithoutKernel => e.kernel.is_none(),
            Self::Flags(flags) => flags.get(k).copied().unwrap_or(false),
            Self::None => false,
        }
    }
}

/// Settings of [`GraduatedNonConvexity`].
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct GncConfig {
    /// The robust loss; default truncated least squares (the paper's and GTSAM's choice for pose
    /// graphs).
    pub loss: GncLoss,
    /// An inlier's squared Mahalanobis error `e^T Omega e` is below the chi-square quantile of
    /// this probability with the pose's degrees of freedom; default 0.99 (the threshold is then
    /// 11.34 in SE(2), 16.81 in SE(3)). In `(0, 1)`.
    pub inlier_probability: f64,
    /// The edges never tested; default [`KnownInliers::ConsecutiveIds`] (odometry).
    pub known_inliers: KnownInliers,
    /// Factor by which `mu` moves each outer iteration (the paper's 1.4); greater than 1.
    pub mu_step: f64,
    /// Cap on outer iterations (weight updates); at least 1. Reaching it is reported
    /// ([`GncReport::converged`] false), not an error.
    pub max_outer_iterations: usize,
    /// Candidate loops with a consistent partner joining the same two stretches of odometry,
    /// each end within this many odometry steps (the pairwise consistency test of PCM on short
    /// chains, which needs no pose estimate), start as inliers: they are held at weight 1 while
    /// the others graduate, and re-tested with them at the end. 0 turns the test off; default 5.
    pub support_window: usize,
    /// After the weights have converged, the rejected candidates with the smallest errors are
    /// re-admitted one at a time, up to this many, each kept only when it lowers the TLS cost
    /// (a rejected loop is judged at a solution without it); the first failure ends the trials.
    /// Truncated least squares only; 0 turns it off; default 4.
    pub readmission_trials: usize,
    /// Levenberg-Marquardt iterations per outer iteration (the weights change little from one
    /// to the next, so a full solve each time is wasted); at least 1.
    pub inner_iterations: usize,
    /// Truncated least squares has converged when every candidate's weight is within this of 0
    /// or 1; Geman-McClure when no weight changes by more than this at `mu = 1`. In `(0, 0.5)`;
    /// default 1e-4 (GTSAM's default, which its own GNC needs tightened: it stops early on a
    /// change of the weights' sum instead).
    pub weight_tolerance: f64,
    /// The first least-squares solve (every weight 1) and the final one (the weights found) run
    /// Levenberg-Marquardt with these stopping rules and this error model.
    pub solver: SolverConfig,
}

impl Default for GncConfig {
    fn default() -> Self {
        Self {
            loss: GncLoss::TruncatedLeastSquares,
            inlier_probability: 0.99,
            known_inliers: KnownInliers::ConsecutiveIds,
            mu_step: 1.4,
            support_window: 5,
            readmission_trials: 4,
            max_outer_iterations: 1000,
            inner_iterations: 2,
            weight_tolerance: 1e-4,
            solver: SolverConfig::default(),
        }
    }
}

impl GncConfig {
    /// Checks every setting (see each field's range).
    ///
    /// # Errors
    /// [`InvalidSetting`] naming the first bad setting.
    pub fn validate(&self) -> Result<(), InvalidSetting> {
        let p = self.inlier_probability;
        InvalidSetting::check(
            p > 0.0 && p < 1.0,
            "GncConfig::inlier_probability",
            p,
            "in (0, 1)",
        )?;
        InvalidSetting::check(
            self.mu_step.is_finite() && self.mu_step > 1.0,
            "GncConfig::mu_step",
            self.mu_step,
            "finite and greater than 1",
        )?;
        for (setting, v) in [
            ("GncConfig::max_outer_iterations", self.max_outer_iterations),
            ("GncConfig::inner_iterations", self.inner_iterations),
        ] {
            InvalidSetting::check(v >= 1, setting, v as f64, "at least 1")?;
        }
        let t = self.weight_tolerance;
        InvalidSetting::check(
            t > 0.0 && t < 0.5,
            "GncConfig::weight_tolerance",
            t,
            "in (0, 0.5)",
        )?;
        self.solver.validate()
    }
}

/// What a run of [`GraduatedNonConvexity`] did, with every edge's final weight.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct GncReport {
    /// Iterations (every Levenberg-Marquardt iteration of every solve), the robust cost before
    /// and after (`sum e^T Omega e` over known inliers plus the loss over candidates, at `mu`'s
    /// final value) and the final solve's stop reason ([`StopReason::MaxIterations`] when the
    /// outer loop hit its cap).
    pub optimization: OptimizationReport,
    /// Outer iterations (weight updates).
    pub outer_iterations: usize,
    /// Whether the weights converged (TLS: all 0 or 1; GM: steady at `mu = 1`) before the outer
    /// cap.
    pub converged: bool,
    /// The inlier threshold `c2` on `e^T Omega e` (from
    /// [`GncConfig::inlier_probability`]).
    pub inlier_threshold: f64,
    /// Final weight of each edge, in [`PoseGraph::edges`] order, in `[0, 1]`: 1 for known
    /// inliers; 0 or 1 for truncated least squares.
    pub weights: Vec<f64>,
    /// Number of known inliers.
    pub known_inliers: usize,
    /// Candidates weighted out (weight below 0.5).
    pub rejected: usize,
    /// Candidates that had a consistent partner ([`GncConfig::support_window`]) and so started
    /// as inliers.
    pub supported: usize,
}

impl GncReport {
    /// Whether edge `k` was weighted out (weight below 0.5); `false` past the last edge.
    #[must_use]
    pub fn is_rejected(&self, k: usize) -> bool {
        self.weights.get(k).is_some_and(|&w| w < 0.5)
    }
}

/// Graduated non-convexity: outlier-robust pose-graph optimisation that needs no initial guess
/// of which loop closures are wrong (Yang et al., RA-L 2020). Starts from the least-squares
/// solution with every edge, then graduates a surrogate of the robust loss from convex to the
/// real one, reweighting the candidate edges (by default every edge but odometry) at each step.
/// Ends with a Levenberg-Marquardt solve with the final weights; for truncated least squares the
/// weights are then re-tested against the threshold at the solution (an edge is an inlier exactly
/// when its error is below it) until none changes. The graph's own robust kernels are ignored:
/// the loss replaces them.
///
/// [`Optimizer::optimize`] returns the summary; [`GraduatedNonConvexity::optimize_robust`] the
/// full [`GncReport`], and [`GraduatedNonConvexity::weights`] keeps the last run's weights.
#[derive(Default)]
pub struct GraduatedNonConvexity {
    config: GncConfig,
    caches: Caches,
    weights: Vec<f64>,
}

/// The settings and how many edge weights the last run left; not the weights themselves.
impl std::fmt::Debug for GraduatedNonConvexity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GraduatedNonConvexity")
            .field("config", &self.config)
            .field("weights", &self.weights.len())
            .finish_non_exhaustive()
    }
}

impl GraduatedNonConvexity {
    /// Graduated non-convexity with `config`.
    ///
    /// # Errors
    /// [`InvalidSetting`] naming the first bad setting of `config`.
    pub fn try_new(config: GncConfig) -> Result<Self, InvalidSetting> {
        config.validate()?;
        Ok(Self {
            config,
            caches: Caches::default(),
            weights: Vec::new(),
        })
    }

    /// The settings.
    #[must_use]
    pub fn config(&self) -> &GncConfig {
        &self.config
    }

    /// The final weight of each edge after the last run (empty before the first), in
    /// [`PoseGraph::edges`] order.
    #[must_use]
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// Optimise `graph` and report every edge's weight.
    ///
    /// # Errors
    /// As [`Optimizer::optimize`]: an invalid graph (no fixed node, disconnected nodes) or a
    /// factorisation that cannot be recovered.
    pub fn optimize_robust<P: SolverPose>(
        &mut self,
        graph: &mut PoseGraph<P>,
    ) -> Result<GncReport, OptimizeError> {
        let report = P::graduate(graph, &mut self.caches, &self.config)?;
        self.weights.clone_from(&report.weights);
        Ok(report)
    }
}

impl<P: SolverPose> Optimizer<P> for GraduatedNonConvexity {
    fn optimize(&mut self, graph: &mut PoseGraph<P>) -> Result<OptimizationReport, OptimizeError> {
        Ok(self.optimize_robust(graph)?.optimization)
    }

    fn edge_weights(&self) -> Option<&[f64]> {
        Some(&self.weights)
    }
}

/// Squared errors of every edge at the graph's poses.
fn residuals<P: Linearize<D>, const D: usize>(
    graph: &PoseGraph<P>,
    config: &SolverConfig,
    out: &mut Vec<f64>,
) {
    let poses: Vec<P> = graph.nodes().iter().map(|n| n.pose).collect();
    out.clear();
    out.extend(
        graph
            .edges()
            .iter()
            .map(|e| chi2(e, &poses, config.error_model)),
    );
}

/// The final solves: Levenberg-Marquardt with the weights, then each candidate re-weighted at
/// the solution (TLS: 1 exactly when its error is below `c2`; GM: its weight at `mu = 1`), until
/// no weight changes (at most 10 rounds).
struct Settle<'a> {
    config: &'a GncConfig,
    known: &'a [bool],
    c2: f64,
    /// LM iterations so far.
    iterations: usize,
}

impl Settle<'_> {
    /// Solve and re-weight until steady; returns the last solve's stop reason.
    fn run<P: Linearize<D>, const D: usize>(
        &mut self,
        graph: &mut PoseGraph<P>,
        cache: &mut Cache<D>,
        weights: &mut [f64],
        s: &mut Vec<f64>,
    ) -> Result<StopReason, OptimizeError> {
        let mut stop = StopReason::NothingToDo;
        for _ in 0..10 {
            let r = optimize(graph, cache, &self.config.solver, true, 1e-8, Some(weights))?;
            self.iterations += r.iterations;
            stop = r.stop_reason;
            residuals(graph, &self.config.solver, s);
            let mut changed = false;
            for k in (0..weights.len()).filter(|&k| !self.known[k]) {
                let w = match self.config.loss {
                    GncLoss::TruncatedLeastSquares => {
                        if s[k] <= self.c2 {
                            1.0
                        } else {
                            0.0
                        }
                    }
                    GncLoss::GemanMcClure => self.config.loss.weight(s[k], self.c2, 1.0),
                };
                changed |= (w - weights[k]).abs() > self.config.weight_tolerance;
                weights[k] = w;
            }
            if !changed {
                break;
            }
        }
        Ok(stop)
    }
}

/// The robust cost: `s` over known inliers, the loss over candidates.
fn robust_cost(s: &[f64], known: &[bool], loss: GncLoss, c2: f64) -> f64 {
    s.iter()
        .zip(known)
        .map(|(&s, &k)| if k { s } else { loss.cost(s, c2) })
        .sum()
}

/// The whole run for one pose type (see [`GraduatedNonConvexity`]).
// The outer loop, its convergence tests and the final re-test in one place.
#[allow(clippy::too_many_lines)]
pub(crate) fn graduate<P: Linearize<D> + SolverPose, const D: usize>(
    graph: &mut PoseGraph<P>,
    cache: &mut Cache<D>,
    config: &GncConfig,
) -> Result<GncReport, OptimizeError> {
    graph.check_gauge()?;
    check_finite(graph, config.solver.error_model)?;
    let m = graph.edge_count();
    let known: Vec<bool> = (0..m)
        .map(|k| config.known_inliers.contains(graph, k))
        .collect();
    let c2 = chi2_quantile(D, config.inlier_probability);
    let loss = config.loss;
    // Supported candidates are held at weight 1 while the rest graduate.
    let candidate: Vec<bool> = known.iter().map(|k| !k).collect();
    let support = supported(graph, &candidate, config.support_window as u64, c2);
    let held: Vec<bool> = known.iter().zip(&support).map(|(k, s)| *k || *s).collect();
    let mut s = Vec::with_capacity(m);
    residuals(graph, &config.solver, &mut s);
    let initial_cost = robust_cost(&s, &known, loss, c2);
    let mut weights = vec![1.0; m];
    let lambda = 1e-8; // LevenbergMarquardt's default
    let mut iterations = 0;
    // mu starts where the surrogate is convex over the residuals at the initial guess: with
    // odometry as the guess and the known inliers, the candidates start nearly weighted out
    // and come in as the surrogate graduates, those that agree with the rest first. (Starting
    // from the least-squares solution with every edge instead lets wrong loops fold the graph
    // until they look like inliers: on ring.g2o it is 50-100 m off.)
    let s_max = s
        .iter()
        .zip(&held)
        .filter(|&(_, &k)| !k)
        .map(|(&s, _)| s)
        .fold(0.0, f64::max);
    let inner = SolverConfig {
        max_iterations: config.inner_iterations,
        ..config.solver
    };
    let mut outer = 0;
    let mut converged = true;
    if let Some(mut mu) = loss.initial_mu(s_max, c2) {
        converged = false;
        while outer < config.max_outer_iterations {
            outer += 1;
            let mut change: f64 = 0.0;
            let mut binary = true;
            for k in (0..m).filter(|&k| !held[k]) {
                let w = loss.weight(s[k], c2, mu);
                change = change.max((w - weights[k]).abs());
                binary &= w <= config.weight_tolerance || w >= 1.0 - config.weight_tolerance;
                weights[k] = w;
            }
            let done = match loss {
                // Binary weights at a tiny mu only say that every residual is far beyond the
                // surrogate's (then very wide) band, as all loops are at a drifted guess; from
                // mu = 1 on the band is within a factor 2 of the threshold.
                GncLoss::TruncatedLeastSquares => binary && mu >= 1.0,
                GncLoss::GemanMcClure => loss.mu_at_end(mu) && change <= config.weight_tolerance,
            };
            if done {
                converged = true;
                break;
            }
            let r = optimize(graph, cache, &inner, true, lambda, Some(&weights))?;
            iterations += r.iterations;
            residuals(graph, &config.solver, &mut s);
            mu = loss.next_mu(mu, config.mu_step);
        }
    }
    // The final solve. TLS: weights rounded, then re-tested at the solution against the
    // threshold (a TLS minimum weights an edge 1 exactly when its error is below c2).
    if loss == GncLoss::TruncatedLeastSquares {
        for w in &mut weights {
            *w = if *w >= 0.5 { 1.0 } else { 0.0 };
        }
    }
    let mut settled = Settle {
        config,
        known: &known,
        c2,
        iterations: 0,
    };
    let mut stop = settled.run(graph, cache, &mut weights, &mut s)?;
    // Re-admission: a rejected candidate was judged at a solution without it, where a part of
    // the graph that only it holds (a stretch of odometry after the last other loop) can sit
    // well off. Try the rejected candidates with the smallest errors one at a time, keeping a
    // trial only when it lowers the TLS cost.
    if loss == GncLoss::TruncatedLeastSquares {
        let mut tried = vec![false; m];
        for _ in 0..config.readmission_trials {
            let Some(k) = (0..m)
                .filter(|&k| !known[k] && weights[k] == 0.0 && !tried[k])
                .min_by(|&a, &b| s[a].total_cmp(&s[b]))
            else {
                break;
            };
            tried[k] = true;
            let before = robust_cost(&s, &known, loss, c2);
            let (saved_poses, saved_weights, saved_s): (Vec<P>, Vec<f64>, Vec<f64>) = (
                graph.nodes().iter().map(|n| n.pose).collect(),
                weights.clone(),
                s.clone(),
            );
            weights[k] = 1.0;
            let trial_stop = settled.run(graph, cache, &mut weights, &mut s)?;
            if robust_cost(&s, &known, loss, c2) < before * (1.0 - 1e-9) {
                stop = trial_stop;
            } else {
                for (i, p) in saved_poses.into_iter().enumerate() {
                    graph.set_pose(i, p);
                }
                weights = saved_weights;
                s = saved_s;
                break;
            }
        }
    }
    iterations += settled.iterations;
    if !converged {
        stop = StopReason::MaxIterations;
    }
    let rejected = weights.iter().filter(|&&w| w < 0.5).count();
    Ok(GncReport {
        optimization: OptimizationReport {
            iterations,
            initial_cost,
            final_cost: robust_cost(&s, &known, loss, c2),
            stop_reason: stop,
        },
        outer_iterations: outer,
        converged,
        inlier_threshold: c2,
        known_inliers: known.iter().filter(|&&k| k).count(),
        supported: support.iter().filter(|&&s| s).count(),
        weights,
        rejected,
    })
}
