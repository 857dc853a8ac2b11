//! The `Optimizer` trait: optimise a [`PoseGraph`] in place.

use crate::error::OptimizeError;
use crate::pose_graph::{GraphPose, PoseGraph};

/// Why an optimisation stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub enum StopReason {
    /// The relative cost decrease fell below its threshold.
    CostConverged,
    /// The update step fell below its threshold.
    StepConverged,
    /// The iteration cap was reached.
    MaxIterations,
    /// Levenberg-Marquardt's damping grew past its cap without finding a better step.
    DampingExhausted,
    /// Nothing to optimise (every node fixed, or no edges).
    NothingToDo,
}

/// What an optimisation did.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct OptimizationReport {
    /// Iterations run (accepted and rejected steps).
    pub iterations: usize,
    /// Cost before, `sum e^T Omega e` over edges (robust kernels applied).
    pub initial_cost: f64,
    /// Cost after.
    pub final_cost: f64,
    /// Why it stopped.
    pub stop_reason: StopReason,
}

/// A pose-graph optimiser.
///
/// ```
/// use slam_core::{OptimizationReport, OptimizeError, Optimizer, PoseGraph, Pose2, StopReason};
///
/// /// Does nothing: shows the contract.
/// struct Idle;
/// impl Optimizer<Pose2> for Idle {
///     fn optimize(&mut self, graph: &mut PoseGraph<Pose2>) -> Result<OptimizationReport, OptimizeError> {
///         let cost = graph.cost();
///         Ok(OptimizationReport { iterations: 0, initial_cost: cost, final_cost: cost,
///             stop_reason: StopReason::NothingToDo })
///     }
/// }
///
/// let mut graph = PoseGraph::<Pose2>::new();
/// graph.add_node(0, Pose2::identity())?;
/// assert_eq!(Idle.optimize(&mut graph)?.final_cost, 0.0);
/// # Ok::<(), OptimizeError>(())
/// ```
pub trait Optimizer<P: GraphPose> {
    /// Move the free nodes of `graph` to minimise its cost, starting from their current poses.
    ///
    /// # Errors
    /// Invalid graphs (no fixed node, disconnected nodes, bad information) or a factorisation that
    /// cannot be recovered. Stopping at the iteration cap is not an error: see the report.
    fn optimize(&mut self, graph: &mut PoseGraph<P>) -> Result<OptimizationReport, OptimizeError>;

    /// For an optimiser that decides which edges are outliers (graduated non-convexity): the
    /// weight in `[0, 1]` each edge ended the last run with, in [`PoseGraph::edges`] order (below
    /// 0.5: weighted out). `None` (the default) for an optimiser that keeps every edge.
    fn edge_weights(&self) -> Option<&[f64]> {
        None
    }
}

/// What one incremental update did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct IncrementalReport {
    /// Nodes new since the last update.
    pub new_nodes: usize,
    /// Edges new since the last update.
    pub new_edges: usize,
    /// Free nodes whose linearisation point moved (their step exceeded the threshold).
    pub relinearized: usize,
    /// Free nodes whose part of the factor was recomputed (the ones the update affected and all
    /// their ancestors in the elimination tree).
    pub refactored: usize,
    /// Free nodes in the graph.
    pub variables: usize,
}

/// An optimiser that follows a growing [`PoseGraph`]: each call to
/// [`update`](IncrementalOptimizer::update) takes in the nodes and edges appended since the
/// previous call and moves the estimate by redoing only the work they affect (an iSAM2-style
/// smoother), instead of re-solving the whole graph. [`Optimizer::optimize`] on such an
/// optimiser takes in what is new and then iterates to convergence.
///
/// The graph must only grow between calls (nodes and edges appended, no node's fixed flag
/// changed); an implementation that meets another graph starts afresh. The poses of the nodes
/// already seen are the optimiser's: it writes its estimate into every node at each call.
pub trait IncrementalOptimizer<P: GraphPose>: Optimizer<P> {
    /// Take in the nodes and edges appended to `graph` since the last call and update every free
    /// node's pose (one relinearisation and partial re-factorisation step, not a converged
    /// solve).
    ///
    /// # Errors
    /// As [`Optimizer::optimize`]: a new node's pose or a new edge's error that is not finite, a
    /// graph without a gauge, a factorisation that fails. The optimiser's state is then reset
    /// and the next call starts afresh; the graph's poses are left as they were.
    fn update(&mut self, graph: &mut PoseGraph<P>) -> Result<IncrementalReport, OptimizeError>;

    /// Forget everything: the next call starts from the graph's poses as a new graph.
    fn reset(&mut self);
}
