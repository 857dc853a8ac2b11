//! Pose graphs: `read_g2o`, `read_toro`, `write_g2o`, `optimize` and its report.

use std::path::PathBuf;

use numpy::PyArray2;
use posegraph::g2o::{G2oGraph, g2o_chi2};
use posegraph::{
    ErrorModel, GaussNewton, GncConfig, GncLoss, GraduatedNonConvexity, KnownInliers,
    LevenbergMarquardt, SolverConfig, SolverPose,
};
use pyo3::prelude::*;
use slam_core::{OptimizationReport, OptimizeError, Optimizer, PoseGraph, StopReason};

use crate::arrays::{poses_to, row_major};
use crate::error::{ToPyErr, invalid, py_result};

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Graph>()?;
    m.add_class::<OptimizeReport>()?;
    m.add_function(wrap_pyfunction!(read_g2o, m)?)?;
    m.add_function(wrap_pyfunction!(read_toro, m)?)?;
    m.add_function(wrap_pyfunction!(write_g2o, m)?)?;
    m.add_function(wrap_pyfunction!(optimize, m)?)?;
    Ok(())
}

/// A pose graph read from a file: SE(2) (`dimension == 2`) or SE(3).
#[pyclass(name = "PoseGraph", module = "spot_nav")]
pub(crate) struct Graph {
    inner: G2oGraph,
}

#[pymethods]
impl Graph {
    /// 2 for SE(2) graphs (`VERTEX_SE2`, TORO), 3 for SE(3).
    #[getter]
    fn dimension(&self) -> u8 {
        match self.inner {
            G2oGraph::Se2(_) => 2,
            G2oGraph::Se3(_) => 3,
        }
    }

    /// Number of nodes.
    #[getter]
    fn node_count(&self) -> usize {
        match &self.inner {
            G2oGraph::Se2(g) => g.node_count(),
            G2oGraph::Se3(g) => g.node_count(),
        }
    }

    /// Number of edges.
    #[getter]
    fn edge_count(&self) -> usize {
        match &self.inner {
            G2oGraph::Se2(g) => g.edge_count(),
            G2oGraph::Se3(g) => g.edge_count(),
        }
    }

    /// The node ids, in node order.
    #[getter]
    fn ids(&self) -> Vec<u64> {
        match &self.inner {
            G2oGraph::Se2(g) => g.nodes().iter().map(|n| n.id).collect(),
            G2oGraph::Se3(g) => g.nodes().iter().map(|n| n.id).collect(),
        }
    }

    /// The edges as `(from_id, to_id)`, in edge order (the order of `optimize`'s weights).
    #[getter]
    fn edges(&self) -> Vec<(u64, u64)> {
        fn ids<P: slam_core::GraphPose>(g: &PoseGraph<P>) -> Vec<(u64, u64)> {
            g.edges()
                .iter()
                .map(|e| (g.nodes()[e.from].id, g.nodes()[e.to].id))
                .collect()
        }
        match &self.inner {
            G2oGraph::Se2(g) => ids(g),
            G2oGraph::Se3(g) => ids(g),
        }
    }

    /// Node poses: `N x 4 x 4` (SE(3)), or `N x 3` rows of `x, y, theta` (SE(2)).
    #[getter]
    fn poses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        match &self.inner {
            G2oGraph::Se3(g) => poses_to(py, g.nodes().iter().map(|n| n.pose)),
            G2oGraph::Se2(g) => {
                let flat: Vec<f64> = g
                    .nodes()
                    .iter()
                    .flat_map(|n| {
                        let t = n.pose.translation.vector;
                        [t.x, t.y, n.pose.rotation.angle()]
                    })
                    .collect();
                let a: Bound<'py, PyArray2<f64>> = row_major(py, &flat, g.node_count(), 3);
                Ok(a.into_any())
            }
        }
    }

    /// Hold node `id` fixed while optimising (TORO files cannot say so; g2o files use `FIX`).
    fn fix(&mut self, id: u64) -> PyResult<()> {
        py_result(match &mut self.inner {
            G2oGraph::Se2(g) => g.fix(id),
            G2oGraph::Se3(g) => g.fix(id),
        })
    }

    /// The cost `sum e^T Omega e` with the log-map error (what `optimize` minimises by default).
    fn cost(&self) -> f64 {
        match &self.inner {
            G2oGraph::Se2(g) => g.cost(),
            G2oGraph::Se3(g) => g.cost(),
        }
    }

    /// The cost in g2o's own error convention (g2o's reported chi2).
    fn chi2(&self) -> f64 {
        g2o_chi2(&self.inner)
    }

    fn __repr__(&self) -> String {
        format!(
            "PoseGraph(dimension={}, nodes={}, edges={})",
            self.dimension(),
            self.node_count(),
            self.edge_count()
        )
    }
}

/// Read a g2o file (`VERTEX_SE2`/`EDGE_SE2` or `VERTEX_SE3:QUAT`/`EDGE_SE3:QUAT`, `FIX`).
#[pyfunction]
// PyO3 extracts a path argument as an owned `PathBuf`.
#[allow(clippy::needless_pass_by_value)]
fn read_g2o(py: Python<'_>, path: PathBuf) -> PyResult<Graph> {
    let g = py_result(py.detach(|| posegraph::g2o::read_g2o(&path)))?;
    Ok(Graph { inner: g })
}

/// Read a TORO file (`VERTEX2`/`EDGE2`): an SE(2) graph.
#[pyfunction]
// PyO3 extracts a path argument as an owned `PathBuf`.
#[allow(clippy::needless_pass_by_value)]
fn read_toro(py: Python<'_>, path: PathBuf) -> PyResult<Graph> {
    let g = py_result(py.detach(|| posegraph::toro::read_toro(&path)))?;
    Ok(Graph {
        inner: G2oGraph::Se2(g),
    })
}

/// Write `graph` as a g2o file.
#[pyfunction]
// PyO3 extracts a path argument as an owned `PathBuf`.
#[allow(clippy::needless_pass_by_value)]
fn write_g2o(py: Python<'_>, graph: &Bound<'_, Graph>, path: PathBuf) -> PyResult<()> {
    let g = graph.borrow();
    let inner = &g.inner;
    py_result(py.detach(|| posegraph::g2o::write_g2o(&path, inner)))
}

/// What `optimize` did.
#[pyclass(frozen, get_all, module = "spot_nav")]
pub(crate) struct OptimizeReport {
    /// Iterations run (GNC: inner iterations over every outer one).
    iterations: usize,
    /// Cost before.
    initial_cost: f64,
    /// Cost after.
    final_cost: f64,
    /// Why it stopped: "cost_converged", "step_converged", "max_iterations",
    /// "damping_exhausted" or "nothing_to_do".
    stop_reason: &'static str,
    /// GNC only: each edge's final weight (0: rejected), in edge order; `None` otherwise.
    weights: Option<Vec<f64>>,
    /// GNC only: edges rejected (weight 0); 0 otherwise.
    rejected: usize,
}

#[pymethods]
impl OptimizeReport {
    fn __repr__(&self) -> String {
        format!(
            "OptimizeReport(iterations={}, initial_cost={:.6e}, final_cost={:.6e}, stop_reason={:?}, rejected={})",
            self.iterations, self.initial_cost, self.final_cost, self.stop_reason, self.rejected
        )
    }
}

fn stop_name(r: StopReason) -> &'static str {
    match r {
        StopReason::CostConverged => "cost_converged",
        StopReason::StepConverged => "step_converged",
        StopReason::MaxIterations => "max_iterations",
        StopReason::DampingExhausted => "damping_exhausted",
        StopReason::NothingToDo => "nothing_to_do",
        _ => "other",
    }
}

fn plain(r: OptimizationReport) -> OptimizeReport {
    OptimizeReport {
        iterations: r.iterations,
        initial_cost: r.initial_cost,
        final_cost: r.final_cost,
        stop_reason: stop_name(r.stop_reason),
        weights: None,
        rejected: 0,
    }
}

/// The optimiser `optimize` runs.
enum Method {
    GaussNewton(GaussNewton),
    LevenbergMarquardt(LevenbergMarquardt),
    Gnc(Box<GraduatedNonConvexity>),
}

fn run<P: SolverPose>(
    method: &mut Method,
    graph: &mut PoseGraph<P>,
) -> Result<OptimizeReport, OptimizeError> {
    match method {
        Method::GaussNewton(o) => o.optimize(graph).map(plain),
        Method::LevenbergMarquardt(o) => o.optimize(graph).map(plain),
        Method::Gnc(o) => o.optimize_robust(graph).map(|r| OptimizeReport {
            rejected: r.rejected,
            weights: Some(r.weights),
            ..plain(r.optimization)
        }),
    }
}

/// Optimise `graph` in place and return the report.
///
/// `method`: "lm" (Levenberg-Marquardt, default), "gn" (Gauss-Newton) or "gnc" (graduated
/// non-convexity over LM: outlier loops weighted out). `error_model`: "log_map" (default) or
/// "g2o". GNC: `loss` "tls" | "geman_mcclure", `known_inliers` "consecutive_ids" |
/// "without_kernel", `inlier_probability`.
#[pyfunction]
#[pyo3(signature = (graph, method = "lm", *, max_iterations = 100, relative_cost_tolerance = 1e-6, step_tolerance = 1e-10, error_model = "log_map", loss = "tls", known_inliers = "consecutive_ids", inlier_probability = None))]
#[allow(clippy::too_many_arguments)]
fn optimize(
    py: Python<'_>,
    graph: &Bound<'_, Graph>,
    method: &str,
    max_iterations: usize,
    relative_cost_tolerance: f64,
    step_tolerance: f64,
    error_model: &str,
    loss: &str,
    known_inliers: &str,
    inlier_probability: Option<f64>,
) -> PyResult<OptimizeReport> {
    let solver = SolverConfig {
        max_iterations,
        relative_cost_tolerance,
        step_tolerance,
        error_model: match error_model {
            "log_map" => ErrorModel::LogMap,
            "g2o" => ErrorModel::G2o,
            other => {
                return Err(invalid(format!(
                    "unknown error_model {other:?}: use \"log_map\" or \"g2o\""
                )));
            }
        },
    };
    py_result(solver.validate())?;
    let mut method = match method {
        "gn" => Method::GaussNewton(GaussNewton::new(solver)),
        "lm" => Method::LevenbergMarquardt(LevenbergMarquardt::new(solver)),
        "gnc" => {
            let mut c = GncConfig {
                solver,
                ..GncConfig::default()
            };
            c.loss = match loss {
                "tls" => GncLoss::TruncatedLeastSquares,
                "geman_mcclure" => GncLoss::GemanMcClure,
                other => {
                    return Err(invalid(format!(
                        "unknown loss {other:?}: use \"tls\" or \"geman_mcclure\""
                    )));
                }
            };
            c.known_inliers = match known_inliers {
                "consecutive_ids" => KnownInliers::ConsecutiveIds,
                "without_kernel" => KnownInliers::WithoutKernel,
                other => {
                    return Err(invalid(format!(
                        "unknown known_inliers {other:?}: use \"consecutive_ids\" or \"without_kernel\""
                    )));
                }
            };
            if let Some(p) = inlier_probability {
                c.inlier_probability = p;
            }
            Method::Gnc(Box::new(
                GraduatedNonConvexity::try_new(c).map_err(|e| e.to_py())?,
            ))
        }
        other => {
            return Err(invalid(format!(
                "unknown method {other:?}: use \"lm\", \"gn\" or \"gnc\""
            )));
        }
    };
    let mut g = graph.borrow_mut();
    let inner = &mut g.inner;
    py_result(py.detach(|| match inner {
        G2oGraph::Se2(g) => run(&mut method, g),
        G2oGraph::Se3(g) => run(&mut method, g),
    }))
}
