//! Pose-graph optimisation: Levenberg-Marquardt and Gauss-Newton from each file's initial guess
//! to the optimum, single thread (faer is built without its rayon feature). Reading the file is
//! outside the timed loop; each iteration optimises a fresh copy. torus3D, where LM from the
//! file's guess stops in a local minimum, is solved from the chordal initialisation (timed too).
//!
//! Group `posegraph_incremental`: the SLAM engine's case. The first 2,000 poses of sphere2500
//! (with the edges among them) are optimised once; then the next five poses arrive with their
//! odometry and loop edges, each new pose guessed by composing odometry. Re-optimising that
//! grown graph is timed from the previous optimum (warm start, a fresh pattern and symbolic
//! factorisation since the structure changed) against the same graph from the file's guess
//! (from scratch); and a re-optimisation where only values changed (one pose nudged) with the
//! optimiser's cached pattern and symbolic factorisation.
//!
//! `cargo bench -p spot-nav-benches --bench posegraph` (`SPOT_NAV_DATA` names the shared data
//! folder). The GTSAM peer: `bash benches/peers/gtsam_posegraph.sh`.

use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};
use posegraph::g2o::{G2oGraph, read_g2o};
use posegraph::{GaussNewton, LevenbergMarquardt, initialize_chordal};
use slam_core::{Optimizer, Pose3, PoseGraph, pose3_from_xyz_rpy};
use spot_nav_benches::data_root_or_notice;

fn optimize(graph: &mut G2oGraph, lm: bool) -> f64 {
    let report = match graph {
        G2oGraph::Se3(g) => {
            if lm {
                LevenbergMarquardt::default().optimize(g)
            } else {
                GaussNewton::default().optimize(g)
            }
        }
        G2oGraph::Se2(g) => {
            if lm {
                LevenbergMarquardt::default().optimize(g)
            } else {
                GaussNewton::default().optimize(g)
            }
        }
    };
    report.map_or(f64::NAN, |r| r.final_cost)
}

fn posegraph(c: &mut Criterion) {
    let Some(root) = data_root_or_notice("posegraph") else {
        return;
    };
    let mut group = c.benchmark_group("posegraph");
    group.sample_size(10);
    for file in [
        "sphere2500.g2o",
        "parking-garage.g2o",
        "input_M3500_g2o.g2o",
        "intel.g2o",
    ] {
        let Ok(mut graph) = read_g2o(root.join("posegraph").join(file)) else {
            eprintln!("posegraph: {file} missing; skipping");
            continue;
        };
        match &mut graph {
            G2oGraph::Se3(g) => {
                let id = g.nodes()[0].id;
                let _ = g.fix(id);
            }
            G2oGraph::Se2(g) => {
                let id = g.nodes()[0].id;
                let _ = g.fix(id);
            }
        }
        for (name, lm) in [("LevenbergMarquardt", true), ("GaussNewton", false)] {
            group.bench_function(BenchmarkId::new(name, file), |b| {
                b.iter_batched(
                    || graph.clone(),
                    |mut g| optimize(&mut g, lm),
                    BatchSize::LargeInput,
                );
            });
        }
    }
    if let Ok(G2oGraph::Se3(mut torus)) = read_g2o(root.join("posegraph/torus3D.g2o")) {
        let id = torus.nodes()[0].id;
        let _ = torus.fix(id);
        group.bench_function(
            BenchmarkId::new("ChordalLevenbergMarquardt", "torus3D.g2o"),
            |b| {
                b.iter_batched(
                    || torus.clone(),
                    |mut g| {
                        let _ = initialize_chordal(&mut g);
                        LevenbergMarquardt::default()
                            .optimize(&mut g)
                            .map_or(f64::NAN, |r| r.final_cost)
                    },
                    BatchSize::LargeInput,
                );
            },
        );
    } else {
        eprintln!("posegraph: torus3D.g2o missing; skipping");
    }
    group.finish();
}

/// The sub-graph of `full` on nodes with index below `n`; new nodes' poses come from
/// `guess(index, graph so far)`.
fn prefix(
    full: &PoseGraph<Pose3>,
    n: usize,
    guess: impl Fn(usize, &PoseGraph<Pose3>) -> Pose3,
) -> PoseGraph<Pose3> {
    let mut g = PoseGraph::new();
    for (i, node) in full.nodes().iter().take(n).enumerate() {
        let pose = guess(i, &g);
        let _ = g.add_node(node.id, pose);
    }
    let _ = g.fix(full.nodes()[0].id);
    for e in full.edges().iter().filter(|e| e.from < n && e.to < n) {
        let (a, b) = (full.nodes()[e.from].id, full.nodes()[e.to].id);
        let _ = g.add_edge(a, b, e.measurement, e.information, e.kernel);
    }
    g
}

/// Optimise a copy of `graph` once and print the iterations (the bench does not report them).
fn print_iterations(what: &str, lm: &mut LevenbergMarquardt, graph: &PoseGraph<Pose3>) {
    if let Ok(r) = lm.optimize(&mut graph.clone()) {
        eprintln!(
            "posegraph_incremental: {what}: {} iterations, {:.3} -> {:.3}",
            r.iterations, r.initial_cost, r.final_cost
        );
    }
}

fn incremental(c: &mut Criterion) {
    let Some(root) = data_root_or_notice("posegraph_incremental") else {
        return;
    };
    let Ok(G2oGraph::Se3(full)) = read_g2o(root.join("posegraph/sphere2500.g2o")) else {
        eprintln!("posegraph_incremental: sphere2500.g2o missing; skipping");
        return;
    };
    let (n, added) = (2000, 5);
    // The first 2,000 poses, optimised: the state before the update.
    let mut before = prefix(&full, n, |i, _| full.nodes()[i].pose);
    let _ = LevenbergMarquardt::default().optimize(&mut before);
    // The grown graph, warm: old poses at their optimum, new ones by odometry from the last.
    let odometry = |i: usize, g: &PoseGraph<Pose3>| -> Option<Pose3> {
        let e = full.edges().iter().find(|e| e.to == i && e.from + 1 == i)?;
        Some(g.nodes()[e.from].pose * e.measurement)
    };
    let warm = prefix(&full, n + added, |i, g| {
        if i < n {
            before.nodes()[i].pose
        } else {
            odometry(i, g).unwrap_or(full.nodes()[i].pose)
        }
    });
    let cold = prefix(&full, n + added, |i, _| full.nodes()[i].pose);
    let loops = warm
        .edges()
        .iter()
        .filter(|e| e.to >= n && e.from + 1 != e.to)
        .count();
    eprintln!(
        "posegraph_incremental: {} + {added} nodes, {} + {} edges ({loops} loop edges on the new nodes)",
        n,
        before.edge_count(),
        warm.edge_count() - before.edge_count()
    );
    print_iterations("from scratch", &mut LevenbergMarquardt::default(), &cold);
    print_iterations("warm start", &mut LevenbergMarquardt::default(), &warm);
    let mut group = c.benchmark_group("posegraph_incremental");
    group.sample_size(10);
    let name = format!("{n}+{added}");
    // Same structure, new values: the optimiser keeps its pattern and symbolic factorisation.
    let mut optimum = warm.clone();
    let mut lm = LevenbergMarquardt::default();
    let _ = lm.optimize(&mut optimum);
    let mut nudged = optimum.clone();
    let last = nudged.node_count() - 1;
    let pose = nudged.nodes()[last].pose;
    nudged.set_pose(
        last,
        pose3_from_xyz_rpy(0.05, -0.05, 0.02, 0.01, 0.0, -0.01) * pose,
    );
    print_iterations("one pose nudged", &mut lm, &nudged);
    // A fresh optimiser on each graph.
    for (id, graph) in [
        ("FromScratch", &cold),
        ("WarmStart", &warm),
        ("ValuesOnlyFresh", &nudged),
    ] {
        group.bench_function(BenchmarkId::new(id, &name), |b| {
            b.iter_batched(
                || graph.clone(),
                |mut g| {
                    LevenbergMarquardt::default()
                        .optimize(&mut g)
                        .map_or(f64::NAN, |r| r.final_cost)
                },
                BatchSize::LargeInput,
            );
        });
    }
    group.bench_function(BenchmarkId::new("ValuesOnlyCached", &name), |b| {
        b.iter_batched(
            || nudged.clone(),
            |mut g| lm.optimize(&mut g).map_or(f64::NAN, |r| r.final_cost),
            BatchSize::LargeInput,
        );
    });
    group.finish();
}

criterion_group!(benches, posegraph, incremental);
criterion_main!(benches);
