//! The incremental smoother against the batch solver (LM) as oracle: the bundled graphs fed edge
//! by edge in file order, random graphs (proptest), and bad input.
#![allow(clippy::unwrap_used, clippy::panic)]

use std::path::PathBuf;

use posegraph::g2o::{G2oGraph, read_g2o};
use posegraph::{IncrementalConfig, IncrementalSmoother, LevenbergMarquardt};
use proptest::prelude::*;
use slam_core::{
    GraphPose, GraphValue, IncrementalOptimizer, OptimizeError, Optimizer, Pose2, Pose3, PoseGraph,
    pose3_from_xyz_rpy,
};

use crate::common::rng;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// `file`'s edges fed one at a time in file order into a graph that starts empty: an endpoint
/// not seen yet enters with the other end's current estimate composed with the measurement (the
/// first node, fixed, with the file's pose); the smoother updates after each edge. Returns the
/// grown graph, converged by `optimize`, and the largest share of the free nodes one update
/// re-factored after the first hundred nodes.
fn feed<P>(
    file: &PoseGraph<P>,
    compose: fn(&P, &P) -> P,
    inverse: fn(&P) -> P,
) -> (PoseGraph<P>, f64)
where
    P: GraphPose,
    IncrementalSmoother: IncrementalOptimizer<P>,
{
    let mut g = PoseGraph::<P>::new();
    let first = file.nodes()[0];
    g.add_node(first.id, first.pose).unwrap();
    g.fix(first.id).unwrap();
    let mut smoother = IncrementalSmoother::default();
    let mut refactored_mean = (0.0, 0usize);
    for e in file.edges() {
        let (a, b) = (file.nodes()[e.from].id, file.nodes()[e.to].id);
        match (g.pose(a).copied(), g.pose(b).copied()) {
            (Some(pa), None) => {
                g.add_node(b, compose(&pa, &e.measurement)).unwrap();
            }
            (None, Some(pb)) => {
                g.add_node(a, compose(&pb, &inverse(&e.measurement)))
                    .unwrap();
            }
            (Some(_), Some(_)) => {}
            (None, None) => panic!("edge {a}-{b} joins two unseen nodes"),
        }
        g.add_edge(a, b, e.measurement, e.information, e.kernel)
            .unwrap();
        let r = smoother.update(&mut g).unwrap();
        if r.variables > 100 {
            refactored_mean.0 += r.refactored as f64 / r.variables as f64;
            refactored_mean.1 += 1;
        }
    }
    smoother.optimize(&mut g).unwrap();
    (g, refactored_mean.0 / refactored_mean.1.max(1) as f64)
}

/// LM's cost on `file` from the file's guess, with its first node fixed.
fn batch<P>(file: &PoseGraph<P>) -> f64
where
    P: GraphPose,
    LevenbergMarquardt: Optimizer<P>,
{
    let mut g = file.clone();
    g.fix(g.nodes()[0].id).unwrap();
    LevenbergMarquardt::default().optimize(&mut g).unwrap();
    g.cost()
}

fn assert_rel(got: f64, want: f64, tol: f64, what: &str) {
    assert!(
        ((got - want) / want).abs() <= tol,
        "{what}: incremental {got} vs batch {want}"
    );
}

fn compose3(a: &Pose3, b: &Pose3) -> Pose3 {
    a * b
}
fn inverse3(a: &Pose3) -> Pose3 {
    a.inverse()
}
fn compose2(a: &Pose2, b: &Pose2) -> Pose2 {
    a * b
}
fn inverse2(a: &Pose2) -> Pose2 {
    a.inverse()
}

#[test]
fn bundled_graphs_fed_edge_by_edge_reach_the_batch_cost() {
    for name in ["tinyGrid3D.g2o", "smallGrid3D.g2o", "input_M3500_g2o.g2o"] {
        let (got, want, share) = match read_g2o(data(name)).unwrap() {
            G2oGraph::Se3(file) => {
                let (g, share) = feed(&file, compose3, inverse3);
                (g.cost(), batch(&file), share)
            }
            G2oGraph::Se2(file) => {
                let (g, share) = feed(&file, compose2, inverse2);
                (g.cost(), batch(&file), share)
            }
        };
        eprintln!("{name}: incremental {got}, batch {want}, mean share re-factored {share:.3}");
        assert_rel(got, want, 1e-6, name);
    }
}

/// A whole file at once: `optimize` eliminates everything in minimum degree order and iterates
/// Gauss-Newton from the file's guess to LM's optimum.
#[test]
fn whole_files_at_once_reach_the_batch_cost() {
    for name in ["smallGrid3D.g2o", "input_M3500_g2o.g2o"] {
        let t = std::time::Instant::now();
        let (got, iterations, want) = match read_g2o(data(name)).unwrap() {
            G2oGraph::Se3(file) => {
                let mut g = file.clone();
                g.fix(g.nodes()[0].id).unwrap();
                let r = IncrementalSmoother::default().optimize(&mut g).unwrap();
                (r.final_cost, r.iterations, batch(&file))
            }
            G2oGraph::Se2(file) => {
                let mut g = file.clone();
                g.fix(g.nodes()[0].id).unwrap();
                let r = IncrementalSmoother::default().optimize(&mut g).unwrap();
                (r.final_cost, r.iterations, batch(&file))
            }
        };
        eprintln!(
            "{name}: {iterations} updates, {got} vs LM {want} ({:?} both)",
            t.elapsed()
        );
        assert_rel(got, want, 1e-6, name);
    }
}

/// A random walk of `n` poses: odometry with noise, `loops` loop edges from the newest pose back
/// to a random older one, each added when its newer end arrives; the smoother updates after
/// each pose. `step` and `noise` draw a motion and a measurement error from uniform numbers in
/// `[-0.5, 0.5)`. Returns the smoother's converged cost and LM's on the same final graph.
fn random_walk<P>(
    seed: u64,
    n: usize,
    loops: usize,
    step: fn(&mut dyn FnMut() -> f64) -> P,
    noise: fn(&mut dyn FnMut() -> f64) -> P,
    inverse: fn(&P) -> P,
) -> (f64, f64)
where
    P: GraphPose + std::ops::Mul<Output = P>,
    P::Information: std::ops::Mul<f64, Output = P::Information>,
    IncrementalSmoother: IncrementalOptimizer<P>,
    LevenbergMarquardt: Optimizer<P>,
{
    let mut r = rng(seed);
    let mut at_loop = vec![0usize; n];
    for _ in 0..loops {
        let k = 2 + ((r() + 0.5) * (n - 2) as f64) as usize;
        at_loop[k.min(n - 1)] += 1;
    }
    // Any pose serves as the fixed first one.
    let first = step(&mut || 0.0);
    let mut truth = vec![first];
    let mut g = PoseGraph::<P>::new();
    g.add_node(0, first).unwrap();
    g.fix(0).unwrap();
    let mut smoother = IncrementalSmoother::default();
    let info = P::identity_information() * 100.0;
    for i in 1..n {
        let s = step(&mut r);
        truth.push(truth[i - 1] * s);
        let z = s * noise(&mut r);
        let guess = *g.pose(i as u64 - 1).unwrap() * z;
        g.add_node(i as u64, guess).unwrap();
        g.add_edge(i as u64 - 1, i as u64, z, info, None).unwrap();
        for _ in 0..at_loop[i] {
            let j = ((r() + 0.5) * (i - 1) as f64) as usize;
            let z = inverse(&truth[j]) * truth[i] * noise(&mut r);
            g.add_edge(j as u64, i as u64, z, info, None).unwrap();
        }
        smoother.update(&mut g).unwrap();
    }
    let mut oracle = g.clone();
    smoother.optimize(&mut g).unwrap();
    LevenbergMarquardt::default().optimize(&mut oracle).unwrap();
    (g.cost(), oracle.cost())
}

fn step3(r: &mut dyn FnMut() -> f64) -> Pose3 {
    pose3_from_xyz_rpy(1.0, 0.3 * r(), 0.1 * r(), 0.05 * r(), 0.05 * r(), r())
}
fn noise3(r: &mut dyn FnMut() -> f64) -> Pose3 {
    pose3_from_xyz_rpy(
        0.05 * r(),
        0.05 * r(),
        0.05 * r(),
        0.02 * r(),
        0.02 * r(),
        0.02 * r(),
    )
}
fn step2(r: &mut dyn FnMut() -> f64) -> Pose2 {
    Pose2::new([1.0, 0.3 * r()].into(), r())
}
fn noise2(r: &mut dyn FnMut() -> f64) -> Pose2 {
    Pose2::new([0.05 * r(), 0.05 * r()].into(), 0.02 * r())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn random_graphs_reach_the_batch_cost(
        seed in 0u64..1_000_000,
        n in 3usize..120,
        loops in 0usize..40,
        three_d in any::<bool>(),
    ) {
        let (got, want) = if three_d {
            random_walk(seed, n, loops, step3, noise3, inverse3)
        } else {
            random_walk(seed, n, loops, step2, noise2, inverse2)
        };
        prop_assert!(
            (got - want).abs() <= 1e-6 * want.max(1e-12),
            "incremental {got} vs batch {want}"
        );
    }
}

#[test]
fn bad_input_is_an_error_and_the_smoother_recovers() {
    let info = Pose2::identity_information();
    let step = Pose2::new([1.0, 0.0].into(), 0.0);
    let mut g = PoseGraph::<Pose2>::new();
    g.add_node(0, Pose2::identity()).unwrap();
    g.fix(0).unwrap();
    g.add_node(1, step).unwrap();
    g.add_edge(0, 1, step, info, None).unwrap();
    let mut smoother = IncrementalSmoother::default();
    smoother.update(&mut g).unwrap();
    // A node id never added.
    assert_eq!(
        g.add_edge(1, 7, step, info, None),
        Err(OptimizeError::UnknownNode { id: 7 })
    );
    // A new node that nothing joins to the fixed one.
    g.add_node(2, step).unwrap();
    assert!(matches!(
        smoother.update(&mut g),
        Err(OptimizeError::Disconnected { first_id: 2, .. })
    ));
    // A NaN pose on a new node (set after it was added).
    g.set_pose(2, Pose2::new([f64::NAN, 0.0].into(), 0.0));
    g.add_edge(1, 2, step, info, None).unwrap();
    assert_eq!(
        smoother.update(&mut g),
        Err(OptimizeError::NonFinite {
            what: GraphValue::NodePose { id: 2 }
        })
    );
    // An edge whose squared error overflows.
    g.set_pose(2, Pose2::new([2.0, 0.0].into(), 0.0));
    g.add_edge(0, 2, Pose2::new([1e200, 0.0].into(), 0.0), info, None)
        .unwrap();
    assert!(matches!(
        IncrementalOptimizer::update(&mut smoother, &mut g),
        Err(OptimizeError::NonFinite {
            what: GraphValue::EdgeError { edge: 2, .. }
        })
    ));
    // The poses were left as they were; a sound graph then updates from scratch.
    assert_eq!(g.pose(2), Some(&Pose2::new([2.0, 0.0].into(), 0.0)));
    let mut sound = g.clone();
    let mut fresh = PoseGraph::<Pose2>::new();
    for n in &sound.nodes()[..3] {
        fresh.add_node(n.id, n.pose).unwrap();
    }
    fresh.fix(0).unwrap();
    fresh.add_edge(0, 1, step, info, None).unwrap();
    fresh.add_edge(1, 2, step, info, None).unwrap();
    sound = fresh;
    let r = smoother.update(&mut sound).unwrap();
    assert_eq!((r.new_nodes, r.new_edges, r.variables), (3, 2, 2));
    assert!(sound.cost() < 1e-20);
    // Settings are checked.
    let bad = IncrementalConfig {
        relinearize_threshold: f64::NAN,
        ..IncrementalConfig::default()
    };
    assert!(IncrementalSmoother::try_new(bad).is_err());
}

#[test]
fn the_statistics_tell_a_growing_graph_from_one_that_changed() {
    let info = Pose2::identity_information();
    let step = Pose2::new([1.0, 0.0].into(), 0.1);
    let mut g = PoseGraph::<Pose2>::new();
    g.add_node(0, Pose2::identity()).unwrap();
    g.fix(0).unwrap();
    let mut smoother = IncrementalSmoother::default();
    for i in 1..=20u64 {
        let guess = compose2(g.pose(i - 1).unwrap(), &step);
        g.add_node(i, guess).unwrap();
        g.add_edge(i - 1, i, step, info, None).unwrap();
        smoother.update(&mut g).unwrap();
    }
    // Appended only: never afresh, and an odometry step re-factors only the newest nodes.
    let chain = smoother.statistics();
    assert_eq!((chain.restarts, chain.updates), (0, 20), "{chain:?}");
    assert!(chain.refactored <= 2 * chain.updates, "{chain:?}");
    g.add_edge(0, 20, compose2(g.pose(20).unwrap(), &step), info, None)
        .unwrap();
    smoother.optimize(&mut g).unwrap();
    let grown = smoother.statistics();
    assert_eq!((grown.restarts, grown.optimizations), (0, 1), "{grown:?}");
    assert!(grown.updates > 20, "{grown:?}");
    // A fixed flag changed: the next update starts afresh, and says so.
    g.fix(10).unwrap();
    smoother.update(&mut g).unwrap();
    let changed = smoother.statistics();
    assert_eq!(changed.restarts, 1, "{changed:?}");
    assert_eq!(changed.updates, grown.updates + 1);
    // An error drops the state: counted too.
    g.add_node(21, step).unwrap();
    g.add_edge(20, 21, step, info, None).unwrap();
    g.set_pose(21, Pose2::new([f64::NAN, 0.0].into(), 0.0));
    assert!(smoother.update(&mut g).is_err());
    assert_eq!(smoother.statistics().restarts, 2);
}
