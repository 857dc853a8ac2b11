//! Pose-graph optimisation: Levenberg-Marquardt and Gauss-Newton from each file's initial guess
//! to the optimum, single thread (faer is built without its rayon feature). Reading the file is
//! outside the timed loop; each iteration optimises a fresh copy. torus3D, where LM from the
//! file's guess stops in a local minimum, is solved from the chordal initialisation (timed too).
//!
//! `cargo bench -p spot-nav-benches --bench posegraph` (`SPOT_NAV_DATA` names the shared data
//! folder). The GTSAM peer: `bash benches/peers/gtsam_posegraph.sh`.

use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};
use posegraph::g2o::{G2oGraph, read_g2o};
use posegraph::{GaussNewton, LevenbergMarquardt, initialize_chordal};
use slam_core::Optimizer;
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

criterion_group!(benches, posegraph);
criterion_main!(benches);
