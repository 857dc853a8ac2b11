//! A graph with known ground truth and 10 % wrong loop closures: with a robust kernel on the
//! loops every pose ends within 5 cm of the truth.
#![allow(clippy::unwrap_used)]

use crate::common::rng;
use nalgebra::{Matrix6, Vector6};
use posegraph::LevenbergMarquardt;
use slam_core::{Optimizer, Pose3, PoseGraph, RobustKernel, pose3_from_xyz_rpy, se3_exp};

#[test]
fn wrong_loops_are_ignored_with_a_robust_kernel() {
    let mut r = rng(7);
    let n_lap = 50;
    // Two laps of a circle of radius 6 m, gently rising and falling.
    let truth: Vec<Pose3> = (0..2 * n_lap)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n_lap as f64;
            pose3_from_xyz_rpy(
                6.0 * a.cos(),
                6.0 * a.sin(),
                0.2 * (2.0 * a).sin(),
                0.0,
                0.0,
                a + std::f64::consts::FRAC_PI_2,
            )
        })
        .collect();
    let (st, sr) = (0.01, 0.2f64.to_radians());
    let info = Matrix6::from_diagonal(&Vector6::new(
        1.0 / (st * st),
        1.0 / (st * st),
        1.0 / (st * st),
        1.0 / (sr * sr),
        1.0 / (sr * sr),
        1.0 / (sr * sr),
    ));
    let mut noise = |scale: f64| {
        se3_exp(
            &Vector6::new(r() * st, r() * st, r() * st, r() * sr, r() * sr, r() * sr).scale(scale),
        )
    };
    let mut g = PoseGraph::<Pose3>::new();
    // Initial guess: the truth with a drift that grows along the trajectory (up to about 1 m).
    for (i, t) in truth.iter().enumerate() {
        let k = i as f64 / truth.len() as f64;
        g.add_node(
            i as u64,
            pose3_from_xyz_rpy(0.8 * k, -0.5 * k, 0.1 * k, 0.0, 0.0, 0.1 * k) * t,
        )
        .unwrap();
    }
    g.fix(0).unwrap();
    for i in 1..truth.len() {
        let z = truth[i - 1].inverse() * truth[i] * noise(0.3);
        g.add_edge(i as u64 - 1, i as u64, z, info, None).unwrap();
    }
    let kernel = Some(RobustKernel::Cauchy { c: 1.0 });
    let mut loops = 0;
    for i in n_lap..2 * n_lap {
        let j = i - n_lap;
        let z = truth[j].inverse() * truth[i] * noise(0.3);
        g.add_edge(j as u64, i as u64, z, info, kernel).unwrap();
        loops += 1;
    }
    // 10 % wrong loop closures: plausible-looking but wrong by 0.5 to 2 m and up to 30 degrees.
    let mut r2 = rng(99);
    let wrong = loops / 10;
    for k in 0..wrong {
        let i = n_lap + 3 + 9 * k;
        let j = (i * 7 + 11) % n_lap;
        let bogus = truth[j].inverse()
            * truth[i]
            * pose3_from_xyz_rpy(0.5 + 3.0 * r2().abs(), 1.5 * r2(), 0.0, 0.0, 0.0, r2());
        g.add_edge(j as u64, i as u64, bogus, info, kernel).unwrap();
    }
    let report = LevenbergMarquardt::default().optimize(&mut g).unwrap();
    let worst = g
        .nodes()
        .iter()
        .zip(&truth)
        .map(|(n, t)| (n.pose.translation.vector - t.translation.vector).norm())
        .fold(0.0, f64::max);
    assert!(worst < 0.05, "worst position error {worst} m ({report:?})");
    // Without the kernel the wrong loops bend the map.
    let mut plain = PoseGraph::<Pose3>::new();
    for n in g.nodes() {
        plain.add_node(n.id, truth[n.id as usize]).unwrap();
    }
    plain.fix(0).unwrap();
    for e in g.edges() {
        plain
            .add_edge(
                g.nodes()[e.from].id,
                g.nodes()[e.to].id,
                e.measurement,
                e.information,
                None,
            )
            .unwrap();
    }
    LevenbergMarquardt::default().optimize(&mut plain).unwrap();
    let worst_plain = plain
        .nodes()
        .iter()
        .zip(&truth)
        .map(|(n, t)| (n.pose.translation.vector - t.translation.vector).norm())
        .fold(0.0, f64::max);
    assert!(
        worst_plain > 0.1,
        "the wrong loops must matter without a kernel: {worst_plain} m"
    );
}
