//! Loop closure on the drifting loop: the drift removed, and every rejected candidate counted.

use super::backends::{BruteIcp, DenseGaussNewton, GrowthCheck};
use super::{brute_engine, drifting_odometry, feed, hall, loop_config, loop_poses, scan};
use slam_core::io::StampedPose;
use slam_core::{
    GraphSlam, GraphSlamConfig, LoopOutcome, LoopRejection, PointCloud, Pose3, ScanInput,
    ScanOutcome,
};

#[test]
fn loop_closure_removes_odometry_drift() {
    let world = hall();
    let truth = loop_poses();
    let odom = drifting_odometry(&truth);
    let mut slam = GraphSlam::try_new(
        loop_config(),
        BruteIcp { max_distance: 0.5 },
        BruteIcp { max_distance: 1.0 },
        BruteIcp { max_distance: 0.5 },
        DenseGaussNewton,
    )
    .unwrap();
    let body_t_lidar = Pose3::identity();
    let mut keyframes = 0;
    for (k, (gt, od)) in truth.iter().zip(&odom).enumerate() {
        let cloud = scan(&world, gt);
        let outcome = slam.process(&ScanInput {
            stamp: k as f64 * 0.2,
            odom_t_body: Some(*od),
            body_t_lidar,
            cloud: &cloud,
            gyro_orientation: None,
        });
        if matches!(outcome, ScanOutcome::Keyframe { .. }) {
            keyframes += 1;
        }
    }
    // Bad input is skipped and counted, never fatal.
    let empty = PointCloud::new();
    let last = *odom.last().unwrap();
    let far = last * Pose3::translation(1.0, 0.0, 0.0);
    assert_eq!(
        slam.process(&ScanInput {
            stamp: 0.0,
            odom_t_body: Some(far),
            body_t_lidar,
            cloud: &empty,
            gyro_orientation: None,
        }),
        ScanOutcome::Skipped(slam_core::SkipReason::OutOfOrderStamp)
    );
    let nan = Pose3::translation(f64::NAN, 0.0, 0.0);
    assert!(matches!(
        slam.process(&ScanInput {
            stamp: 1e6,
            odom_t_body: Some(nan),
            body_t_lidar,
            cloud: &empty,
            gyro_orientation: None,
        }),
        ScanOutcome::Skipped(_)
    ));
    assert!(matches!(
        slam.process(&ScanInput {
            stamp: 1e6 + 1.0,
            odom_t_body: Some(far),
            body_t_lidar,
            cloud: &empty,
            gyro_orientation: None,
        }),
        ScanOutcome::Skipped(_)
    ));

    let report = slam.report();
    assert!(keyframes > 80, "{keyframes} keyframes");
    eprintln!(
        "loops {} of {}, fallbacks {}",
        report.loops_closed,
        report.loops_attempted,
        report.fallbacks()
    );
    assert!(report.loops_closed >= 1, "{report:?}");
    // The map frame is the odometry frame at the first scan, which is the ground truth's here.
    let traj = slam.scan_trajectory();
    let err_end = (traj.last().unwrap().pose.translation.vector
        - truth.last().unwrap().translation.vector)
        .norm();
    let odom_end =
        (odom.last().unwrap().translation.vector - truth.last().unwrap().translation.vector).norm();
    let max_err = traj
        .iter()
        .zip(&truth)
        .map(|(s, g)| (s.pose.translation.vector - g.translation.vector).norm())
        .fold(0.0, f64::max);
    for q in [0.25, 0.5, 0.75, 0.9, 0.95, 1.0] {
        let k = ((traj.len() - 1) as f64 * q) as usize;
        let StampedPose { stamp, pose: p } = traj[k];
        let i = (stamp / 0.2).round() as usize;
        eprintln!(
            "at {q}: slam {:.3} m, odometry {:.3} m",
            (p.translation.vector - truth[i].translation.vector).norm(),
            (odom[i].translation.vector - truth[i].translation.vector).norm()
        );
    }
    assert!(
        odom_end > 0.5,
        "the odometry must drift for the test to mean anything: {odom_end}"
    );
    assert!(
        err_end < 0.05,
        "end error {err_end} m (odometry alone: {odom_end} m)"
    );
    // The test ICP is crude (point-to-point on 0.4 m voxels), so the odometry between loop closures
    // drifts; the bound checks that the optimisation spreads the correction along the loop.
    assert!(max_err < 0.4, "largest position error {max_err} m");
    let rms = |v: Vec<f64>| (v.iter().map(|e| e * e).sum::<f64>() / v.len() as f64).sqrt();
    let slam_rms = rms(traj
        .iter()
        .map(|s| {
            let truth = truth[(s.stamp / 0.2).round() as usize];
            (s.pose.translation.vector - truth.translation.vector).norm()
        })
        .collect());
    let odom_rms = rms(odom
        .iter()
        .zip(&truth)
        .map(|(o, g)| (o.translation.vector - g.translation.vector).norm())
        .collect());
    assert!(
        slam_rms < 0.5 * odom_rms,
        "RMS error {slam_rms} m against odometry's {odom_rms} m"
    );
    let map = slam.map(0.1).unwrap();
    assert!(map.len() > 1000);
    // Every map point lies near the hall's true geometry.
    let near = map
        .points()
        .iter()
        .filter(|p| {
            let p = p.cast::<f64>();
            world.iter().any(|w| (w - p).norm() < 0.3)
        })
        .count();
    assert!(
        near as f64 > 0.98 * map.len() as f64,
        "{near} of {}",
        map.len()
    );
}

/// Between optimisations the engine's graph only grows: nodes and edges appended, no edge or
/// fixed flag changed, so an incremental optimiser (posegraph's `IncrementalSmoother`) keeps
/// its factor from one loop closure to the next instead of starting afresh.
#[test]
fn the_graph_only_grows_between_optimisations() {
    let world = hall();
    let truth = loop_poses();
    let odom = drifting_odometry(&truth);
    // A keyframe every step, revisits too, each trying a loop: a closure on each of the last.
    let config = GraphSlamConfig {
        revisit_radius: 0.0,
        loop_min_keyframe_gap: 1,
        ..loop_config()
    };
    let mut slam = GraphSlam::try_new(
        config,
        BruteIcp { max_distance: 0.5 },
        BruteIcp { max_distance: 1.0 },
        BruteIcp { max_distance: 0.5 },
        GrowthCheck::new(DenseGaussNewton),
    )
    .unwrap();
    for (k, (gt, od)) in truth.iter().zip(&odom).enumerate() {
        feed(&mut slam, &world, k, gt, *od);
    }
    let calls = slam.optimizer().calls;
    assert_eq!(calls, slam.report().loops_closed);
    assert!(calls >= 2, "{calls} optimisations: {:?}", slam.report());
}

/// The drifting loop through `config` with the caller running the loop-closure steps (as a
/// scheduler would): every step's outcome that had a candidate, and the report.
fn loop_steps(config: &GraphSlamConfig) -> (Vec<LoopOutcome>, slam_core::SlamReport) {
    let world = hall();
    let truth = loop_poses();
    let odom = drifting_odometry(&truth);
    let mut slam = brute_engine(GraphSlamConfig {
        inline_loop_closure: false,
        ..config.clone()
    })
    .unwrap();
    let mut outcomes = Vec::new();
    for (k, (gt, od)) in truth.iter().zip(&odom).enumerate() {
        feed(&mut slam, &world, k, gt, *od);
        loop {
            match slam.loop_closure_step() {
                LoopOutcome::Idle => break,
                other => outcomes.push(other),
            }
        }
    }
    (outcomes, slam.report().clone())
}

#[test]
fn every_rejected_loop_is_counted_by_its_reason() {
    let counted = |outcomes: &[LoopOutcome], reason: LoopRejection| {
        outcomes
            .iter()
            .filter(|o| matches!(o, LoopOutcome::Rejected { reason: r, .. } if *r == reason))
            .count()
    };
    // An acceptance threshold nothing meets: every candidate that converges is a mismatch.
    let (outcomes, report) = loop_steps(&GraphSlamConfig {
        loop_max_mean_squared_error: 1e-12,
        ..loop_config()
    });
    eprintln!("{:?}", report.loop_rejections.nonzero());
    assert_eq!(report.loops_closed, 0);
    assert!(!outcomes.is_empty());
    assert_eq!(report.loops_attempted, outcomes.len());
    assert_eq!(report.loops_attempted, report.loop_rejections.total());
    for reason in LoopRejection::ALL {
        assert_eq!(
            counted(&outcomes, reason),
            report.loop_rejections.get(reason),
            "{reason:?}"
        );
    }
    assert_eq!(
        counted(&outcomes, LoopRejection::CoarseMismatch)
            + counted(&outcomes, LoopRejection::CoarseNotConverged),
        outcomes.len(),
        "{:?}",
        report.loop_rejections.nonzero()
    );
    assert!(report.loop_rejections.get(LoopRejection::CoarseMismatch) >= 1);
}

/// The loop walked with the keyframes' map clouds and registration points kept in a file past
/// the newest 4 (the loop checks and the local map read the old keyframes' points back): the
/// same trajectory, loops and map, bit for bit, as with everything in memory (the oracle: the
/// engine without the store), only 4 clouds held, every keyframe's scan read back equal to the
/// one held in memory, and the file gone with the engine. Moving an engine's keyframes to a
/// store midway gives the same.
#[test]
fn keyframe_clouds_kept_in_a_file_change_nothing_but_memory() {
    let world = hall();
    let truth = loop_poses();
    let odom = drifting_odometry(&truth);
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("keyframe-store");
    std::fs::create_dir_all(&dir).unwrap();
    let mut held = brute_engine(loop_config()).unwrap();
    let mut stored = brute_engine(loop_config())
        .unwrap()
        .with_keyframe_store(&dir, 4)
        .unwrap();
    let mut moved = brute_engine(loop_config()).unwrap();
    for (k, (gt, od)) in truth.iter().zip(&odom).enumerate() {
        for slam in [&mut held, &mut stored] {
            feed(slam, &world, k, gt, *od);
        }
        feed(&mut moved, &world, k, gt, *od);
        if k == truth.len() / 2 {
            moved = moved.with_keyframe_store(&dir, 4).unwrap();
        }
    }
    let keyframes = held.keyframe_count();
    assert!(keyframes > 20, "{keyframes} keyframes");
    // The loop checks read old keyframes' points back from the file.
    assert!(super::backends::RESTORED.load(std::sync::atomic::Ordering::Relaxed) > 0);
    assert!(held.report().loops_closed > 0);
    assert_eq!(held.keyframe_scans_in_memory(), keyframes);
    for slam in [&stored, &moved] {
        assert_eq!(slam.keyframe_scans_in_memory(), 4);
        assert_eq!(slam.report().keyframe_store_failures, 0);
        assert_eq!(slam.report().loops_closed, held.report().loops_closed);
        assert_eq!(slam.scan_trajectory(), held.scan_trajectory());
        assert_eq!(slam.map(0.1).unwrap(), held.map(0.1).unwrap());
        let scans: Vec<_> = slam.keyframe_scans().map(Result::unwrap).collect();
        let expected: Vec<_> = held.keyframe_scans().map(Result::unwrap).collect();
        assert_eq!(scans.len(), keyframes);
        for ((p, c), (q, d)) in scans.iter().zip(&expected) {
            assert_eq!(p, q);
            assert_eq!(c.as_ref(), d.as_ref());
        }
    }
    let files = || std::fs::read_dir(&dir).unwrap().count();
    assert_eq!(files(), 2);
    drop(stored);
    drop(moved);
    assert_eq!(files(), 0);
    // A folder that does not exist is refused by its path.
    let missing = dir.join("missing");
    assert!(matches!(
        brute_engine(loop_config()).unwrap().with_keyframe_store(&missing, 4),
        Err(slam_core::KeyframeCloudError::Store { path, .. }) if path.starts_with(&missing)
    ));
}
