//! Optimise a g2o (or TORO `.graph`) pose graph and print nodes, edges, iterations, initial and
//! final cost in both conventions (log-map `sum e^T Omega e`, and g2o's own chi2) and milliseconds.
//!
//! `cargo run --release --example g2o -- FILE [--optimizer gn|lm] [--init file|chordal]
//! [--error logmap|g2o] [--out OUT.g2o]`
//!
//! The first node is fixed when the file fixes none. `--init chordal` replaces the file's initial
//! guess by the chordal initialisation before optimising (its time is included). `--error g2o`
//! minimises g2o's error convention instead of the log map (GTSAM's).

use std::time::Instant;

use anyhow::{Context, Result, bail};
use posegraph::g2o::{G2oGraph, g2o_chi2, read_g2o, write_g2o};
use posegraph::toro::read_toro;
use posegraph::{ChordalInitialization, ErrorModel, GaussNewton, LevenbergMarquardt, SolverConfig};
use slam_core::{GraphPose, OptimizationReport, Optimizer, Pose2, Pose3, PoseGraph};

const USAGE: &str = "usage: g2o FILE [--optimizer gn|lm] [--init file|chordal] [--error logmap|g2o] [--out OUT.g2o]";

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

fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    let (mut file, mut optimizer, mut init, mut error, mut out) = (
        None,
        "lm".to_string(),
        "file".to_string(),
        "logmap".to_string(),
        None,
    );
    while let Some(a) = args.next() {
        match a.as_str() {
            "--optimizer" => optimizer = args.next().context(USAGE)?,
            "--init" => init = args.next().context(USAGE)?,
            "--error" => error = args.next().context(USAGE)?,
            "--out" => out = Some(args.next().context(USAGE)?),
            "-h" | "--help" => {
                println!("{USAGE}");
                return Ok(());
            }
            _ if file.is_none() => file = Some(a),
            _ => bail!("unexpected argument {a:?}; {USAGE}"),
        }
    }
    let file = file.context(USAGE)?;
    let is_toro = std::path::Path::new(&file)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("graph"));
    let mut graph = if is_toro {
        G2oGraph::Se2(read_toro(&file)?)
    } else {
        read_g2o(&file).with_context(|| format!("reading {file}"))?
    };
    let (nodes, edges) = match &graph {
        G2oGraph::Se2(g) => (g.node_count(), g.edge_count()),
        G2oGraph::Se3(g) => (g.node_count(), g.edge_count()),
    };
    let chordal = match init.as_str() {
        "file" => false,
        "chordal" => true,
        other => bail!("unknown initialisation {other:?}; {USAGE}"),
    };
    let config = SolverConfig {
        error_model: match error.as_str() {
            "logmap" => ErrorModel::LogMap,
            "g2o" => ErrorModel::G2o,
            other => bail!("unknown error model {other:?}; {USAGE}"),
        },
        ..SolverConfig::default()
    };
    let g2o_before = g2o_chi2(&graph);
    let t = Instant::now();
    let report = match (&mut graph, optimizer.as_str()) {
        (G2oGraph::Se3(g), "lm") => {
            run::<Pose3, _>(g, &mut LevenbergMarquardt::new(config), chordal)?
        }
        (G2oGraph::Se3(g), "gn") => run::<Pose3, _>(g, &mut GaussNewton::new(config), chordal)?,
        (G2oGraph::Se2(g), "lm") => {
            run::<Pose2, _>(g, &mut LevenbergMarquardt::new(config), chordal)?
        }
        (G2oGraph::Se2(g), "gn") => run::<Pose2, _>(g, &mut GaussNewton::new(config), chordal)?,
        (_, other) => bail!("unknown optimizer {other:?}; {USAGE}"),
    };
    let ms = t.elapsed().as_secs_f64() * 1e3;
    println!("file        {file}");
    println!(
        "graph       {nodes} nodes, {edges} edges ({})",
        if matches!(graph, G2oGraph::Se3(_)) {
            "SE(3)"
        } else {
            "SE(2)"
        }
    );
    println!(
        "optimizer   {optimizer} from the {init} guess: {} iterations, {:?}",
        report.iterations, report.stop_reason
    );
    println!(
        "minimised   {error} cost {:.6} -> {:.6} (from the --init guess)",
        report.initial_cost, report.final_cost
    );
    let log_map = match &graph {
        G2oGraph::Se2(g) => g.cost(),
        G2oGraph::Se3(g) => g.cost(),
    };
    println!("log-map     {log_map:.6} (GTSAM's error is half of this)");
    println!("g2o chi2    {g2o_before:.6} -> {:.6}", g2o_chi2(&graph));
    println!("time        {ms:.1} ms");
    if let Some(out) = out {
        write_g2o(&out, &graph)?;
        println!("wrote       {out}");
    }
    Ok(())
}
