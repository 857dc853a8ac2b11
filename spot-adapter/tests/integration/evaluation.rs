//! ATE, alignment and drift against closed-form oracles.

// Test helpers outside #[test] functions unwrap too, and exact float equality is the point
// where stored values must round-trip bit for bit.
#![allow(clippy::unwrap_used, clippy::panic, clippy::float_cmp)]

use nalgebra::{Point3, Translation3, UnitQuaternion, Vector3, Vector6};
use slam_core::fit_rigid_transform;
use slam_core::io::StampedPose;
use slam_core::{Pose3, se3_exp};
use spot_adapter::eval::{
    DEFAULT_MAX_STAMP_DIFFERENCE, absolute_trajectory_error, associate, end_point_drift,
    loop_end_point_error, path_length, segment_drift,
};
use spot_adapter::sim::SimRng;

/// A wandering 3D trajectory: a circle of radius 5 m with a gentle climb, 0.1 s apart.
fn reference(n: usize) -> Vec<StampedPose> {
    (0..n)
        .map(|i| {
            let a = i as f64 * 0.02;
            StampedPose {
                stamp: i as f64 * 0.1,
                pose: Pose3::from_parts(
                    Translation3::new(5.0 * a.cos(), 5.0 * a.sin(), 0.01 * i as f64),
                    UnitQuaternion::from_euler_angles(0.0, 0.0, a + 1.5),
                ),
            }
        })
        .collect()
}

fn random_pose(rng: &mut SimRng) -> Pose3 {
    se3_exp(&Vector6::from_fn(|_, _| rng.normal(1.0)))
}

#[test]
fn rigidly_moved_trajectory_has_zero_ate() {
    let mut rng = SimRng::new(1, 1);
    let gt = reference(300);
    for _ in 0..5 {
        let t = random_pose(&mut rng);
        let est: Vec<StampedPose> = gt
            .iter()
            .map(|p| StampedPose {
                stamp: p.stamp,
                pose: t * p.pose,
            })
            .collect();
        let ate = absolute_trajectory_error(&est, &gt, DEFAULT_MAX_STAMP_DIFFERENCE).unwrap();
        assert!(ate.rmse < 1e-9 && ate.max < 1e-9, "{ate:?}");
        assert_eq!(ate.pairs, 300);
        // The alignment undoes the transform.
        let back = ate.alignment * t;
        assert!(back.translation.vector.norm() < 1e-9 && back.rotation.angle() < 1e-9);
    }
}

#[test]
/// The fit ATE aligns with (slam-core's) is a least-squares minimum on noisy trajectories.
fn alignment_is_a_least_squares_minimum() {
    let mut rng = SimRng::new(2, 2);
    let a: Vec<Point3<f64>> = (0..50)
        .map(|_| {
            Point3::new(
                rng.range(-5.0, 5.0),
                rng.range(-5.0, 5.0),
                rng.range(-1.0, 1.0),
            )
        })
        .collect();
    let t = random_pose(&mut rng);
    let b: Vec<Point3<f64>> = a
        .iter()
        .map(|p| t * p + Vector3::new(rng.normal(0.1), rng.normal(0.1), rng.normal(0.1)))
        .collect();
    let best = fit_rigid_transform(&a, &b).unwrap();
    let cost = |x: &Pose3| {
        a.iter()
            .zip(&b)
            .map(|(p, q)| (x * p - q).norm_squared())
            .sum::<f64>()
    };
    let c0 = cost(&best);
    // Brute-force check: no small step in any of the 6 directions (or random ones) does better.
    for k in 0..6 {
        for s in [-1e-4, 1e-4, -1e-2, 1e-2] {
            let mut xi = Vector6::zeros();
            xi[k] = s;
            assert!(
                cost(&(se3_exp(&xi) * best)) >= c0 - 1e-12,
                "direction {k} step {s}"
            );
        }
    }
    for _ in 0..200 {
        let xi = Vector6::from_fn(|_, _| rng.normal(0.01));
        assert!(cost(&(se3_exp(&xi) * best)) >= c0 - 1e-12);
    }
    // And a reflection would fit mirrored data; the guard must still return a rotation.
    let mirrored: Vec<Point3<f64>> = a.iter().map(|p| Point3::new(p.x, p.y, -p.z)).collect();
    let r = fit_rigid_transform(&a, &mirrored).unwrap();
    assert!((r.rotation.to_rotation_matrix().matrix().determinant() - 1.0).abs() < 1e-9);
}

#[test]
fn known_offsets_give_known_ate() {
    // Every reference position appears twice (at two stamps), once estimated d above it and
    // once d below. For any rigid T, |T(p + dz) - r|^2 + |T(p - dz) - r|^2 >= (2d)^2 / 2 (the
    // parallelogram law), with equality for T = identity: the ATE is exactly d.
    let d = 0.05;
    let mut gt = Vec::new();
    let mut est = Vec::new();
    for (i, p) in reference(200).into_iter().enumerate() {
        for (k, sign) in [(0, 1.0), (1, -1.0)] {
            let stamp = (2 * i + k) as f64 * 0.1;
            gt.push(StampedPose {
                stamp,
                pose: p.pose,
            });
            let mut q = p.pose;
            q.translation.z += sign * d;
            est.push(StampedPose { stamp, pose: q });
        }
    }
    let ate = absolute_trajectory_error(&est, &gt, DEFAULT_MAX_STAMP_DIFFERENCE).unwrap();
    assert!((ate.rmse - d).abs() < 1e-9, "{ate:?}");
    assert!((ate.median - d).abs() < 1e-9 && (ate.max - d).abs() < 1e-9);
}

#[test]
fn association_by_stamp() {
    let gt = reference(10);
    let est: Vec<StampedPose> = gt
        .iter()
        .skip(2)
        .map(|p| StampedPose {
            stamp: p.stamp + 0.004,
            pose: p.pose,
        })
        .collect();
    let pairs = associate(&est, &gt, 0.01);
    assert_eq!(pairs, (0..8).map(|i| (i, i + 2)).collect::<Vec<_>>());
    assert!(associate(&est, &gt, 0.001).is_empty());
}

#[test]
fn scale_error_gives_known_drift() {
    // A straight 100 m walk whose estimate overshoots by 2 %: every segment and the end point
    // drift 2 %.
    let gt: Vec<Pose3> = (0..=1000)
        .map(|i| Pose3::translation(0.1 * f64::from(i), 0.0, 0.0))
        .collect();
    let est: Vec<Pose3> = gt
        .iter()
        .map(|p| Pose3::translation(p.translation.x * 1.02, 0.0, 0.0))
        .collect();
    assert!((path_length(&gt) - 100.0).abs() < 1e-9);
    let d = end_point_drift(&est, &gt).unwrap();
    assert!((d.end_point_error - 2.0).abs() < 1e-9 && (d.relative_drift - 0.02).abs() < 1e-12);
    let s = segment_drift(&est, &gt, &spot_adapter::eval::INDOOR_SEGMENT_LENGTHS, 10).unwrap();
    assert!((s.translation - 0.02).abs() < 1e-9, "{s:?}");
    assert!(s.rotation.abs() < 1e-12);
    assert_eq!(s.per_length.len(), 5);
    // 10 m segments start at poses 0, 10, ..., 900.
    assert_eq!(s.per_length[0].2, 91);
    // A heading error of 1 degree at the start of an otherwise perfect run: a segment of
    // length L that starts after it has no error; the end point is off by 2 sin(0.5 deg) * 100.
    let yaw = 1f64.to_radians();
    let bent: Vec<Pose3> = gt
        .iter()
        .map(|p| Pose3::rotation(Vector3::z() * yaw) * p)
        .collect();
    let mut est = vec![gt[0]];
    est.extend_from_slice(&bent[1..]);
    let d = end_point_drift(&est, &gt).unwrap();
    let expect = 2.0 * (0.5 * yaw).sin() * 100.0;
    assert!((d.end_point_error - expect).abs() < 1e-9);
    let s = segment_drift(&est, &gt, &[10.0], 1).unwrap();
    // Only segments starting at pose 0 see the bend; the others are exact.
    let first = (2.0 * (0.5 * yaw).sin() * 10.0) / 10.0;
    assert!(
        (s.translation - first / s.segments as f64).abs() < 1e-9,
        "{s:?}"
    );
}

#[test]
fn loop_error_is_the_gap_between_ends() {
    let poses = [
        Pose3::translation(1.0, 2.0, 0.0),
        Pose3::translation(5.0, 2.0, 0.0),
        Pose3::translation(1.0, 2.3, 0.4),
    ];
    assert!((loop_end_point_error(&poses) - 0.5).abs() < 1e-12);
    assert!(loop_end_point_error(&[]) == 0.0);
}

#[test]
fn evaluation_combines_the_figures() {
    // A closed square lap of 40 m walked twice as an estimate that drifts 1 m east in total.
    let mut gt = Vec::new();
    let corners = [
        (0.0, 0.0),
        (10.0, 0.0),
        (10.0, 10.0),
        (0.0, 10.0),
        (0.0, 0.0),
    ];
    for w in corners.windows(2) {
        for k in 0..100 {
            let t = f64::from(k) / 100.0;
            let (x, y) = (
                w[0].0 + t * (w[1].0 - w[0].0),
                w[0].1 + t * (w[1].1 - w[0].1),
            );
            gt.push(Pose3::translation(x, y, 0.0));
        }
    }
    gt.push(Pose3::translation(0.0, 0.0, 0.0));
    let n = gt.len();
    let stamped = |poses: &[Pose3]| -> Vec<StampedPose> {
        poses
            .iter()
            .enumerate()
            .map(|(i, p)| StampedPose {
                stamp: i as f64 * 0.2,
                pose: *p,
            })
            .collect()
    };
    let est: Vec<Pose3> = gt
        .iter()
        .enumerate()
        .map(|(i, p)| Pose3::translation(i as f64 / (n - 1) as f64, 0.0, 0.0) * p)
        .collect();
    let e = spot_adapter::eval::TrajectoryEvaluation::compute(
        &stamped(&est),
        &stamped(&gt),
        DEFAULT_MAX_STAMP_DIFFERENCE,
        &[10.0, 20.0],
    )
    .unwrap();
    assert!((e.loop_end_point_error - 1.0).abs() < 1e-9);
    assert!((e.end_point.end_point_error - 1.0).abs() < 1e-9);
    assert!((e.end_point.path_length - 40.0).abs() < 1e-9);
    assert!((e.end_point.relative_drift - 0.025).abs() < 1e-9);
    assert_eq!(e.ate.pairs, n);
    assert!(e.ate.rmse > 0.0 && e.ate.rmse < 0.5);
    assert!(e.segments.is_some());
}

/// The trajectory pair of `tests/data/evo`, read as the `slam` example reads a ground truth.
fn evo_pair() -> (Vec<StampedPose>, Vec<StampedPose>) {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/evo");
    let truth = slam_core::io::read_tum(dir.join("ground_truth.tum")).unwrap();
    let estimate = slam_core::io::read_tum(dir.join("estimate.tum")).unwrap();
    (truth, estimate)
}

/// `a` within `tolerance` of the golden `b`.
fn close(a: f64, b: f64, tolerance: f64, what: &str) {
    assert!((a - b).abs() <= tolerance, "{what}: ours {a}, golden {b}");
}

#[test]
// The golden figures are written as the tools printed them, to be found in the README.
#[allow(clippy::unreadable_literal)]
fn evo_golden_figures() {
    if slam_core::skip_without_test_data!("tests/data") {
        return;
    }
    // Golden answers: evo 1.38.1's `evo_ape tum ground_truth.tum estimate.tum -a` and `evo_rpe
    // ... -r angle_deg --delta 1 --delta_unit f` to full precision (evo_figures.py), and the
    // KITTI devkit's translation error through KISS-ICP 1.3.0's port (kitti_figures.py);
    // tests/data/evo/README.md has the commands and what they printed.
    let (truth, estimate) = evo_pair();
    let e = spot_adapter::eval::TrajectoryEvaluation::compute(
        &estimate,
        &truth,
        DEFAULT_MAX_STAMP_DIFFERENCE,
        &spot_adapter::eval::INDOOR_SEGMENT_LENGTHS,
    )
    .unwrap();
    assert_eq!(e.ate.pairs, 565);
    close(e.ate.rmse, 2.334440560218639, 1e-9, "ATE rmse");
    close(e.ate.mean, 2.04081752465752, 1e-9, "ATE mean");
    close(e.ate.median, 1.5913037604322984, 1e-9, "ATE median");
    close(e.ate.max, 4.591366684701789, 1e-9, "ATE max");
    close(
        e.end_point.path_length,
        360.2575219110453,
        1e-9,
        "path length",
    );
    // evo's RPE of 1-frame steps in degrees.
    let steps: Vec<f64> = e
        .step_rotation_errors
        .iter()
        .map(|r| r.to_degrees())
        .collect();
    assert_eq!(steps.len(), 564);
    let n = steps.len() as f64;
    let rmse = (steps.iter().map(|s| s * s).sum::<f64>() / n).sqrt();
    close(rmse, 0.32676077959942423, 1e-9, "step rmse");
    close(
        steps.iter().sum::<f64>() / n,
        0.06687034540976393,
        1e-9,
        "step mean",
    );
    close(
        e.max_step_rotation_error_deg(),
        7.018302228558682,
        1e-9,
        "step max",
    );
    assert_eq!((e.steps_over(2.0), e.steps_over(5.0)), (2, 1));
    // KITTI: float32 from the peer, about 7 significant digits.
    let rpe = e.rpe.as_ref().unwrap();
    close(
        rpe.translation_percent,
        2.474599838256836,
        2.5e-6,
        "KITTI translation %",
    );
    assert_eq!(rpe.lengths, [100.0, 200.0, 300.0]);
    assert!(rpe.is_kitti_ladder());
}

#[test]
fn known_drifts_give_known_figures() {
    // A straight 65 m walk along x in a world turned 30 degrees about z; the estimate, in a
    // frame of its own, overshoots by 2 % and climbs 1 cm per metre walked.
    let world = Pose3::from_parts(
        Translation3::new(3.0, -2.0, 1.0),
        UnitQuaternion::from_euler_angles(0.0, 0.0, 30f64.to_radians()),
    );
    let own = Pose3::from_parts(
        Translation3::new(-7.0, 4.0, 0.5),
        UnitQuaternion::from_euler_angles(0.1, -0.2, 1.0),
    );
    let gt: Vec<Pose3> = (0..=650)
        .map(|i| world * Pose3::translation(0.1 * f64::from(i), 0.0, 0.0))
        .collect();
    let climb = |x: f64| Pose3::translation(1.02 * x, 0.0, 0.01 * x);
    let est: Vec<Pose3> = (0..=650).map(|i| own * climb(0.1 * f64::from(i))).collect();
    let d = spot_adapter::eval::height_drift(&est, &gt).unwrap();
    assert!((d - 0.65).abs() < 1e-9, "{d}");
    // The end point: 1.3 m ahead and 0.65 m up.
    let end = end_point_drift(&est, &gt).unwrap();
    assert!((end.end_point_error - 1.3f64.hypot(0.65)).abs() < 1e-9);
    // 65 m is shorter than KITTI's 100 m: its ladder tenfold smaller, 10 to 60 m fit (70 and
    // more do not), and every segment is off by the same 2 % ahead and 1 % up.
    let rpe = spot_adapter::eval::kitti_rpe(&est, &gt).unwrap();
    assert!(!rpe.is_kitti_ladder() && (rpe.scale - 0.1).abs() < 1e-12);
    assert_eq!(rpe.lengths.len(), 6);
    for (l, expect) in rpe.lengths.iter().zip([10.0, 20.0, 30.0, 40.0, 50.0, 60.0]) {
        assert!((l - expect).abs() < 1e-9);
    }
    let per_metre = 0.02f64.hypot(0.01);
    // Segments end at the first pose beyond their length (0.1 m later), as KITTI's do.
    assert!(
        (rpe.translation_percent - 100.0 * per_metre).abs() < 100.0 * per_metre * 0.011,
        "{rpe:?}"
    );
    // The pitch of the climb is a constant rotation between the frames, not a step error.
    let steps = spot_adapter::eval::step_rotation_errors(&est, &gt).unwrap();
    assert!(steps.iter().all(|&s| s < 1e-9));
    // A sensor that did not move has no RPE.
    let still = vec![world; 10];
    assert!(spot_adapter::eval::kitti_rpe(&still, &still).is_none());
}

#[test]
fn a_rotation_spike_is_one_step_error() {
    // A 5 degree yaw kick at step 40 of a straight walk: that step, and no other, is 5 degrees
    // off, whatever the path does afterwards.
    let gt: Vec<Pose3> = (0..100)
        .map(|i| Pose3::translation(0.2 * f64::from(i), 0.0, 0.0))
        .collect();
    let kick = Pose3::rotation(Vector3::z() * 5f64.to_radians());
    let mut est = vec![gt[0]];
    for k in 1..gt.len() {
        let step = gt[k - 1].inverse() * gt[k];
        let step = if k == 40 { step * kick } else { step };
        est.push(est[k - 1] * step);
    }
    let steps = spot_adapter::eval::step_rotation_errors(&est, &gt).unwrap();
    for (k, s) in steps.iter().enumerate() {
        let expect = if k == 39 { 5f64.to_radians() } else { 0.0 };
        assert!((s - expect).abs() < 1e-9, "step {k}: {s}");
    }
}
