//! Outlier-robust pose-graph optimisation: `GraduatedNonConvexity` (truncated least squares, its
//! default settings) on public graphs with wrong loop closures added, 3 seeds each: `ring.g2o`
//! with 2, 5, 13 and 45 wrong loops, `input_M3500_g2o.g2o` with 272 (5 % of its edges) and
//! `sphere2500.g2o` with 495 (10 %). A wrong loop joins two random nodes at least 5 m apart at the
//! clean optimum (ids not consecutive), claims they are the same place (identity measurement) and
//! carries the file's first loop's information (`posegraph::wrong_loops`, a PCG generator seeded
//! with the seed). Not criterion: prints, per graph, the mean and largest position error against
//! plain LM's optimum of the clean file, wrong loops kept, true loops lost, GNC's outer and LM
//! iterations, and the best of `POSEGRAPH_ROBUST_REPEATS` (default 3) wall times; then the clean
//! files through GNC against plain LM's cost.
//!
//! `cargo bench -p spot-nav-benches --bench posegraph_robust` (`SPOT_NAV_DATA` names the shared
//! data folder; `POSEGRAPH_ROBUST_CASES=ring,m3500,sphere` picks files;
//! `POSEGRAPH_ROBUST_WRITE=DIR` also writes each corrupted graph as `DIR/<file>_w<wrong>_s<seed>.g2o`
//! for the GTSAM peer, `bash benches/peers/gtsam_gnc.sh`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use posegraph::g2o::{G2oGraph, read_g2o, write_g2o};
use posegraph::wrong_loops::{add_wrong_loops, score};
use posegraph::{GraduatedNonConvexity, LevenbergMarquardt, SolverPose};
use rand_pcg::Pcg64Mcg;
use rand_pcg::rand_core::{Rng, SeedableRng};
use slam_core::{Optimizer, PoseGraph};
use spot_nav_benches::data_root_or_notice;

/// The graphs: (case name, file, wrong loops).
const CASES: [(&str, &str, &[usize]); 3] = [
    ("ring", "ring.g2o", &[2, 5, 13, 45]),
    ("m3500", "input_M3500_g2o.g2o", &[272]),
    ("sphere", "sphere2500.g2o", &[495]),
];
const SEEDS: [u64; 3] = [1, 2, 3];

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn fix_first<P: SolverPose>(g: &mut PoseGraph<P>) {
    if !g.nodes().iter().any(|n| n.fixed)
        && let Some(id) = g.nodes().first().map(|n| n.id)
    {
        let _ = g.fix(id);
    }
}

/// The corrupted graphs of one file, timed and scored.
fn run<P: SolverPose>(
    file: &str,
    mut clean: PoseGraph<P>,
    wrong: &[usize],
    write: Option<&Path>,
    wrap: fn(PoseGraph<P>) -> G2oGraph,
) where
    GraduatedNonConvexity: Optimizer<P>,
    LevenbergMarquardt: Optimizer<P>,
{
    fix_first(&mut clean);
    let mut optimum = clean.clone();
    let t = Instant::now();
    let Ok(lm) = LevenbergMarquardt::default().optimize(&mut optimum) else {
        eprintln!("{file}: LM failed on the clean graph");
        return;
    };
    let lm_ms = t.elapsed().as_secs_f64() * 1e3;
    let reference: Vec<P> = optimum.nodes().iter().map(|n| n.pose).collect();
    let mut g = clean.clone();
    let gnc = GraduatedNonConvexity::default().optimize_robust(&mut g);
    if let Ok(r) = gnc {
        let s = score(&g, &reference, &r.weights, g.edge_count());
        println!(
            "{file:<20} clean    LM cost {:.6} ({lm_ms:.0} ms), GNC cost {:.6}, error {:.2e} m, true lost {}/{}",
            lm.final_cost,
            g.cost(),
            s.mean_position_error,
            s.true_lost,
            s.true_loops
        );
    }
    let Some(info) = clean
        .edges()
        .iter()
        .find(|e| clean.nodes()[e.from].id.abs_diff(clean.nodes()[e.to].id) > 1)
        .map(|e| e.information)
    else {
        eprintln!("{file}: no loop closure to copy the information of");
        return;
    };
    let repeats = env_usize("POSEGRAPH_ROBUST_REPEATS", 3).max(1);
    for &count in wrong {
        for seed in SEEDS {
            let mut corrupted = clean.clone();
            let first = corrupted.edge_count();
            let mut rng = Pcg64Mcg::seed_from_u64(seed);
            if add_wrong_loops(&mut corrupted, &reference, count, 5.0, info, &mut || {
                rng.next_u64()
            })
            .is_err()
            {
                eprintln!("{file}: the loop information is not positive definite");
                return;
            }
            if let Some(dir) = write {
                let stem = file.trim_end_matches(".g2o");
                let path = dir.join(format!("{stem}_w{count}_s{seed}.g2o"));
                // Without the FIX line, as the original files: GTSAM's reader stops at it.
                let mut unfixed = corrupted.clone();
                for id in unfixed
                    .nodes()
                    .iter()
                    .filter(|n| n.fixed)
                    .map(|n| n.id)
                    .collect::<Vec<_>>()
                {
                    let _ = unfixed.unfix(id);
                }
                if let Err(e) = write_g2o(&path, &wrap(unfixed)) {
                    eprintln!("{e}");
                }
            }
            let mut best = f64::INFINITY;
            let mut last = None;
            for _ in 0..repeats {
                let mut g = corrupted.clone();
                let mut gnc = GraduatedNonConvexity::default();
                let t = Instant::now();
                let r = gnc.optimize_robust(&mut g);
                best = best.min(t.elapsed().as_secs_f64() * 1e3);
                last = Some((g, r));
            }
            let Some((g, Ok(r))) = last else {
                eprintln!("{file} +{count} seed {seed}: GNC failed");
                continue;
            };
            let s = score(&g, &reference, &r.weights, first);
            println!(
                "{file:<20} +{count:<3} s{seed}  error {:.6} m (max {:.4}), wrong kept {}/{count}, true lost {}/{}, outer {} LM {} {}, best {best:.1} ms",
                s.mean_position_error,
                s.max_position_error,
                s.wrong_kept,
                s.true_lost,
                s.true_loops,
                r.outer_iterations,
                r.optimization.iterations,
                if r.converged {
                    "converged"
                } else {
                    "NOT converged"
                },
            );
        }
    }
}

fn main() {
    let Some(root) = data_root_or_notice("posegraph_robust") else {
        return;
    };
    let picked = std::env::var("POSEGRAPH_ROBUST_CASES").ok();
    let write = std::env::var_os("POSEGRAPH_ROBUST_WRITE").map(PathBuf::from);
    if let Some(dir) = &write
        && let Err(e) = std::fs::create_dir_all(dir)
    {
        eprintln!("{}: {e}", dir.display());
        return;
    }
    for (name, file, wrong) in CASES {
        if picked
            .as_deref()
            .is_some_and(|p| !p.split(',').any(|c| c == name))
        {
            continue;
        }
        match read_g2o(root.join("posegraph").join(file)) {
            Ok(G2oGraph::Se2(g)) => run(file, g, wrong, write.as_deref(), G2oGraph::Se2),
            Ok(G2oGraph::Se3(g)) => run(file, g, wrong, write.as_deref(), G2oGraph::Se3),
            Err(e) => eprintln!("posegraph_robust: {file}: {e}; skipping"),
        }
    }
}
