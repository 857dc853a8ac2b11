//! Silent wrong results the solvers must not give (issue 17): an optimiser reused on a second
//! graph of the same size, and graphs whose cost is not finite at the start.
#![allow(clippy::unwrap_used, clippy::panic)]

use nalgebra::{Matrix3, Vector3};
use posegraph::{
    GaussNewton, GncConfig, GraduatedNonConvexity, LevenbergMarquardt, SolverPose,
    initialize_chordal,
};
use slam_core::{
    GraphPose, GraphValue, OptimizeError, Optimizer, Pose2, Pose3, PoseGraph, pose3_from_xyz_rpy,
    se2_exp,
};

/// A noisy SE(2) chain of `n` nodes (node 0 fixed) plus `loops` (node pairs), measurements from
/// a zig-zag truth with noise from `seed`.
fn se2_graph(n: u64, loops: &[(u64, u64)], seed: u64) -> PoseGraph<Pose2> {
    let mut r = crate::common::rng(seed);
    let truth: Vec<Pose2> = (0..n)
        .map(|i| {
            let x = i as f64;
            Pose2::new([x, 0.5 * (x * 0.7).sin()].into(), 0.3 * x)
        })
        .collect();
    let mut g = PoseGraph::new();
    for (i, p) in truth.iter().enumerate() {
        g.add_node(i as u64, *p).unwrap();
    }
    g.fix(0).unwrap();
    let info = Matrix3::from_diagonal(&Vector3::new(100.0, 100.0, 400.0));
    let pairs = (1..n).map(|i| (i - 1, i)).chain(loops.iter().copied());
    for (a, b) in pairs {
        let z = truth[a as usize].inverse() * truth[b as usize];
        let noise = se2_exp(&Vector3::new(0.1 * r(), 0.1 * r(), 0.05 * r()));
        g.add_edge(a, b, z * noise, info, None).unwrap();
    }
    // Start from odometry with a drift, so the loops have work to do.
    let mut pose = Pose2::identity();
    for k in 1..n as usize {
        pose *= g.edges()[k - 1].measurement * se2_exp(&Vector3::new(0.0, 0.0, 0.02));
        g.set_pose(k, pose);
    }
    g
}

/// The same for SE(3) (a helix).
fn se3_graph(n: u64, loops: &[(u64, u64)], seed: u64) -> PoseGraph<Pose3> {
    let mut r = crate::common::rng(seed);
    let truth: Vec<Pose3> = (0..n)
        .map(|i| {
            let x = i as f64;
            pose3_from_xyz_rpy(x.cos() * 3.0, x.sin() * 3.0, 0.2 * x, 0.05 * x, 0.0, x)
        })
        .collect();
    let mut g = PoseGraph::new();
    for (i, p) in truth.iter().enumerate() {
        g.add_node(
            i as u64,
            *p * pose3_from_xyz_rpy(0.1, 0.0, 0.0, 0.0, 0.0, 0.05),
        )
        .unwrap();
    }
    g.fix(0).unwrap();
    g.set_pose(0, truth[0]);
    let info = Pose3::identity_information() * 50.0;
    let pairs = (1..n).map(|i| (i - 1, i)).chain(loops.iter().copied());
    for (a, b) in pairs {
        let z = truth[a as usize].inverse() * truth[b as usize];
        let noise =
            pose3_from_xyz_rpy(0.1 * r(), 0.1 * r(), 0.1 * r(), 0.02 * r(), 0.0, 0.02 * r());
        g.add_edge(a, b, z * noise, info, None).unwrap();
    }
    g
}

/// Largest distance between the same node's positions in `a` and `b`.
fn max_gap<P: GraphPose>(
    a: &PoseGraph<P>,
    b: &PoseGraph<P>,
    position: fn(&P) -> nalgebra::Vector3<f64>,
) -> f64 {
    a.nodes()
        .iter()
        .zip(b.nodes())
        .map(|(x, y)| (position(&x.pose) - position(&y.pose)).norm())
        .fold(0.0, f64::max)
}

fn se2_position(p: &Pose2) -> nalgebra::Vector3<f64> {
    Vector3::new(p.translation.x, p.translation.y, 0.0)
}

fn se3_position(p: &Pose3) -> nalgebra::Vector3<f64> {
    p.translation.vector
}

/// `optimiser` run on `first`, then on `second` (same node and edge counts, same fixed node,
/// other edges): the second answer must equal a fresh optimiser's on `second`.
fn reused_equals_fresh<P: GraphPose, O: Optimizer<P>>(
    mut make: impl FnMut() -> O,
    first: &PoseGraph<P>,
    second: &PoseGraph<P>,
    position: fn(&P) -> nalgebra::Vector3<f64>,
) {
    assert_eq!(first.node_count(), second.node_count());
    assert_eq!(first.edge_count(), second.edge_count());
    let mut reused = make();
    reused.optimize(&mut first.clone()).unwrap();
    let mut by_reused = second.clone();
    let report = reused.optimize(&mut by_reused).unwrap();
    let mut by_fresh = second.clone();
    let fresh = make().optimize(&mut by_fresh).unwrap();
    assert!(
        (report.final_cost - fresh.final_cost).abs() <= 1e-9 * fresh.final_cost.max(1.0),
        "{report:?} vs {fresh:?}"
    );
    let gap = max_gap(&by_reused, &by_fresh, position);
    assert!(gap < 1e-9, "reused optimiser ends {gap} m from a fresh one");
    // And the answer is an optimum of `second`, not of `first`'s structure.
    assert!(fresh.final_cost < second.cost());
}

#[test]
fn an_optimiser_reused_on_a_graph_of_the_same_size_gives_a_fresh_ones_answer() {
    let a2 = se2_graph(12, &[(0, 11), (2, 9), (4, 7)], 1);
    let b2 = se2_graph(12, &[(1, 10), (3, 11), (0, 6)], 2);
    let a3 = se3_graph(10, &[(0, 9), (2, 7)], 3);
    let b3 = se3_graph(10, &[(1, 8), (0, 5)], 4);
    reused_equals_fresh(LevenbergMarquardt::default, &a2, &b2, se2_position);
    reused_equals_fresh(GaussNewton::default, &a2, &b2, se2_position);
    reused_equals_fresh(GraduatedNonConvexity::default, &a2, &b2, se2_position);
    reused_equals_fresh(LevenbergMarquardt::default, &a3, &b3, se3_position);
    reused_equals_fresh(GaussNewton::default, &a3, &b3, se3_position);
    reused_equals_fresh(GraduatedNonConvexity::default, &a3, &b3, se3_position);
    // Same edges, another node fixed: the pattern differs too.
    let mut c2 = a2.clone();
    c2.unfix(0).unwrap();
    c2.fix(5).unwrap();
    reused_equals_fresh(LevenbergMarquardt::default, &a2, &c2, se2_position);
}

/// Every optimiser's answer on `graph`, each from a copy.
fn every_solver<P: SolverPose>(
    graph: &PoseGraph<P>,
) -> Vec<(&'static str, Result<f64, OptimizeError>)>
where
    LevenbergMarquardt: Optimizer<P>,
    GaussNewton: Optimizer<P>,
    GraduatedNonConvexity: Optimizer<P>,
{
    let run = |o: &mut dyn Optimizer<P>| o.optimize(&mut graph.clone()).map(|r| r.final_cost);
    vec![
        ("LM", run(&mut LevenbergMarquardt::default())),
        ("GN", run(&mut GaussNewton::default())),
        ("GNC", run(&mut GraduatedNonConvexity::default())),
        (
            "GNC-GM",
            run(&mut GraduatedNonConvexity::try_new(GncConfig {
                loss: posegraph::GncLoss::GemanMcClure,
                ..GncConfig::default()
            })
            .unwrap()),
        ),
    ]
}

fn assert_all_refuse<P: SolverPose>(graph: &PoseGraph<P>, want: GraphValue, what: &str)
where
    LevenbergMarquardt: Optimizer<P>,
    GaussNewton: Optimizer<P>,
    GraduatedNonConvexity: Optimizer<P>,
{
    for (solver, got) in every_solver(graph) {
        assert_eq!(
            got,
            Err(OptimizeError::NonFinite { what: want }),
            "{solver} on {what}"
        );
    }
}

#[test]
fn a_nan_pose_set_through_the_api_is_an_error_in_every_solver() {
    let mut g2 = se2_graph(8, &[(0, 7)], 5);
    g2.set_pose(3, Pose2::new([f64::NAN, 0.0].into(), 0.0));
    assert_all_refuse(&g2, GraphValue::NodePose { id: 3 }, "SE(2) NaN pose");
    let mut g3 = se3_graph(8, &[(0, 7)], 6);
    g3.set_pose(4, Pose3::translation(0.0, f64::NAN, 0.0));
    assert_all_refuse(&g3, GraphValue::NodePose { id: 4 }, "SE(3) NaN pose");
    // The chordal initialisation anchors on the fixed node: a NaN there is an error too.
    let mut g3 = se3_graph(8, &[(0, 7)], 6);
    g3.set_pose(0, Pose3::translation(f64::NAN, 0.0, 0.0));
    assert!(initialize_chordal(&mut g3).is_err());
}

#[test]
fn a_measurement_of_1e200_m_is_an_error_in_every_solver() {
    // Finite numbers whose squared error overflows: every solver ended Ok(DampingExhausted)
    // with an infinite cost.
    let mut g2 = se2_graph(8, &[], 7);
    let info = g2.edges()[0].information;
    g2.add_edge(0, 7, Pose2::new([1e200, 0.0].into(), 0.0), info, None)
        .unwrap();
    let want = GraphValue::EdgeError {
        edge: 7,
        from: 0,
        to: 7,
    };
    assert_all_refuse(&g2, want, "SE(2) 1e200 m loop");
    let mut g3 = se3_graph(8, &[], 8);
    let info = g3.edges()[0].information;
    g3.add_edge(2, 6, Pose3::translation(0.0, 0.0, 1e200), info, None)
        .unwrap();
    let want = GraphValue::EdgeError {
        edge: 7,
        from: 2,
        to: 6,
    };
    assert_all_refuse(&g3, want, "SE(3) 1e200 m loop");
    // A pose of 1e200 m set through the API: the same.
    let mut g3 = se3_graph(8, &[], 8);
    g3.set_pose(5, Pose3::translation(1e200, 0.0, 0.0));
    for (solver, got) in every_solver(&g3) {
        assert!(
            matches!(
                got,
                Err(OptimizeError::NonFinite {
                    what: GraphValue::EdgeError { .. }
                })
            ),
            "{solver}: {got:?}"
        );
    }
}
