//! Public pose-graph datasets against the reference costs in `shared/data/posegraph/README.md`
//! (GTSAM 4.3 LM, log-map error; our cost is `sum e^T Omega e` = 2 x GTSAM's error).
#![allow(clippy::unwrap_used, clippy::panic)]

use crate::common::shared;
use std::path::PathBuf;
use std::time::Instant;

use posegraph::g2o::{G2oGraph, g2o_chi2, parse_g2o, read_g2o};
use posegraph::{ErrorModel, GaussNewton, LevenbergMarquardt, SolverConfig};
use slam_core::{GraphPose, OptimizeError, Optimizer, PoseGraph};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn fix_first<P: GraphPose>(g: &mut PoseGraph<P>) {
    if !g.nodes().iter().any(|n| n.fixed) {
        let id = g.nodes()[0].id;
        g.fix(id).unwrap();
    }
}

/// Optimise with LM (and GN when `gn`), returning the final costs.
fn solve(graph: &G2oGraph, gn: bool) -> (f64, Option<f64>, f64) {
    let run = |lm: bool| -> (f64, f64) {
        let mut g = graph.clone();
        let t = Instant::now();
        let r = match &mut g {
            G2oGraph::Se3(g) => {
                fix_first(g);
                if lm {
                    LevenbergMarquardt::default().optimize(g)
                } else {
                    GaussNewton::default().optimize(g)
                }
            }
            G2oGraph::Se2(g) => {
                fix_first(g);
                if lm {
                    LevenbergMarquardt::default().optimize(g)
                } else {
                    GaussNewton::default().optimize(g)
                }
            }
        }
        .unwrap();
        eprintln!(
            "{} iterations {} cost {} -> {} ({:?}) in {:.1} ms",
            if lm { "LM" } else { "GN" },
            r.iterations,
            r.initial_cost,
            r.final_cost,
            r.stop_reason,
            t.elapsed().as_secs_f64() * 1e3
        );
        (r.final_cost, g2o_chi2(&g))
    };
    let (lm, g2o) = run(true);
    let gn_cost = gn.then(|| run(false).0);
    (lm, gn_cost, g2o)
}

fn assert_rel(got: f64, want: f64, tol: f64, what: &str) {
    assert!(
        ((got - want) / want).abs() <= tol,
        "{what}: {got} vs reference {want}"
    );
}

#[test]
fn tiny_grid_3d() {
    if slam_core::skip_without_test_data!("tests/data") {
        return;
    }
    let g = read_g2o(data("tinyGrid3D.g2o")).unwrap();
    let (lm, gn, _) = solve(&g, true);
    assert_rel(lm, 18.6278, 1e-4, "LM");
    assert_rel(gn.unwrap(), 18.6278, 1e-4, "GN");
}

#[test]
fn small_grid_3d() {
    if slam_core::skip_without_test_data!("tests/data") {
        return;
    }
    let g = read_g2o(data("smallGrid3D.g2o")).unwrap();
    let (lm, gn, _) = solve(&g, true);
    assert_rel(lm, 1035.85, 1e-4, "LM");
    assert_rel(gn.unwrap(), 1035.85, 1e-4, "GN");
}

#[test]
fn manhattan_m3500_2d() {
    if slam_core::skip_without_test_data!("tests/data") {
        return;
    }
    let g = read_g2o(data("input_M3500_g2o.g2o")).unwrap();
    let (lm, gn, g2o) = solve(&g, true);
    assert_rel(lm, 137.915, 1e-4, "LM");
    assert_rel(gn.unwrap(), 137.915, 1e-4, "GN");
    assert_rel(g2o, 137.913, 1e-4, "g2o chi2");
}

/// The larger public files, when the shared data folder is present.
#[test]
#[ignore = "reads the shared data folder; run with --ignored"]
fn larger_datasets() {
    for (file, want, gn) in [
        ("sphere2500.g2o", 1351.40, true),
        ("parking-garage.g2o", 1.26838, true),
        ("intel.g2o", 45.0042, true),
        ("manhattanOlson3500.g2o", 146.079, true),
        ("ringCity.g2o", 262.818, true),
        ("ring.g2o", 11.1631, true),
    ] {
        let Some(p) = shared(file) else {
            eprintln!("{file}: not found; skipped");
            continue;
        };
        eprintln!("{file}");
        let (lm, gnc, _) = solve(&read_g2o(p).unwrap(), gn);
        assert_rel(lm, want, 1e-4, file);
        if let Some(c) = gnc {
            assert_rel(c, want, 1e-4, file);
        }
    }
}

#[test]
fn malformed_files_and_bad_graphs_are_errors() {
    use posegraph::{GraphFileError, UnknownTag};
    assert!(matches!(
        parse_g2o("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 0 1 0 0\n"),
        Err(GraphFileError::Graph { line: 2, .. })
    ));
    assert!(matches!(
        parse_g2o("VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n"),
        Err(GraphFileError::Graph { line: 2, .. })
    ));
    assert!(matches!(
        parse_g2o("VERTEX_SE2 0 0 x 0\n"),
        Err(GraphFileError::Line { line: 1, .. })
    ));
    assert!(
        matches!(parse_g2o("VERTEX_SE2 0 0 0 0\nVERTEX_XY 1 0 0\nVERTEX_XY 2 0 0\n"), Err(GraphFileError::UnknownTags { tags }) if tags == vec![UnknownTag { line: 2, tag: "VERTEX_XY".to_string() }])
    );
    assert!(matches!(
        parse_g2o("VERTEX_SE2 0 0 0 0\nVERTEX_SE3:QUAT 1 0 0 0 0 0 0 1\n"),
        Err(GraphFileError::MixedDimensions { line: 2 })
    ));
    // Information that is not positive definite.
    let bad = "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0 0 -1 0 0 1 0 1\n";
    let refused = parse_g2o(bad).unwrap_err();
    assert!(
        matches!(
            refused,
            GraphFileError::InformationNotPositiveDefinite { line: 3, edge: 0 }
        ),
        "{refused}"
    );
    // The error names the option that repairs it.
    assert!(
        refused.to_string().contains("--repair-information"),
        "{refused}"
    );
    // No fixed node, and a node connected to nothing.
    let G2oGraph::Se2(mut g) = parse_g2o("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nVERTEX_SE2 2 5 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n").unwrap() else { panic!() };
    assert!(matches!(
        LevenbergMarquardt::default().optimize(&mut g),
        Err(OptimizeError::NoFixedNode)
    ));
    g.fix(0).unwrap();
    assert!(matches!(
        GaussNewton::default().optimize(&mut g),
        Err(OptimizeError::Disconnected {
            count: 1,
            first_id: 2
        })
    ));
}

#[test]
fn g2o_round_trip_is_exact() {
    if slam_core::skip_without_test_data!("tests/data") {
        return;
    }
    let text = std::fs::read_to_string(data("tinyGrid3D.g2o")).unwrap();
    let G2oGraph::Se3(g) = parse_g2o(&text).unwrap() else {
        panic!("3D file")
    };
    let back = posegraph::g2o::g2o_text_se3(&g);
    let G2oGraph::Se3(g2) = parse_g2o(&back).unwrap() else {
        panic!()
    };
    assert_eq!(g.node_count(), g2.node_count());
    for (a, b) in g.nodes().iter().zip(g2.nodes()) {
        assert_eq!(a.id, b.id);
        assert!((a.pose.to_homogeneous() - b.pose.to_homogeneous()).amax() < 1e-15);
    }
    for (a, b) in g.edges().iter().zip(g2.edges()) {
        assert_eq!(a.information, b.information);
    }
}

/// `input_INTEL_g2o`, where GTSAM's LM does not move. Its edge 160->161 has a translational
/// information of 2.7e12 on a near-pure rotation, so the log-map and g2o's convention have
/// different optima: at the log-map optimum (215.84) g2o's chi2 is 1.2e5, nearly all of it that
/// edge. Minimising g2o's own error ([`ErrorModel::G2o`]), Gauss-Newton reaches g2o's chi2 of
/// 215.83 (g2o's GN, shared README), evaluated independently by `g2o_chi2`.
#[test]
#[ignore = "reads the shared data folder; run with --ignored"]
fn intel_where_gtsam_lm_is_stuck() {
    let Some(p) = shared("input_INTEL_g2o.g2o") else {
        eprintln!("input_INTEL_g2o.g2o not found; skipped");
        return;
    };
    let G2oGraph::Se2(mut g) = read_g2o(p).unwrap() else {
        panic!("a 2D file")
    };
    fix_first(&mut g);
    let file_guess = g.clone();
    let r = GaussNewton::default().optimize(&mut g).unwrap();
    eprintln!(
        "INTEL log-map: GN {} iterations, log-map chi2 {}, g2o chi2 {}",
        r.iterations,
        r.final_cost,
        g2o_chi2(&G2oGraph::Se2(g.clone()))
    );
    assert!(r.final_cost <= 216.0, "log-map chi2 {}", r.final_cost);
    let config = SolverConfig {
        error_model: ErrorModel::G2o,
        ..SolverConfig::default()
    };
    let mut g = file_guess.clone();
    let r = GaussNewton::new(config).optimize(&mut g).unwrap();
    let chi2 = g2o_chi2(&G2oGraph::Se2(g));
    eprintln!(
        "INTEL g2o convention: GN {} iterations, g2o chi2 {chi2}",
        r.iterations
    );
    assert!(chi2 <= 216.0, "g2o chi2 {chi2}");
    assert_rel(r.final_cost, chi2, 1e-12, "reported cost vs g2o_chi2");
    // LM from the file's guess crawls along a curved valley (GN's path goes uphill first); from
    // the chordal guess (g2o chi2 220.6 already) it reaches the optimum.
    let mut g = file_guess;
    posegraph::initialize_chordal(&mut g).unwrap();
    let r = LevenbergMarquardt::new(config).optimize(&mut g).unwrap();
    let chi2 = g2o_chi2(&G2oGraph::Se2(g));
    eprintln!(
        "INTEL g2o convention: chordal + LM {} iterations ({:?}), g2o chi2 {} -> {chi2}",
        r.iterations, r.stop_reason, r.initial_cost
    );
    assert!(chi2 <= 216.0, "g2o chi2 {chi2}");
}

/// FR079 in TORO's format: LM reaches GTSAM's 37.5718.
#[test]
#[ignore = "reads the shared data folder; run with --ignored"]
fn fr079_toro() {
    let Some(p) = shared("FR079.graph") else {
        return;
    };
    let mut g = posegraph::toro::read_toro(p).unwrap();
    fix_first(&mut g);
    let r = LevenbergMarquardt::default().optimize(&mut g).unwrap();
    assert_rel(r.final_cost, 37.5718, 1e-4, "FR079");
}

#[test]
fn toro_information_order() {
    let g = posegraph::toro::parse_toro(
        "VERTEX2 0 0 0 0\nVERTEX2 1 1 0 0\nEDGE2 0 1 1 0 0 10 1 20 30 2 3\n",
    )
    .unwrap();
    let i = g.edges()[0].information;
    assert_eq!(
        (
            i[(0, 0)],
            i[(0, 1)],
            i[(1, 1)],
            i[(2, 2)],
            i[(0, 2)],
            i[(1, 2)]
        ),
        (10.0, 1.0, 20.0, 30.0, 2.0, 3.0)
    );
    assert!(posegraph::toro::parse_toro("VERTEX2 0 0 0 0\nFOO 1\n").is_err());
}

/// Minimising g2o's own error reaches g2o's optimum in g2o's convention (g2o-python's GN, shared
/// README): tinyGrid3D 6.72788, smallGrid3D 458.154, `input_M3500_g2o` 137.913.
#[test]
fn g2o_error_model_reaches_g2o_optimum() {
    if slam_core::skip_without_test_data!("tests/data") {
        return;
    }
    let config = SolverConfig {
        error_model: ErrorModel::G2o,
        ..SolverConfig::default()
    };
    for (file, want) in [
        ("tinyGrid3D.g2o", 6.72788),
        ("smallGrid3D.g2o", 458.154),
        ("input_M3500_g2o.g2o", 137.913),
    ] {
        for lm in [true, false] {
            let mut graph = read_g2o(data(file)).unwrap();
            let r = match &mut graph {
                G2oGraph::Se3(g) => {
                    fix_first(g);
                    if lm {
                        LevenbergMarquardt::new(config).optimize(g)
                    } else {
                        GaussNewton::new(config).optimize(g)
                    }
                }
                G2oGraph::Se2(g) => {
                    fix_first(g);
                    if lm {
                        LevenbergMarquardt::new(config).optimize(g)
                    } else {
                        GaussNewton::new(config).optimize(g)
                    }
                }
            }
            .unwrap();
            let chi2 = g2o_chi2(&graph);
            assert_rel(chi2, want, 1e-4, file);
            assert_rel(r.final_cost, chi2, 1e-12, "reported cost vs g2o_chi2");
        }
    }
}
