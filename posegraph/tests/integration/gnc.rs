//! Graduated non-convexity against wrong loop closures, and the Geman-McClure kernel from a poor
//! start. Wrong loops: random node pairs at least 5 m apart at the clean optimum, claimed to be
//! the same place with the file's loop information (`posegraph::wrong_loops`, PCG seeded).
//! Targets (issue 18): mean position error at most 5 cm from plain LM's clean optimum, every
//! wrong loop weighted out, at most 1 % of the true loops lost.
//!
//! The bundled M3500 and a synthetic ring run in the normal suite; `ring.g2o` (issue 17's
//! Geman-McClure case and the wrong loops) and sphere2500 (shared data) with
//! `cargo test -p spot-nav-posegraph --release --test integration gnc:: -- --ignored`.
#![allow(clippy::unwrap_used, clippy::panic)]

use std::path::PathBuf;

use nalgebra::{Matrix3, Vector2, Vector3};
use posegraph::g2o::{G2oGraph, read_g2o};
use posegraph::wrong_loops::{RobustScore, add_wrong_loops, score};
use posegraph::{
    GncConfig, GncLoss, GraduatedNonConvexity, KnownInliers, LevenbergMarquardt, SolverConfig,
    SolverPose,
};
use slam_core::{InvalidSetting, Optimizer, Pose2, PoseGraph, RobustKernel, StopReason, se2_exp};

use crate::common::{rng_u64, uniform};

fn bundled(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn fix_first<P: SolverPose>(g: &mut PoseGraph<P>) {
    if !g.nodes().iter().any(|n| n.fixed) {
        let id = g.nodes()[0].id;
        g.fix(id).unwrap();
    }
}

/// Plain LM's optimum of `clean`, one pose per node.
fn optimum<P: SolverPose>(clean: &PoseGraph<P>) -> Vec<P>
where
    LevenbergMarquardt: Optimizer<P>,
{
    let mut g = clean.clone();
    LevenbergMarquardt::default().optimize(&mut g).unwrap();
    g.nodes().iter().map(|n| n.pose).collect()
}

/// `clean` with `count` wrong loops (seed `seed`), optimised by GNC's defaults, scored.
fn corrupted_run<P: SolverPose>(
    clean: &PoseGraph<P>,
    reference: &[P],
    count: usize,
    seed: u64,
) -> RobustScore
where
    GraduatedNonConvexity: Optimizer<P>,
{
    let info = clean
        .edges()
        .iter()
        .find(|e| clean.nodes()[e.from].id.abs_diff(clean.nodes()[e.to].id) > 1)
        .unwrap()
        .information;
    let mut g = clean.clone();
    let first = g.edge_count();
    let added = add_wrong_loops(&mut g, reference, count, 5.0, info, &mut rng_u64(seed)).unwrap();
    assert_eq!(added.len(), count);
    let report = GraduatedNonConvexity::default()
        .optimize_robust(&mut g)
        .unwrap();
    assert!(report.converged, "{report:?}");
    let s = score(&g, reference, &report.weights, first);
    eprintln!(
        "+{count} seed {seed}: mean error {:.2e} m (max {:.2e}), wrong kept {}, true lost {}/{}, {} outer, {} LM iterations, {} supported",
        s.mean_position_error,
        s.max_position_error,
        s.wrong_kept,
        s.true_lost,
        s.true_loops,
        report.outer_iterations,
        report.optimization.iterations,
        report.supported
    );
    s
}

fn assert_targets(s: &RobustScore, what: &str) {
    assert!(s.mean_position_error <= 0.05, "{what}: {s:?}");
    assert_eq!(s.wrong_kept, 0, "{what}: {s:?}");
    assert!(s.true_lost * 100 <= s.true_loops, "{what}: {s:?}");
}

/// A ring like Vertigo's ring.g2o: `n` poses on a circle of radius 40 m, odometry with 5 cm and
/// 0.5 degree noise (the guess composed from it drifts by metres), the last 20 poses closing
/// exactly onto the first 20 with ring.g2o's loop information (10 cm, 5 degrees).
fn synthetic_ring(n: usize, seed: u64) -> PoseGraph<Pose2> {
    let mut u = uniform(seed);
    let mut normal = move || {
        // Sum of 12 uniforms: a portable, roughly normal sample.
        (0..12).map(|_| u()).sum::<f64>() - 6.0
    };
    let lap = n - 20;
    let truth: Vec<Pose2> = (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / lap as f64;
            Pose2::new(Vector2::new(40.0 * a.sin(), 40.0 - 40.0 * a.cos()), a)
        })
        .collect();
    let (st, sr) = (0.05, 0.5f64.to_radians());
    let info = Matrix3::from_diagonal(&Vector3::new(
        1.0 / (st * st),
        1.0 / (st * st),
        1.0 / (sr * sr),
    ));
    let mut g = PoseGraph::new();
    let mut guess = truth[0];
    g.add_node(0, guess).unwrap();
    g.fix(0).unwrap();
    let mut edges = Vec::new();
    for i in 1..n {
        let z = truth[i - 1].inverse()
            * truth[i]
            * se2_exp(&Vector3::new(st * normal(), st * normal(), sr * normal()));
        guess *= z;
        g.add_node(i as u64, guess).unwrap();
        edges.push((i - 1, i, z));
    }
    for i in lap..n {
        let j = i - lap;
        let z = truth[j].inverse() * truth[i];
        edges.push((j, i, z));
    }
    let loop_info = Matrix3::from_diagonal(&Vector3::new(100.0, 100.0, 131.312_254));
    for (a, b, z) in edges {
        let info = if b - a == 1 { info } else { loop_info };
        g.add_edge(a as u64, b as u64, z, info, None).unwrap();
    }
    g
}

#[test]
fn synthetic_ring_with_2_to_45_wrong_loops() {
    let clean = synthetic_ring(420, 5);
    let reference = optimum(&clean);
    // The guess has drifted by metres: the wrong loops and the true ones look alike at it.
    let drift =
        (clean.nodes()[419].pose.translation.vector - reference[419].translation.vector).norm();
    assert!(drift > 1.0, "drift {drift} m");
    for count in [2, 5, 13, 45] {
        for seed in [1, 2, 3] {
            let s = corrupted_run(&clean, &reference, count, seed);
            assert_targets(&s, &format!("synthetic ring +{count} seed {seed}"));
        }
    }
}

#[test]
fn bundled_m3500_with_5_percent_wrong_loops() {
    if slam_core::skip_without_test_data!("tests/data") {
        return;
    }
    let G2oGraph::Se2(mut clean) = read_g2o(bundled("input_M3500_g2o.g2o")).unwrap() else {
        panic!("M3500 is 2D")
    };
    fix_first(&mut clean);
    let reference = optimum(&clean);
    let count = clean.edge_count() / 20;
    assert_eq!(count, 272);
    for seed in [1, 2, 3] {
        let s = corrupted_run(&clean, &reference, count, seed);
        assert_targets(&s, &format!("M3500 +{count} seed {seed}"));
    }
}

#[test]
fn clean_graphs_reach_the_lm_optimum() {
    if slam_core::skip_without_test_data!("tests/data") {
        return;
    }
    // smallGrid3D's noise is at its information's scale: 3 of its 297 edges are beyond the 0.99
    // chi-square quantile at the optimum and TLS rejects them (cost 1044.12 against 1035.85);
    // with the 0.9999 quantile it keeps them all.
    for (name, p) in [
        ("input_M3500_g2o.g2o", 0.99),
        ("tinyGrid3D.g2o", 0.99),
        ("smallGrid3D.g2o", 0.9999),
    ] {
        let (lm, gnc, rejected) = match read_g2o(bundled(name)).unwrap() {
            G2oGraph::Se2(g) => clean_costs(g, p),
            G2oGraph::Se3(g) => clean_costs(g, p),
        };
        assert!(
            ((gnc - lm) / lm).abs() < 1e-6,
            "{name}: GNC {gnc} vs LM {lm}"
        );
        assert_eq!(rejected, 0, "{name}");
    }
    let ring = synthetic_ring(420, 5);
    let (lm, gnc, rejected) = clean_costs(ring, 0.99);
    assert!(((gnc - lm) / lm).abs() < 1e-6, "ring: GNC {gnc} vs LM {lm}");
    assert_eq!(rejected, 0);
}

/// (LM's cost, GNC's plain cost, edges GNC rejected) on a clean graph.
fn clean_costs<P: SolverPose>(mut g: PoseGraph<P>, inlier_probability: f64) -> (f64, f64, usize)
where
    GraduatedNonConvexity: Optimizer<P>,
    LevenbergMarquardt: Optimizer<P>,
{
    fix_first(&mut g);
    let mut lm = g.clone();
    LevenbergMarquardt::default().optimize(&mut lm).unwrap();
    let report = GraduatedNonConvexity::try_new(GncConfig {
        inlier_probability,
        ..GncConfig::default()
    })
    .unwrap()
    .optimize_robust(&mut g)
    .unwrap();
    (lm.cost(), g.cost(), report.rejected)
}

#[test]
fn geman_mcclure_from_a_drifted_guess_reaches_the_optimum() {
    // Regression: LM with a Geman-McClure kernel on the loops stopped after one iteration
    // reporting CostConverged, metres off: every loop was saturated at the guess (ring.g2o with
    // c = 1: 13 m; see the ignored test). Here c = 3 (with c = 1 GM's own optimum is 22 cm from
    // least squares' on this ring, whose loops sit near 1 sigma).
    let clean = synthetic_ring(420, 5);
    let reference = optimum(&clean);
    let mut g = PoseGraph::new();
    for n in clean.nodes() {
        g.add_node(n.id, n.pose).unwrap();
    }
    g.fix(0).unwrap();
    for e in clean.edges() {
        let (a, b) = (clean.nodes()[e.from].id, clean.nodes()[e.to].id);
        let kernel = (a.abs_diff(b) > 1).then_some(RobustKernel::GemanMcClure { c: 3.0 });
        g.add_edge(a, b, e.measurement, e.information, kernel)
            .unwrap();
    }
    let report = LevenbergMarquardt::default().optimize(&mut g).unwrap();
    let s = score(&g, &reference, &[], g.edge_count());
    assert!(report.iterations > 1, "{report:?}");
    assert_ne!(report.stop_reason, StopReason::MaxIterations, "{report:?}");
    // GM's optimum is 2 cm from least squares' here; the bug left it metres off.
    assert!(s.mean_position_error < 0.05, "{s:?} {report:?}");
}

#[test]
fn settings_are_validated() {
    let bad = [
        GncConfig {
            inlier_probability: 1.0,
            ..GncConfig::default()
        },
        GncConfig {
            mu_step: 1.0,
            ..GncConfig::default()
        },
        GncConfig {
            inner_iterations: 0,
            ..GncConfig::default()
        },
        GncConfig {
            max_outer_iterations: 0,
            ..GncConfig::default()
        },
        GncConfig {
            weight_tolerance: 0.5,
            ..GncConfig::default()
        },
        GncConfig {
            solver: SolverConfig {
                relative_cost_tolerance: f64::NAN,
                ..SolverConfig::default()
            },
            ..GncConfig::default()
        },
    ];
    let names = [
        "GncConfig::inlier_probability",
        "GncConfig::mu_step",
        "GncConfig::inner_iterations",
        "GncConfig::max_outer_iterations",
        "GncConfig::weight_tolerance",
        "SolverConfig::relative_cost_tolerance",
    ];
    for (config, name) in bad.into_iter().zip(names) {
        match GraduatedNonConvexity::try_new(config) {
            Err(InvalidSetting { setting, .. }) => assert_eq!(setting, name),
            Ok(_) => panic!("{name} accepted"),
        }
    }
    assert!(GraduatedNonConvexity::try_new(GncConfig::default()).is_ok());
}

#[test]
fn known_inliers_and_losses() {
    let clean = synthetic_ring(420, 5);
    let reference = optimum(&clean);
    let info = clean.edges().last().unwrap().information;
    let mut g = clean.clone();
    let first = g.edge_count();
    add_wrong_loops(&mut g, &reference, 13, 5.0, info, &mut rng_u64(9)).unwrap();
    // Explicit flags marking the odometry, and kernels marking the candidates, give the same
    // result as consecutive ids.
    let odometry: Vec<bool> = g
        .edges()
        .iter()
        .map(|e| g.nodes()[e.from].id.abs_diff(g.nodes()[e.to].id) == 1)
        .collect();
    let mut kernelled = PoseGraph::new();
    for n in g.nodes() {
        kernelled.add_node(n.id, n.pose).unwrap();
    }
    kernelled.fix(0).unwrap();
    for (e, &odo) in g.edges().iter().zip(&odometry) {
        let (a, b) = (g.nodes()[e.from].id, g.nodes()[e.to].id);
        let kernel = (!odo).then_some(RobustKernel::Cauchy { c: 1.0 });
        kernelled
            .add_edge(a, b, e.measurement, e.information, kernel)
            .unwrap();
    }
    for (known, mut graph) in [
        (KnownInliers::Flags(odometry.clone()), g.clone()),
        (KnownInliers::WithoutKernel, kernelled),
    ] {
        let mut gnc = GraduatedNonConvexity::try_new(GncConfig {
            known_inliers: known.clone(),
            ..GncConfig::default()
        })
        .unwrap();
        let report = gnc.optimize_robust(&mut graph).unwrap();
        assert_eq!(report.known_inliers, 419, "{known:?}");
        assert_eq!(gnc.weights(), &report.weights[..]);
        assert_targets(
            &score(&graph, &reference, &report.weights, first),
            "known inliers",
        );
    }
    // Geman-McClure's weights are continuous; the wrong loops' end near 0.
    let mut graph = g.clone();
    let report = GraduatedNonConvexity::try_new(GncConfig {
        loss: GncLoss::GemanMcClure,
        ..GncConfig::default()
    })
    .unwrap()
    .optimize_robust(&mut graph)
    .unwrap();
    let s = score(&graph, &reference, &report.weights, first);
    assert!(s.mean_position_error < 0.05 && s.wrong_kept == 0, "{s:?}");
}

/// Vertigo's ring.g2o from the shared data folder (GPL-3.0, so not bundled), first node fixed,
/// and plain LM's optimum of it.
fn ring_g2o() -> (PoseGraph<Pose2>, Vec<Pose2>) {
    let Some(path) = crate::common::shared("ring.g2o") else {
        panic!("ring.g2o not found in the shared data folder (SPOT_NAV_DATA)");
    };
    let G2oGraph::Se2(mut clean) = read_g2o(path).unwrap() else {
        panic!("ring is 2D")
    };
    fix_first(&mut clean);
    let reference = optimum(&clean);
    (clean, reference)
}

#[test]
#[ignore = "reads the shared data folder; run with --ignored"]
fn ring_g2o_with_2_to_45_wrong_loops() {
    let (clean, reference) = ring_g2o();
    for count in [2, 5, 13, 45] {
        for seed in [1, 2, 3] {
            let s = corrupted_run(&clean, &reference, count, seed);
            assert_targets(&s, &format!("ring.g2o +{count} seed {seed}"));
        }
    }
}

/// `clean` with Geman-McClure kernels (`c = 1`, as issue 17 tried) on every loop edge (ids more
/// than one apart) and `wrong` extra loops from [`add_wrong_loops`] (seed 1), from the file's
/// own guess.
fn with_gm_loops(clean: &PoseGraph<Pose2>, reference: &[Pose2], wrong: usize) -> PoseGraph<Pose2> {
    let info = clean.edges().last().unwrap().information;
    let mut plain = clean.clone();
    add_wrong_loops(&mut plain, reference, wrong, 5.0, info, &mut rng_u64(1)).unwrap();
    let mut g = PoseGraph::new();
    for n in plain.nodes() {
        g.add_node(n.id, n.pose).unwrap();
    }
    g.fix(plain.nodes()[0].id).unwrap();
    for e in plain.edges() {
        let (a, b) = (plain.nodes()[e.from].id, plain.nodes()[e.to].id);
        let kernel = (a.abs_diff(b) > 1).then_some(RobustKernel::GemanMcClure { c: 1.0 });
        g.add_edge(a, b, e.measurement, e.information, kernel)
            .unwrap();
    }
    g
}

#[test]
#[ignore = "reads the shared data folder (ring.g2o is GPL-3.0, not bundled); run with --ignored"]
fn geman_mcclure_on_ring_g2o_from_the_files_guess() {
    // Issue 17's case: LM with Geman-McClure (c = 1) on ring.g2o's loops, from the file's guess
    // (13 m of drift), stopped after one iteration reporting CostConverged, 13 m off.
    let (clean, reference) = ring_g2o();
    let mut g = with_gm_loops(&clean, &reference, 0);
    let report = LevenbergMarquardt::default().optimize(&mut g).unwrap();
    let s = score(&g, &reference, &[], g.edge_count());
    assert!(report.iterations > 1, "{report:?}");
    assert_ne!(report.stop_reason, StopReason::MaxIterations, "{report:?}");
    assert!(s.mean_position_error < 0.01, "{s:?} {report:?}");
    // With 2 wrong loops a kernel graduated over every residual starts as least squares, which
    // folds the ring (issue 18: 51-96 m); the Geman-McClure loss of graduated non-convexity,
    // with odometry as known inliers, is the tool for that case.
    let first = clean.edge_count();
    let mut g = with_gm_loops(&clean, &reference, 2);
    let report = GraduatedNonConvexity::try_new(GncConfig {
        loss: GncLoss::GemanMcClure,
        ..GncConfig::default()
    })
    .unwrap()
    .optimize_robust(&mut g)
    .unwrap();
    let s = score(&g, &reference, &report.weights, first);
    assert!(s.mean_position_error < 0.05, "{s:?} {report:?}");
    assert_eq!(s.wrong_kept, 0, "{s:?}");
}

#[test]
#[ignore = "reads the shared data folder (about a minute); run with --ignored"]
fn sphere2500_with_10_percent_wrong_loops() {
    let Some(path) = crate::common::shared("sphere2500.g2o") else {
        eprintln!("sphere2500.g2o not found; skipping");
        return;
    };
    let G2oGraph::Se3(mut clean) = read_g2o(path).unwrap() else {
        panic!("sphere2500 is 3D")
    };
    fix_first(&mut clean);
    let reference = optimum(&clean);
    // 10 % of its 4,949 edges, rounded up (as the bench).
    let count = clean.edge_count().div_ceil(10);
    assert_eq!(count, 495);
    for seed in [1, 2, 3] {
        let s = corrupted_run(&clean, &reference, count, seed);
        assert_targets(&s, &format!("sphere2500 +{count} seed {seed}"));
    }
}
