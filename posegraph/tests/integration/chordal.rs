//! Chordal initialisation: a synthetic graph whose initial guess has random rotations lands on
//! the ground truth; torus3D (chordal + LM) reaches SE-Sync's certified optimum, where LM from
//! the file's own guess stops in a local minimum.
#![allow(clippy::unwrap_used, clippy::panic)]

use crate::common::{rng, shared};
use std::time::Instant;

use nalgebra::{Matrix3, Matrix6, Vector2, Vector3, Vector6};
use posegraph::g2o::{G2oGraph, read_g2o};
use posegraph::{LevenbergMarquardt, initialize_chordal};
use slam_core::{Optimizer, Pose2, Pose3, PoseGraph, pose3_from_xyz_rpy, se2_exp, se3_exp};

/// A 4 x 4 x 3 grid of poses with random headings, odometry along a snake path and every grid
/// neighbour as a loop edge; measurements with noise of `sigma_t` metres and `sigma_r` radians.
fn grid3(sigma_t: f64, sigma_r: f64, seed: u64) -> (Vec<Pose3>, PoseGraph<Pose3>) {
    let mut r = rng(seed);
    let (nx, ny, nz) = (4usize, 4usize, 3usize);
    let mut truth = Vec::new();
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                truth.push(pose3_from_xyz_rpy(
                    x as f64,
                    y as f64,
                    z as f64,
                    3.0 * r(),
                    3.0 * r(),
                    6.0 * r(),
                ));
            }
        }
    }
    let info = Matrix6::from_diagonal(&Vector6::new(
        1.0 / (sigma_t * sigma_t),
        1.0 / (sigma_t * sigma_t),
        1.0 / (sigma_t * sigma_t),
        1.0 / (sigma_r * sigma_r),
        1.0 / (sigma_r * sigma_r),
        1.0 / (sigma_r * sigma_r),
    ));
    let mut g = PoseGraph::new();
    for (i, _) in truth.iter().enumerate() {
        // The initial guess: every rotation random, every position off by up to 2 m.
        let guess = pose3_from_xyz_rpy(
            4.0 * r(),
            4.0 * r(),
            4.0 * r(),
            6.0 * r(),
            6.0 * r(),
            6.0 * r(),
        );
        g.add_node(i as u64, if i == 0 { truth[0] } else { guess })
            .unwrap();
    }
    g.fix(0).unwrap();
    let idx = |x: usize, y: usize, z: usize| (z * ny + y) * nx + x;
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                for (dx, dy, dz) in [(1, 0, 0), (0, 1, 0), (0, 0, 1)] {
                    let (x2, y2, z2) = (x + dx, y + dy, z + dz);
                    if x2 < nx && y2 < ny && z2 < nz {
                        let (a, b) = (idx(x, y, z), idx(x2, y2, z2));
                        let noise = se3_exp(&Vector6::new(
                            r() * sigma_t,
                            r() * sigma_t,
                            r() * sigma_t,
                            r() * sigma_r,
                            r() * sigma_r,
                            r() * sigma_r,
                        ));
                        let z = truth[a].inverse() * truth[b] * noise;
                        g.add_edge(a as u64, b as u64, z, info, None).unwrap();
                    }
                }
            }
        }
    }
    (truth, g)
}

fn max_errors(truth: &[Pose3], g: &PoseGraph<Pose3>) -> (f64, f64) {
    let mut worst = (0.0f64, 0.0f64);
    for (t, n) in truth.iter().zip(g.nodes()) {
        let d = t.inverse() * n.pose;
        worst.0 = worst.0.max(d.translation.vector.norm());
        worst.1 = worst.1.max(d.rotation.angle());
    }
    worst
}

#[test]
fn exact_measurements_give_the_truth_from_random_rotations() {
    let (truth, mut g) = grid3(1e-12, 1e-12, 3);
    let before = max_errors(&truth, &g);
    assert!(before.1 > 2.0, "the guess is far: {before:?}");
    initialize_chordal(&mut g).unwrap();
    let (dt, dr) = max_errors(&truth, &g);
    assert!(dt < 1e-8 && dr < 1e-8, "{dt} m, {dr} rad");
}

#[test]
fn noisy_measurements_land_near_the_truth_and_lm_finishes() {
    // 2 cm and 2 degrees of noise per edge.
    let (truth, mut g) = grid3(0.02, 2f64.to_radians(), 5);
    initialize_chordal(&mut g).unwrap();
    let (dt, dr) = max_errors(&truth, &g);
    eprintln!(
        "chordal: {dt} m, {} deg, cost {}",
        dr.to_degrees(),
        g.cost()
    );
    assert!(dt < 0.1 && dr < 3f64.to_radians(), "{dt} m, {dr} rad");
    let chordal_cost = g.cost();
    let r = LevenbergMarquardt::default().optimize(&mut g).unwrap();
    let (dt, dr) = max_errors(&truth, &g);
    eprintln!(
        "LM: {dt} m, {} deg, cost {chordal_cost} -> {}",
        dr.to_degrees(),
        r.final_cost
    );
    assert!(dt < 0.1 && dr < 3f64.to_radians(), "{dt} m, {dr} rad");
}

/// `n` poses evenly around a circle of `radius`, each heading its polar angle plus `offset`.
fn ring(n: u32, radius: f64, offset: f64) -> Vec<Pose2> {
    (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * f64::from(i) / f64::from(n);
            Pose2::new(Vector2::new(radius * a.cos(), radius * a.sin()), a + offset)
        })
        .collect()
}

#[test]
fn se2_ring_from_random_headings() {
    let mut r = rng(11);
    let n = 40;
    let truth = ring(n, 5.0, 1.0);
    let mut g = PoseGraph::new();
    for (i, t) in truth.iter().enumerate() {
        let guess = Pose2::new(Vector2::new(10.0 * r(), 10.0 * r()), 6.0 * r());
        g.add_node(i as u64, if i == 0 { *t } else { guess })
            .unwrap();
    }
    g.fix(0).unwrap();
    let info = Matrix3::from_diagonal(&Vector3::new(1e4, 1e4, 1e4));
    for i in 0..n as usize {
        for step in [1, 7] {
            let j = (i + step) % n as usize;
            let noise = se2_exp(&Vector3::new(0.005 * r(), 0.005 * r(), 0.01 * r()));
            g.add_edge(
                i as u64,
                j as u64,
                truth[i].inverse() * truth[j] * noise,
                info,
                None,
            )
            .unwrap();
        }
    }
    initialize_chordal(&mut g).unwrap();
    for (t, nd) in truth.iter().zip(g.nodes()) {
        let d = t.inverse() * nd.pose;
        assert!(
            d.translation.vector.norm() < 0.05 && d.rotation.angle().abs() < 0.02,
            "{d:?}"
        );
    }
}

/// torus3D: LM from the chordal guess reaches SE-Sync's certified optimum 2.423e4 (our cost is
/// `sum e^T Omega e`; GTSAM 4.3 from its chordal guess: 24235.3), where LM from the file's guess
/// stops in a local minimum (GTSAM: 59907.6).
#[test]
#[ignore = "reads the shared data folder; run with --ignored"]
fn torus3d_reaches_the_global_optimum() {
    let Some(p) = shared("torus3D.g2o") else {
        eprintln!("torus3D.g2o not found; skipped");
        return;
    };
    let G2oGraph::Se3(mut g) = read_g2o(p).unwrap() else {
        panic!("a 3D file")
    };
    g.fix(g.nodes()[0].id).unwrap();
    let t = Instant::now();
    initialize_chordal(&mut g).unwrap();
    let chordal_ms = t.elapsed().as_secs_f64() * 1e3;
    let chordal_cost = g.cost();
    let r = LevenbergMarquardt::default().optimize(&mut g).unwrap();
    eprintln!(
        "torus3D: chordal cost {chordal_cost} ({chordal_ms:.0} ms), LM {} iterations -> {} ({:?}), total {:.0} ms",
        r.iterations,
        r.final_cost,
        r.stop_reason,
        t.elapsed().as_secs_f64() * 1e3
    );
    assert!(r.final_cost <= 24_240.0, "chi2 {}", r.final_cost);
}

#[test]
fn two_fixed_nodes_anchor_the_solution_and_bad_graphs_are_errors() {
    // A ring whose nodes 0 and 20 are both fixed at the truth, everything else random.
    let mut r = rng(21);
    let n = 40;
    let truth = ring(n, 3.0, -0.5);
    let mut g = PoseGraph::new();
    for (i, t) in truth.iter().enumerate() {
        let fixed = i == 0 || i == 20;
        let guess = Pose2::new(Vector2::new(5.0 * r(), 5.0 * r()), 6.0 * r());
        g.add_node(i as u64, if fixed { *t } else { guess })
            .unwrap();
    }
    g.fix(0).unwrap();
    g.fix(20).unwrap();
    let info = Matrix3::identity();
    for i in 0..n as usize {
        let j = (i + 1) % n as usize;
        g.add_edge(
            i as u64,
            j as u64,
            truth[i].inverse() * truth[j],
            info,
            None,
        )
        .unwrap();
    }
    // An edge between the two fixed nodes changes nothing.
    g.add_edge(0, 20, truth[0].inverse() * truth[20], info, None)
        .unwrap();
    initialize_chordal(&mut g).unwrap();
    for (t, nd) in truth.iter().zip(g.nodes()) {
        let d = t.inverse() * nd.pose;
        assert!(d.translation.vector.norm() < 1e-9 && d.rotation.angle().abs() < 1e-9);
    }
    // Every node fixed: nothing to do.
    let mut all_fixed = g.clone();
    for i in 0..u64::from(n) {
        all_fixed.fix(i).unwrap();
    }
    initialize_chordal(&mut all_fixed).unwrap();
    let report = LevenbergMarquardt::default()
        .optimize(&mut all_fixed)
        .unwrap();
    assert_eq!(report.stop_reason, slam_core::StopReason::NothingToDo);
    // No fixed node, and a node connected to nothing: errors.
    let mut free = PoseGraph::<Pose2>::new();
    free.add_node(0, Pose2::identity()).unwrap();
    free.add_node(1, Pose2::identity()).unwrap();
    free.add_edge(0, 1, Pose2::identity(), info, None).unwrap();
    assert!(matches!(
        initialize_chordal(&mut free),
        Err(slam_core::OptimizeError::NoFixedNode)
    ));
    free.add_node(2, Pose2::identity()).unwrap();
    free.fix(0).unwrap();
    assert!(matches!(
        initialize_chordal(&mut free),
        Err(slam_core::OptimizeError::Disconnected { .. })
    ));
}
