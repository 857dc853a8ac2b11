//! Optimise a g2o (or TORO `.graph`) pose graph and print nodes, edges, iterations, initial and
//! final cost in both conventions (log-map `sum e^T Omega e`, and g2o's own chi2) and milliseconds.
//!
//! `cargo run --release --example g2o -- FILE [--optimizer gn|lm] [--init file|chordal]
//! [--error logmap|g2o] [--robust none|gnc] [--repair-information] [--out OUT.g2o]`
//!
//! `--robust gnc` optimises with graduated non-convexity (truncated least squares; odometry, the
//! edges between consecutive ids, as known inliers; its inner solver is always LM) and prints how
//! many edges it weighted out; `--out` then writes the graph without them.
//! The first node is fixed when the file fixes none. `--init chordal` replaces the file's initial
//! guess by the chordal initialisation before optimising (its time is included). `--error g2o`
//! minimises g2o's error convention instead of the log map (GTSAM's). Information matrices that are
//! not positive definite are refused unless `--repair-information` replaces each by the nearest
//! positive-definite matrix (eigenvalues clipped to 1e-6 of the largest) and counts them. Exits with status 1 when the
//! optimiser stopped at its iteration cap (the figures are printed, and `--out` written, first).

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::{Parser, ValueEnum};
use posegraph::g2o::{G2oGraph, g2o_chi2, read_g2o_with, write_g2o};
use posegraph::information_repair::{InformationRepair, RepairedEdge};
use posegraph::toro::read_toro;
use posegraph::{
    ChordalInitialization, ErrorModel, GaussNewton, GncConfig, GraduatedNonConvexity,
    LevenbergMarquardt, SolverConfig, SolverPose,
};
use slam_core::{GraphPose, OptimizationReport, Optimizer, Pose2, Pose3, PoseGraph, StopReason};
use spot_nav_examples::{out, value_name};

/// Optimise a g2o or TORO pose graph and print its cost before and after, and the time.
///
/// Reads g2o (SE(2) or SE(3)) or TORO `.graph` files; prints the graph's size, the optimiser's
/// iterations and stop reason, the cost before and after in both conventions (the log map's
/// `sum e^T Omega e` and g2o's chi2), and the milliseconds.
///
/// The first node is fixed when the file fixes none. `--robust gnc` weights out wrong loop
/// closures (graduated non-convexity) and prints how many. Fails when the optimiser stopped at
/// its iteration cap (after printing the figures and writing `--out`).
#[derive(Debug, Parser)]
#[command(name = "g2o")]
struct Args {
    /// The pose graph: g2o (`VERTEX_SE3:QUAT`, `EDGE_SE3:QUAT`, `VERTEX_SE2`, `EDGE_SE2`, `FIX`)
    /// or TORO (`.graph`).
    #[arg(value_name = "FILE")]
    file: PathBuf,
    /// The optimiser.
    #[arg(long, value_enum, default_value_t = OptimizerChoice::LevenbergMarquardt)]
    optimizer: OptimizerChoice,
    /// Where the optimisation starts (the chordal initialisation's time is included).
    #[arg(long, value_enum, default_value_t = Init::File)]
    init: Init,
    /// The error convention minimised.
    #[arg(long, value_enum, default_value_t = ErrorChoice::LogMap)]
    error: ErrorChoice,
    /// Outlier-robust optimisation: `gnc` weights out wrong loop closures (graduated
    /// non-convexity with truncated least squares over LM; `--optimizer` is then unused).
    #[arg(long, value_enum, default_value_t = Robust::None)]
    robust: Robust,
    /// Write the optimised graph here (g2o; with `--robust gnc` without the edges weighted out).
    #[arg(long, value_name = "OUT.g2o")]
    out: Option<PathBuf>,
    /// Replace information matrices that are not positive definite by the nearest
    /// positive-definite matrix (eigenvalues clipped to 1e-6 of the largest) instead of refusing
    /// the file, and print how many edges changed (g2o files only).
    #[arg(long)]
    repair_information: bool,
}

/// `--optimizer`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum OptimizerChoice {
    /// Gauss-Newton.
    #[value(name = "gn")]
    GaussNewton,
    /// Levenberg-Marquardt.
    #[value(name = "lm")]
    LevenbergMarquardt,
}

/// `--init`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Init {
    /// The file's own initial guess.
    #[value(name = "file")]
    File,
    /// The chordal initialisation (rotations by the chordal relaxation, then translations).
    #[value(name = "chordal")]
    Chordal,
}

/// `--robust`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Robust {
    /// Plain least squares (the file's robust kernels, if any, apply).
    #[value(name = "none")]
    None,
    /// Graduated non-convexity (Yang et al., RA-L 2020), truncated least squares, odometry as
    /// known inliers.
    #[value(name = "gnc")]
    Gnc,
}

/// `--error`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum ErrorChoice {
    /// The log map of the relative pose error (GTSAM's `BetweenFactor`).
    #[value(name = "logmap")]
    LogMap,
    /// g2o's `[t; q_xyz]` (3D) or `[x, y, theta]` (2D) error.
    #[value(name = "g2o")]
    G2o,
}

fn main() -> ExitCode {
    spot_nav_examples::run(|| optimise(&Args::parse()))
}

fn fix_first<P: GraphPose>(g: &mut PoseGraph<P>) -> Result<()> {
    if !g.nodes().iter().any(|n| n.fixed) {
        let id = g.nodes().first().context("the graph has no nodes")?.id;
        g.fix(id)?;
    }
    Ok(())
}

fn run<P, O>(g: &mut PoseGraph<P>, optimizer: &mut O, chordal: bool) -> Result<OptimizationReport>
where
    P: ChordalInitialization,
    O: Optimizer<P>,
{
    fix_first(g)?;
    if chordal {
        P::initialize_chordal(g)?;
    }
    Ok(optimizer.optimize(g)?)
}

/// Graduated non-convexity on `g`; returns the report and the number of edges weighted out, and
/// drops those edges from `g` (for `--out`).
fn run_gnc<P>(
    g: &mut PoseGraph<P>,
    config: SolverConfig,
    chordal: bool,
) -> Result<(OptimizationReport, usize)>
where
    P: ChordalInitialization + SolverPose,
    GraduatedNonConvexity: Optimizer<P>,
{
    let mut gnc = GraduatedNonConvexity::try_new(GncConfig {
        solver: config,
        ..GncConfig::default()
    })?;
    let report = run(g, &mut gnc, chordal)?;
    let weights = gnc.weights();
    let rejected = weights.iter().filter(|&&w| w < 0.5).count();
    let mut kept = PoseGraph::new();
    for n in g.nodes() {
        kept.add_node(n.id, n.pose)?;
        if n.fixed {
            kept.fix(n.id)?;
        }
    }
    for (e, &w) in g.edges().iter().zip(weights) {
        if w >= 0.5 {
            let (a, b) = (g.nodes()[e.from].id, g.nodes()[e.to].id);
            kept.add_edge(a, b, e.measurement, e.information, e.kernel)?;
        }
    }
    *g = kept;
    Ok((report, rejected))
}

/// The graph of `args.file` (TORO when `is_toro`) and the edges whose information was repaired.
fn read(args: &Args, is_toro: bool) -> Result<(G2oGraph, Vec<RepairedEdge>)> {
    let file = &args.file;
    if is_toro && args.repair_information {
        bail!("--repair-information applies to g2o files, not TORO");
    }
    let repair = if args.repair_information {
        InformationRepair::nearest_positive_definite()
    } else {
        InformationRepair::Refuse
    };
    Ok(if is_toro {
        (G2oGraph::Se2(read_toro(file)?), Vec::new())
    } else {
        read_g2o_with(file, repair).with_context(|| format!("reading {}", file.display()))?
    })
}

/// The `repaired` line: how many of `edges` edges' information changed, and the largest change.
fn print_repairs(repaired: &[RepairedEdge], edges: usize) -> Result<()> {
    let largest = repaired
        .iter()
        .map(|r| r.relative_change)
        .fold(0.0, f64::max);
    out!(
        "repaired    {} of {edges} edges' information (nearest positive definite; largest change {:.1} % of a matrix)",
        repaired.len(),
        100.0 * largest
    )?;
    Ok(())
}

fn optimise(args: &Args) -> Result<()> {
    let file = &args.file;
    let is_toro = file
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("graph"));
    let (mut graph, repaired) = read(args, is_toro)?;
    let (nodes, edges) = match &graph {
        G2oGraph::Se2(g) => (g.node_count(), g.edge_count()),
        G2oGraph::Se3(g) => (g.node_count(), g.edge_count()),
    };
    let chordal = args.init == Init::Chordal;
    let config = SolverConfig {
        error_model: match args.error {
            ErrorChoice::LogMap => ErrorModel::LogMap,
            ErrorChoice::G2o => ErrorModel::G2o,
        },
        ..SolverConfig::default()
    };
    let g2o_before = g2o_chi2(&graph);
    let t = Instant::now();
    let mut rejected = None;
    let report = match (&mut graph, args.robust, args.optimizer) {
        (G2oGraph::Se3(g), Robust::Gnc, _) => {
            let (r, n) = run_gnc::<Pose3>(g, config, chordal)?;
            rejected = Some(n);
            r
        }
        (G2oGraph::Se2(g), Robust::Gnc, _) => {
            let (r, n) = run_gnc::<Pose2>(g, config, chordal)?;
            rejected = Some(n);
            r
        }
        (G2oGraph::Se3(g), Robust::None, OptimizerChoice::LevenbergMarquardt) => {
            run::<Pose3, _>(g, &mut LevenbergMarquardt::new(config), chordal)?
        }
        (G2oGraph::Se3(g), Robust::None, OptimizerChoice::GaussNewton) => {
            run::<Pose3, _>(g, &mut GaussNewton::new(config), chordal)?
        }
        (G2oGraph::Se2(g), Robust::None, OptimizerChoice::LevenbergMarquardt) => {
            run::<Pose2, _>(g, &mut LevenbergMarquardt::new(config), chordal)?
        }
        (G2oGraph::Se2(g), Robust::None, OptimizerChoice::GaussNewton) => {
            run::<Pose2, _>(g, &mut GaussNewton::new(config), chordal)?
        }
    };
    let ms = t.elapsed().as_secs_f64() * 1e3;
    out!("file        {}", file.display())?;
    out!(
        "graph       {nodes} nodes, {edges} edges ({})",
        if matches!(graph, G2oGraph::Se3(_)) {
            "SE(3)"
        } else {
            "SE(2)"
        }
    )?;
    if args.repair_information {
        print_repairs(&repaired, edges)?;
    }
    let method = match args.robust {
        Robust::None => value_name(&args.optimizer),
        Robust::Gnc => value_name(&args.robust),
    };
    out!(
        "optimizer   {method} from the {} guess: {} iterations, {:?}",
        value_name(&args.init),
        report.iterations,
        report.stop_reason
    )?;
    if let Some(n) = rejected {
        out!(
            "robust      {n} of {edges} edges weighted out (graduated non-convexity, TLS); the costs after are over the edges kept"
        )?;
    }
    out!(
        "minimised   {} cost {:.6} -> {:.6} (from the --init guess)",
        value_name(&args.error),
        report.initial_cost,
        report.final_cost
    )?;
    let log_map = match &graph {
        G2oGraph::Se2(g) => g.cost(),
        G2oGraph::Se3(g) => g.cost(),
    };
    out!("log-map     {log_map:.6} (GTSAM's error is half of this)")?;
    out!("g2o chi2    {g2o_before:.6} -> {:.6}", g2o_chi2(&graph))?;
    out!("time        {ms:.1} ms")?;
    if let Some(path) = &args.out {
        write_g2o(path, &graph)?;
        out!("wrote       {}", path.display())?;
    }
    if report.stop_reason == StopReason::MaxIterations {
        bail!(
            "the optimiser stopped at its iteration cap ({} iterations) without converging",
            report.iterations
        );
    }
    Ok(())
}
