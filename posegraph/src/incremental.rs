//! [`IncrementalSmoother`]: an iSAM2-style incremental optimiser (Kaess, Johannsson, Roberts, Ila,
//! Leonard, Dellaert, "iSAM2: Incremental smoothing and mapping using the Bayes tree", IJRR 2012).

use nalgebra::{SMatrix, SVector};
use slam_core::{
    FactorizationFailure, GraphValue, IncrementalOptimizer, IncrementalReport, OptimizationReport,
    OptimizeError, Optimizer, Pose2, Pose3, PoseGraph, StopReason,
};

use crate::block_factor::{BlockFactor, BlockSystem};
use crate::linearize::{ErrorModel, Linearize};
use crate::normal_equations::grows_from;
use crate::solver::{check_tolerances, chi2, cost_with};
use slam_core::InvalidSetting;

/// Settings of an [`IncrementalSmoother`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct IncrementalConfig {
    /// A node is relinearised when its pending step's largest component exceeds this (metres or
    /// radians); default 0.05 (iSAM2's default is 0.1). Smaller follows the optimum more closely
    /// at the price of more re-factorisation per update (at 0.01 the SE(3) patrol of the
    /// `posegraph_isam` bench took twice as long a loop, at 0.1 a quarter less).
    pub relinearize_threshold: f64,
    /// An update solves a node's step again only when it was re-factored or a step of one of
    /// the nodes eliminated after it moved by more than this (metres or radians); default 1e-4
    /// (iSAM2's wildfire threshold, default 1e-3 there). 0 solves every step below a change.
    /// [`Optimizer::optimize`] solves every step.
    pub wildfire_threshold: f64,
    /// [`Optimizer::optimize`] iterates until no step component exceeds this; default 1e-9.
    pub step_tolerance: f64,
    /// [`Optimizer::optimize`]'s cap on updates, the first (which takes in the new elements)
    /// included; default 100. 1 makes each call one update, as iSAM2 runs: in the Graph-SLAM
    /// engine's ten-lap walk (posegraph/README.md) it re-factored 1.9 % of the nodes per loop
    /// closure instead of about half, leaving the estimate short of the optimum between calls.
    pub max_iterations: usize,
    /// The edge error minimised.
    pub error_model: ErrorModel,
}

impl Default for IncrementalConfig {
    fn default() -> Self {
        Self {
            relinearize_threshold: 0.05,
            wildfire_threshold: 1e-4,
            step_tolerance: 1e-9,
            max_iterations: 100,
            error_model: ErrorModel::LogMap,
        }
    }
}

impl IncrementalConfig {
    /// Checks every setting: thresholds finite and not negative, at least one iteration.
    ///
    /// # Errors
    /// [`InvalidSetting`] naming the first bad setting.
    pub fn validate(&self) -> Result<(), InvalidSetting> {
        InvalidSetting::check(
            self.max_iterations >= 1,
            "IncrementalConfig::max_iterations",
            self.max_iterations as f64,
            "at least 1",
        )?;
        check_tolerances(&[
            (
                "IncrementalConfig::relinearize_threshold",
                self.relinearize_threshold,
            ),
            (
                "IncrementalConfig::wildfire_threshold",
                self.wildfire_threshold,
            ),
            ("IncrementalConfig::step_tolerance", self.step_tolerance),
        ])
    }
}

/// Incremental smoothing of a growing pose graph (iSAM2's scheme on a sparse Cholesky factor):
/// the graph's linear system is kept factored between calls; an update
///
/// 1. relinearises only the nodes whose pending step exceeds
///    [`IncrementalConfig::relinearize_threshold`] (fluid relinearisation, Alg. 6 of the paper),
/// 2. takes in the new nodes and edges,
/// 3. re-orders and re-factors only the nodes whose rows of the system changed and their
///    ancestors in the elimination tree (the part of the Bayes tree above them; the newest nodes
///    are eliminated last so that the next odometry step touches little), keeping every other
///    column of the factor,
/// 4. back-substitutes from the root down, solving a node's step again only where the factor
///    changed or a step above it moved by more than [`IncrementalConfig::wildfire_threshold`],
///    and writes `linearisation point (+) step` into those nodes of the graph.
///
/// A loop closure thus costs the cycle it closes (the path from its old end to the root), not
/// the whole graph. [`Optimizer::optimize`] takes in what is new and then repeats updates until
/// no step exceeds [`IncrementalConfig::step_tolerance`] (Gauss-Newton on the relinearised
/// nodes), which reaches the batch solvers' optimum.
///
/// Robust kernels enter as IRLS weights taken when an edge is linearised. Between calls the
/// graph may only grow (another graph makes it start afresh, counted in
/// [`SmootherStatistics::restarts`]); the poses of the nodes it has seen are its own: it writes
/// every free node at each call. The Graph-SLAM engine's graph only grows, so it can be the
/// engine's optimiser; but it does not reject a wrong loop, which the engine's default
/// (graduated non-convexity) does.
///
/// When not to use it: for a single solve of a whole graph (use
/// [`LevenbergMarquardt`](crate::LevenbergMarquardt): Gauss-Newton here has no damping), or for
/// graphs that must reject wrong loops (use [`GraduatedNonConvexity`](crate::GraduatedNonConvexity)).
///
/// ```
/// use posegraph::IncrementalSmoother;
/// use slam_core::{GraphPose, IncrementalOptimizer, Optimizer, PoseGraph, Pose2};
///
/// let info = Pose2::identity_information();
/// let step = Pose2::new([1.0, 0.0].into(), 0.0);
/// let mut g = PoseGraph::<Pose2>::new();
/// g.add_node(0, Pose2::identity())?;
/// g.fix(0)?;
/// let mut smoother = IncrementalSmoother::default();
/// for i in 1..3u64 {
///     // Odometry: each new pose guessed one step on.
///     g.add_node(i, Pose2::new([i as f64, 0.0].into(), 0.0))?;
///     g.add_edge(i - 1, i, step, info, None)?;
///     smoother.update(&mut g)?;
/// }
/// // A loop edge that disagrees by 0.3 m: the update re-factors the nodes it touches.
/// g.add_edge(0, 2, Pose2::new([2.3, 0.0].into(), 0.0), info, None)?;
/// let report = smoother.update(&mut g)?;
/// assert_eq!(report.new_edges, 1);
/// // Converged, the 0.3 m are shared equally by the three edges: 3 * 0.1^2.
/// let done = smoother.optimize(&mut g)?;
/// assert!((done.final_cost - 0.03).abs() < 1e-9);
/// # Ok::<(), slam_core::OptimizeError>(())
/// ```
#[derive(Default)]
pub struct IncrementalSmoother {
    /// Settings.
    pub config: IncrementalConfig,
    se2: Option<Smoother<Pose2, 3>>,
    se3: Option<Smoother<Pose3, 6>>,
    statistics: SmootherStatistics,
}

/// What an [`IncrementalSmoother`] has done since it was made, summed over both pose types:
/// whether a caller's graph kept it incremental (`restarts` stays 0 while the graph only grows)
/// and what share of the factor its updates redid (`refactored / variables`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SmootherStatistics {
    /// Calls of [`Optimizer::optimize`].
    pub optimizations: usize,
    /// Updates run: one per [`IncrementalOptimizer::update`], one or more per
    /// [`Optimizer::optimize`].
    pub updates: usize,
    /// Times the state was thrown away with nodes in it, so that the next update factored the
    /// whole graph again: a graph that did not only grow (an edge's ends or a fixed flag
    /// changed, fewer nodes or edges), or an error. [`IncrementalOptimizer::reset`] is not
    /// counted.
    pub restarts: usize,
    /// Free nodes re-factored, summed over the updates.
    pub refactored: usize,
    /// Free nodes in the graph, summed over the updates.
    pub variables: usize,
}

/// The settings only (the state's size follows the graph).
impl std::fmt::Debug for IncrementalSmoother {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("IncrementalSmoother")
            .field("config", &self.config)
            .finish_non_exhaustive()
    }
}

impl IncrementalSmoother {
    /// What it has done so far.
    #[must_use]
    pub fn statistics(&self) -> SmootherStatistics {
        self.statistics
    }

    /// A smoother with `config`.
    ///
    /// # Errors
    /// [`InvalidSetting`] naming the first bad setting.
    pub fn try_new(config: IncrementalConfig) -> Result<Self, InvalidSetting> {
        config.validate()?;
        Ok(Self {
            config,
            se2: None,
            se3: None,
            statistics: SmootherStatistics::default(),
        })
    }
}

/// The state for one pose type.
struct Smoother<P, const D: usize> {
    /// Each node's fixed flag and each edge's ends as seen: the graph must only grow.
    fixed: Vec<bool>,
    ends: Vec<(usize, usize)>,
    /// Linearisation point and pending step of each node.
    lin: Vec<P>,
    step: Vec<SVector<f64, D>>,
    incident: Vec<Vec<usize>>,
    /// Each edge's `h = J_b^T W J_b` and `J_b^T W e` at its linearisation point.
    edge_h: Vec<SMatrix<f64, D, D>>,
    edge_g: Vec<SVector<f64, D>>,
    system: BlockSystem<D>,
    factor: BlockFactor<D>,
    /// Scratch marker per node and per edge.
    node_mark: Vec<usize>,
    edge_mark: Vec<usize>,
    clock: usize,
}

/// How many of the newest variables an update may force to the end of the order (beyond that,
/// as when a whole graph arrives at once, all are ordered by minimum degree).
const MAX_CONSTRAINED: usize = 16;

impl<P: Linearize<D>, const D: usize> Smoother<P, D> {
    fn new() -> Self {
        Self {
            fixed: Vec::new(),
            ends: Vec::new(),
            lin: Vec::new(),
            step: Vec::new(),
            incident: Vec::new(),
            edge_h: Vec::new(),
            edge_g: Vec::new(),
            system: BlockSystem::new(),
            factor: BlockFactor::new(),
            node_mark: Vec::new(),
            edge_mark: Vec::new(),
            clock: 0,
        }
    }

    /// Whether `graph` is the graph seen so far, grown.
    fn continues(&self, graph: &PoseGraph<P>) -> bool {
        grows_from(&self.fixed, &self.ends, graph)
    }

    /// Refuse non-finite new poses and new edges whose error is not finite at the estimate.
    fn check_new(&self, graph: &PoseGraph<P>, model: ErrorModel) -> Result<(), OptimizeError> {
        let nodes = graph.nodes();
        if let Some(n) = nodes[self.fixed.len()..]
            .iter()
            .find(|n| !n.pose.is_finite())
        {
            return Err(OptimizeError::NonFinite {
                what: GraphValue::NodePose { id: n.id },
            });
        }
        let poses: Vec<P> = nodes.iter().map(|n| n.pose).collect();
        for (k, e) in graph.edges().iter().enumerate().skip(self.ends.len()) {
            if !chi2(e, &poses, model).is_finite() {
                return Err(OptimizeError::NonFinite {
                    what: GraphValue::EdgeError {
                        edge: k,
                        from: nodes[e.from].id,
                        to: nodes[e.to].id,
                    },
                });
            }
        }
        Ok(())
    }

    /// One update (see [`IncrementalSmoother`]); relinearises above `threshold`, solves again
    /// the steps below one that moved by more than `wildfire` (`None`: every step).
    fn update(
        &mut self,
        graph: &mut PoseGraph<P>,
        model: ErrorModel,
        threshold: f64,
        wildfire: Option<f64>,
        statistics: &mut SmootherStatistics,
    ) -> Result<IncrementalReport, OptimizeError> {
        if !self.continues(graph) {
            *self = Self::new();
            statistics.restarts += 1;
        }
        graph.check_gauge()?;
        self.check_new(graph, model)?;
        let (n0, m0) = (self.fixed.len(), self.ends.len());
        let (n, m) = (graph.node_count(), graph.edge_count());
        self.clock += 1;
        let mark = self.clock;
        let (mut dirty_edges, relinearized) = self.relinearize(threshold, mark);
        self.take_in(graph, mark, &mut dirty_edges);
        // Relinearise the dirty edges; rebuild the rows of the nodes they touch.
        let edges = graph.edges();
        let mut touched = Vec::new();
        for v in n0..n {
            if !self.fixed[v] {
                self.node_mark[v] = mark;
                touched.push(v);
            }
        }
        for &k in &dirty_edges {
            let e = &edges[k];
            let (a, b) = (self.lin[e.from], self.lin[e.to]);
            let (err, jb) = P::linearize(model, &e.measurement, &a, &b);
            let mut omega = P::info(&e.information);
            if let Some(kernel) = e.kernel {
                omega *= kernel.weight((err.transpose() * omega * err)[0]);
            }
            let jt = jb.transpose();
            self.edge_h[k] = jt * omega * jb;
            self.edge_g[k] = jt * (omega * err);
            for v in [e.from, e.to] {
                if !self.fixed[v] && self.node_mark[v] != mark {
                    self.node_mark[v] = mark;
                    touched.push(v);
                }
            }
        }
        for &v in &touched {
            self.rebuild_row(v);
        }
        // The newest variables go last: the next odometry step then touches only them.
        let mut last: Vec<usize> = edges[m0..]
            .iter()
            .flat_map(|e| [e.from, e.to])
            .chain(n0..n)
            .filter(|&v| !self.fixed[v])
            .collect();
        last.sort_unstable();
        last.dedup();
        if last.len() > MAX_CONSTRAINED {
            last.clear();
        }
        // Partial re-elimination, then the whole back substitution.
        // (On an error the caller drops this state: the next call starts afresh.)
        let refactored = self
            .factor
            .refactor(&self.system, &touched, &last)
            .map_err(|_| OptimizeError::Factorization {
                stage: "incremental Cholesky",
                cause: FactorizationFailure::NotPositiveDefinite,
            })?;
        let mut solved = Vec::new();
        self.factor.solve(&mut self.step, wildfire, &mut solved);
        if solved
            .iter()
            .any(|&v| !self.step[v].iter().all(|x| x.is_finite()))
        {
            return Err(OptimizeError::Factorization {
                stage: "incremental solve",
                cause: FactorizationFailure::NonFiniteSolution,
            });
        }
        for &v in &solved {
            graph.set_pose(v, self.lin[v].retract(&self.step[v]));
        }
        let variables = self.fixed.iter().filter(|&&f| !f).count();
        statistics.updates += 1;
        statistics.refactored += refactored;
        statistics.variables += variables;
        Ok(IncrementalReport {
            new_nodes: n - n0,
            new_edges: m - m0,
            relinearized,
            refactored,
            variables,
        })
    }

    /// Fluid relinearisation: every free node whose pending step exceeds `threshold` moves its
    /// linearisation point by it. Returns the edges at those nodes (marked `mark`) and how many
    /// nodes moved.
    fn relinearize(&mut self, threshold: f64, mark: usize) -> (Vec<usize>, usize) {
        let mut dirty_edges = Vec::new();
        let mut relinearized = 0;
        for v in 0..self.fixed.len() {
            if !self.fixed[v] && self.step[v].amax() > threshold {
                // The step stays as it was until the solve replaces it: the wildfire compares
                // against it (the descendants' steps were computed from it).
                self.lin[v] = self.lin[v].retract(&self.step[v]);
                relinearized += 1;
                for &k in &self.incident[v] {
                    if self.edge_mark[k] != mark {
                        self.edge_mark[k] = mark;
                        dirty_edges.push(k);
                    }
                }
            }
        }
        (dirty_edges, relinearized)
    }

    /// Take in the nodes and edges of `graph` not seen yet (the new edges join `dirty_edges`).
    fn take_in(&mut self, graph: &PoseGraph<P>, mark: usize, dirty_edges: &mut Vec<usize>) {
        let (n0, m0) = (self.fixed.len(), self.ends.len());
        let n = graph.node_count();
        for node in &graph.nodes()[n0..] {
            self.fixed.push(node.fixed);
            self.lin.push(node.pose);
            self.step.push(SVector::zeros());
            self.incident.push(Vec::new());
            self.node_mark.push(0);
        }
        self.system.grow(n);
        self.factor.grow(n);
        for (k, e) in graph.edges().iter().enumerate().skip(m0) {
            self.ends.push((e.from, e.to));
            self.incident[e.from].push(k);
            self.incident[e.to].push(k);
            self.edge_h.push(SMatrix::zeros());
            self.edge_g.push(SVector::zeros());
            self.edge_mark.push(mark);
            dirty_edges.push(k);
        }
    }

    /// `H_vv`, `g_v` and `H_wv` of free node `v` from its edges' stored blocks.
    fn rebuild_row(&mut self, v: usize) {
        let mut diagonal = SMatrix::<f64, D, D>::zeros();
        let mut gradient = SVector::<f64, D>::zeros();
        let mut off = std::mem::take(&mut self.system.off[v]);
        off.clear();
        for &k in &self.incident[v] {
            let (a, b) = self.ends[k];
            let (h, g) = (self.edge_h[k], self.edge_g[k]);
            diagonal += h;
            // J_a = -J_b: the gradient's sign follows the end, the coupling block is -h.
            let w = if v == b {
                gradient += g;
                a
            } else {
                gradient -= g;
                b
            };
            if self.fixed[w] {
                continue;
            }
            match off.iter_mut().find(|(x, _)| *x == w) {
                Some((_, block)) => *block -= h,
                None => off.push((w, -h)),
            }
        }
        self.system.diagonal[v] = diagonal;
        self.system.gradient[v] = gradient;
        self.system.off[v] = off;
    }

    /// Updates until no step component exceeds `config.step_tolerance`.
    fn optimize(
        &mut self,
        graph: &mut PoseGraph<P>,
        config: &IncrementalConfig,
        statistics: &mut SmootherStatistics,
    ) -> Result<OptimizationReport, OptimizeError> {
        let model = config.error_model;
        graph.check_gauge()?;
        self.check_new(graph, model)?;
        let start: Vec<P> = graph.nodes().iter().map(|n| n.pose).collect();
        let initial_cost = cost_with(graph, &start, model, None, 1.0);
        let mut iterations = 1;
        // Every step solved: the stop test must not read a step the wildfire left behind.
        self.update(graph, model, config.relinearize_threshold, None, statistics)?;
        let mut stop = StopReason::MaxIterations;
        loop {
            let largest = self
                .step
                .iter()
                .map(nalgebra::Matrix::amax)
                .fold(0.0, f64::max);
            if largest <= config.step_tolerance {
                stop = StopReason::StepConverged;
                break;
            }
            if iterations >= config.max_iterations {
                break;
            }
            self.update(graph, model, config.step_tolerance, None, statistics)?;
            iterations += 1;
        }
        let poses: Vec<P> = graph.nodes().iter().map(|n| n.pose).collect();
        Ok(OptimizationReport {
            iterations,
            initial_cost,
            final_cost: cost_with(graph, &poses, model, None, 1.0),
            stop_reason: stop,
        })
    }
}

/// After an error the state is dropped (the next call starts afresh): a restart when it held
/// nodes.
fn drop_after_error<P, const D: usize>(
    slot: &mut Option<Smoother<P, D>>,
    statistics: &mut SmootherStatistics,
) {
    if slot.take().is_some_and(|s| !s.fixed.is_empty()) {
        statistics.restarts += 1;
    }
}

/// [`Optimizer`] and [`IncrementalOptimizer`] for a pose type with its state slot.
macro_rules! smoother_for {
    ($pose:ty, $slot:ident) => {
        impl Optimizer<$pose> for IncrementalSmoother {
            fn optimize(
                &mut self,
                graph: &mut PoseGraph<$pose>,
            ) -> Result<OptimizationReport, OptimizeError> {
                let config = self.config;
                self.statistics.optimizations += 1;
                let result = self.$slot.get_or_insert_with(Smoother::new).optimize(
                    graph,
                    &config,
                    &mut self.statistics,
                );
                if result.is_err() {
                    drop_after_error(&mut self.$slot, &mut self.statistics);
                }
                result
            }
        }

        impl IncrementalOptimizer<$pose> for IncrementalSmoother {
            fn update(
                &mut self,
                graph: &mut PoseGraph<$pose>,
            ) -> Result<IncrementalReport, OptimizeError> {
                let config = self.config;
                let result = self.$slot.get_or_insert_with(Smoother::new).update(
                    graph,
                    config.error_model,
                    config.relinearize_threshold,
                    Some(config.wildfire_threshold),
                    &mut self.statistics,
                );
                if result.is_err() {
                    drop_after_error(&mut self.$slot, &mut self.statistics);
                }
                result
            }

            fn reset(&mut self) {
                self.$slot = None;
            }
        }
    };
}

smoother_for!(Pose2, se2);
smoother_for!(Pose3, se3);
