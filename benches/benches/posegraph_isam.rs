//! The incremental smoother (`posegraph::IncrementalSmoother`) against a whole-graph solve per
//! loop closure, at 3,500-4,000 poses: prints the table recorded in `posegraph/README.md`.
//!
//! Each graph is fed one element at a time in its own order (a new pose with its odometry edge,
//! then each loop edge), with an update after each. An update that adds a loop edge is timed as
//! "per loop"; once the graph holds `WINDOW_FROM` poses, every `SAMPLE_EVERY`-th loop closure is
//! also solved whole by Levenberg-Marquardt (a fresh solver: the structure changed, so the
//! ordering and symbolic factorisation are new anyway) from the same warm start (the previous
//! estimate, the new pose from odometry), on a copy made outside the timed region. At the end
//! the smoother converges and its cost is checked against LM's on the final graph.
//!
//! Graphs: `input_M3500_g2o` (bundled with posegraph's tests, SE(2), 3,500 poses, 1,953 loop
//! edges; fed in online order, each edge when its newer pose arrives) and a synthetic SE(3) patrol: ten laps of a 400-pose ring (0.3 m steps, 2 cm / 0.2
//! degree odometry noise), every third pose from the second lap on closing a loop to the same
//! place one lap before (the SLAM engine's revisits: a loop every few keyframes).
//!
//! `cargo bench -p spot-nav-benches --bench posegraph_isam`

// A solver error must stop the bench: its figures would be meaningless.
#![allow(clippy::panic, clippy::unwrap_used)]

use std::time::Instant;

use posegraph::g2o::{G2oGraph, read_g2o};
use posegraph::{IncrementalSmoother, LevenbergMarquardt};
use rand_pcg::Pcg64Mcg;
use rand_pcg::rand_core::{Rng, SeedableRng};
use slam_core::{
    Edge, GraphPose, IncrementalOptimizer, Optimizer, Pose2, Pose3, PoseGraph, pose3_from_xyz_rpy,
};

/// Loops are timed against LM once the graph holds this many poses.
const WINDOW_FROM: usize = 3000;
/// Every this many loop closures in the window, LM solves the whole graph.
const SAMPLE_EVERY: usize = 10;

/// An edge with its endpoints' ids, in the order it is fed.
type IdEdge<P> = (u64, u64, Edge<P>);

/// A pose's `compose` and `inverse`, so one feeding loop serves both pose types.
trait Compose: GraphPose {
    fn then(&self, other: &Self) -> Self;
    fn inverted(&self) -> Self;
}
impl Compose for Pose2 {
    fn then(&self, other: &Self) -> Self {
        self * other
    }
    fn inverted(&self) -> Self {
        self.inverse()
    }
}
impl Compose for Pose3 {
    fn then(&self, other: &Self) -> Self {
        self * other
    }
    fn inverted(&self) -> Self {
        self.inverse()
    }
}

/// Milliseconds of a list of seconds: mean, median, 99th percentile, largest.
fn summary(times: &mut [f64]) -> (f64, f64, f64, f64) {
    times.sort_by(f64::total_cmp);
    let at = |q: f64| times[((times.len() - 1) as f64 * q).round() as usize] * 1e3;
    let mean = times.iter().sum::<f64>() / times.len() as f64 * 1e3;
    (mean, at(0.5), at(0.99), at(1.0))
}

/// Feed `edges` in order, from the `first` node (id, pose; fixed); print the figures.
fn run<P>(name: &str, first: (u64, P), edges: &[IdEdge<P>])
where
    P: Compose,
    IncrementalSmoother: IncrementalOptimizer<P>,
    LevenbergMarquardt: Optimizer<P>,
{
    let mut g = PoseGraph::<P>::new();
    g.add_node(first.0, first.1).unwrap();
    g.fix(first.0).unwrap();
    let mut smoother = IncrementalSmoother::default();
    let (mut loop_times, mut odometry_times, mut batch_times) =
        (Vec::new(), Vec::new(), Vec::new());
    let (mut loops_in_window, mut refactored_share) = (0usize, 0.0);
    let total = Instant::now();
    for (a, b, e) in edges {
        match (g.pose(*a).copied(), g.pose(*b).copied()) {
            (Some(pa), None) => {
                g.add_node(*b, pa.then(&e.measurement)).unwrap();
            }
            (None, Some(pb)) => {
                g.add_node(*a, pb.then(&e.measurement.inverted())).unwrap();
            }
            _ => {}
        }
        g.add_edge(*a, *b, e.measurement, e.information, e.kernel)
            .unwrap();
        let is_loop = a.abs_diff(*b) > 1;
        let in_window = g.node_count() >= WINDOW_FROM;
        if is_loop && in_window {
            loops_in_window += 1;
            if loops_in_window % SAMPLE_EVERY == 0 {
                let mut copy = g.clone();
                let t = Instant::now();
                LevenbergMarquardt::default().optimize(&mut copy).unwrap();
                batch_times.push(t.elapsed().as_secs_f64());
            }
        }
        let t = Instant::now();
        let report = smoother.update(&mut g).unwrap();
        let dt = t.elapsed().as_secs_f64();
        if in_window {
            if is_loop {
                loop_times.push(dt);
                refactored_share += report.refactored as f64 / report.variables as f64;
            } else {
                odometry_times.push(dt);
            }
        }
    }
    let feed = total.elapsed().as_secs_f64() - batch_times.iter().sum::<f64>();
    let mut converged = g.clone();
    smoother.optimize(&mut converged).unwrap();
    let mut batch = g.clone();
    LevenbergMarquardt::default().optimize(&mut batch).unwrap();
    let share = refactored_share / loop_times.len().max(1) as f64;
    // Every update in the window (the odometry steps carry the relinearisations a loop causes)
    // over the loops in it.
    let amortised = (loop_times.iter().sum::<f64>() + odometry_times.iter().sum::<f64>()) * 1e3
        / loop_times.len().max(1) as f64;
    let (lm, lm50, lm99, lmmax) = summary(&mut loop_times);
    let (om, _, om99, _) = summary(&mut odometry_times);
    let (bm, b50, _, _) = summary(&mut batch_times);
    println!(
        "{name}: {} poses, {} edges; whole feed {:.2} s ({:.3} ms an element)",
        g.node_count(),
        g.edge_count(),
        feed,
        feed * 1e3 / edges.len() as f64
    );
    println!(
        "  from pose {WINDOW_FROM}: incremental per loop mean {lm:.3} ms (median {lm50:.3}, p99 \
         {lm99:.3}, max {lmmax:.3}; {} loops, {:.1} % of the poses re-factored on average); per \
         odometry step mean {om:.3} ms (p99 {om99:.3})",
        loop_times.len(),
        share * 100.0
    );
    println!(
        "  whole-graph LM per loop (warm start, {} samples) mean {bm:.2} ms (median {b50:.2}): \
         incremental {:.1}x faster (means), {:.1}x (medians); every update in the window over \
         its loops {amortised:.3} ms a loop: {:.1}x faster",
        batch_times.len(),
        bm / lm,
        b50 / lm50,
        bm / amortised
    );
    let (c, want) = (converged.cost(), batch.cost());
    println!(
        "  converged cost {c:.6} against LM's {want:.6} (relative {:.1e}); as fed, before \
         converging: {:.6}",
        (c - want).abs() / want,
        g.cost()
    );
}

/// The edges of a g2o file with their endpoint ids, and its first node.
fn file_edges<P: GraphPose>(g: &PoseGraph<P>) -> ((u64, P), Vec<IdEdge<P>>) {
    let nodes = g.nodes();
    let edges = g
        .edges()
        .iter()
        .map(|e| (nodes[e.from].id, nodes[e.to].id, *e))
        .collect();
    ((nodes[0].id, nodes[0].pose), edges)
}

/// Ten laps of a ring of `per_lap` poses, loops every third pose to the previous lap.
fn patrol(per_lap: usize, laps: usize) -> Vec<IdEdge<Pose3>> {
    let mut rng = Pcg64Mcg::seed_from_u64(34);
    let mut r = move || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
    let yaw = std::f64::consts::TAU / per_lap as f64;
    let step = pose3_from_xyz_rpy(0.3, 0.0, 0.0, 0.0, 0.0, yaw);
    let mut info = Pose3::identity_information();
    for k in 0..3 {
        info[(k, k)] = 1.0 / (0.02 * 0.02);
        info[(k + 3, k + 3)] = 1.0 / (0.0035 * 0.0035);
    }
    let mut noisy = |z: Pose3| {
        z * pose3_from_xyz_rpy(
            0.04 * r(),
            0.04 * r(),
            0.04 * r(),
            0.007 * r(),
            0.007 * r(),
            0.007 * r(),
        )
    };
    let edge = |to: usize, z: Pose3| Edge {
        from: 0,
        to,
        measurement: z,
        information: info,
        kernel: None,
    };
    let mut out = Vec::new();
    for i in 1..per_lap * laps {
        out.push((i as u64 - 1, i as u64, edge(i, noisy(step))));
        if i >= per_lap && i % 3 == 0 {
            // The same place one lap before: the truth is the identity.
            out.push((
                (i - per_lap) as u64,
                i as u64,
                edge(i, noisy(Pose3::identity())),
            ));
        }
    }
    out
}

fn main() {
    // Cargo passes `--bench`; this binary has no options of its own.
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../posegraph/tests/data/input_M3500_g2o.g2o");
    match read_g2o(&file).unwrap() {
        G2oGraph::Se2(g) => {
            let (first, mut edges) = file_edges::<Pose2>(&g);
            // Online order: each edge when its newer pose arrives (the file lists the whole
            // odometry chain first, then every loop).
            edges.sort_by_key(|&(a, b, _)| a.max(b));
            run("input_M3500_g2o (SE(2))", first, &edges);
        }
        G2oGraph::Se3(_) => panic!("input_M3500_g2o is an SE(2) file"),
    }
    run(
        "patrol, 10 laps of 400 poses (SE(3))",
        (0, Pose3::identity()),
        &patrol(400, 10),
    );
}
