//! Reading graphs whose information matrices are not positive definite: refused by default,
//! repaired on request (nearest positive-definite matrix), every repair reported.
#![allow(clippy::unwrap_used, clippy::panic)]

use posegraph::LevenbergMarquardt;
use posegraph::g2o::{G2oGraph, g2o_text_se3, parse_g2o, parse_g2o_with, read_g2o, read_g2o_with};
use posegraph::information_repair::InformationRepair;
use slam_core::{GraphPose, Optimizer, Pose3, StopReason};

/// The bundled smallGrid3D with a z-roll cross term of 1.5 `sqrt(I_zz I_roll)` written into every
/// third edge's information (a symmetric, indefinite matrix); returns the text and how many
/// edges are indefinite.
fn with_indefinite_edges() -> (String, usize) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/smallGrid3D.g2o");
    let G2oGraph::Se3(g) = read_g2o(path).unwrap() else {
        panic!("smallGrid3D is 3D")
    };
    let text = g2o_text_se3(&g);
    let mut bad = 0;
    let mut out = String::new();
    let mut edge = 0;
    for line in text.lines() {
        if line.starts_with("EDGE_SE3:QUAT") {
            if edge % 3 == 0 {
                let e = &g.edges()[edge];
                let mut info = e.information;
                let cross = 1.5 * (info[(2, 2)] * info[(3, 3)]).sqrt();
                info[(2, 3)] = cross;
                info[(3, 2)] = cross;
                if !Pose3::information_is_valid(&info) {
                    bad += 1;
                }
                let mut words: Vec<String> = line.split_whitespace().map(String::from).collect();
                // Upper-triangle order: row 2 starts at 7 + 6 + 5 = 18; (2, 3) is the next one.
                words[3 + 7 + 11 + 1] = format!("{cross}");
                out.push_str(&words.join(" "));
                out.push('\n');
                edge += 1;
                continue;
            }
            edge += 1;
        }
        out.push_str(line);
        out.push('\n');
    }
    (out, bad)
}

#[test]
fn indefinite_information_is_refused_by_default_and_repaired_on_request() {
    if slam_core::skip_without_test_data!("tests/data") {
        return;
    }
    let (text, bad) = with_indefinite_edges();
    assert!(bad > 90, "{bad} indefinite edges");
    let refused = parse_g2o(&text).unwrap_err();
    assert!(
        refused.to_string().contains("--repair-information"),
        "{refused}"
    );
    let (graph, repaired) =
        parse_g2o_with(&text, InformationRepair::nearest_positive_definite()).unwrap();
    // Every indefinite edge, and only those, was repaired and reported.
    assert_eq!(repaired.len(), bad);
    assert!(
        repaired
            .iter()
            .all(|r| r.edge % 3 == 0 && r.smallest_eigenvalue < 0.0)
    );
    let G2oGraph::Se3(mut g) = graph else {
        panic!()
    };
    for r in &repaired {
        assert!(Pose3::information_is_valid(&g.edges()[r.edge].information));
    }
    // And the repaired graph optimises.
    g.fix(g.nodes()[0].id).unwrap();
    let report = LevenbergMarquardt::default().optimize(&mut g).unwrap();
    assert_ne!(report.stop_reason, StopReason::MaxIterations, "{report:?}");
    assert!(report.final_cost.is_finite() && report.final_cost < report.initial_cost);
}

/// The public SE(3) sets of the shared data folder: how many edges each needs repaired (none
/// must change for a set whose matrices are all positive definite).
#[test]
#[ignore = "reads the shared data folder; run with --ignored"]
fn shared_se3_sets_load_with_repair() {
    for name in [
        "sphere2500.g2o",
        "parking-garage.g2o",
        "torus3D.g2o",
        "sphere_bignoise_vertex3.g2o",
    ] {
        let path =
            crate::common::shared(name).unwrap_or_else(|| panic!("{name} not in the shared data"));
        let plain = read_g2o(&path);
        let (_, repaired) =
            read_g2o_with(&path, InformationRepair::nearest_positive_definite()).unwrap();
        eprintln!("{name}: {} edges repaired", repaired.len());
        assert_eq!(plain.is_ok(), repaired.is_empty(), "{name}");
    }
}
