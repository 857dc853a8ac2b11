//! The Graph-SLAM engine with the real backends (point-to-plane ICP or LOAM odometry and loop
//! refinement, point-to-point loop check, graduated non-convexity over Levenberg-Marquardt, or
//! the incremental smoother) on a simulated lap of a generated building, against the
//! simulator's ground truth.
#![allow(clippy::unwrap_used)]

use posegraph::{IncrementalSmoother, LevenbergMarquardt};
use slam_core::io::StampedPose;
use slam_core::{GraphSlam, GraphSlamConfig, LoopRejection, MapRegistrator, Optimizer, Pose3};
use spot_adapter::eval::{
    DEFAULT_MAX_STAMP_DIFFERENCE, INDOOR_SEGMENT_LENGTHS, TrajectoryEvaluation,
};
use spot_adapter::pipelines::{
    loam_slam, point_to_plane_slam, point_to_plane_slam_optimized_by, scan_context_places,
    slam_config,
};
use spot_adapter::sim::{Building, Route, SimulatedSpot, SimulationConfig};

/// Run `slam` over the seed-3 lap (with the sweep's motion distortion when `skewed`) and assert
/// the accuracy targets against the simulator's ground truth; returns the segment drift.
fn meets_the_accuracy_targets<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    slam: &mut GraphSlam<R, C, O>,
    skewed: bool,
) -> f64 {
    let seed = 3;
    let config = SimulationConfig {
        seed,
        motion_distortion: skewed,
        ..SimulationConfig::default()
    };
    let sim = SimulatedSpot::corridor_loop(&config).unwrap();
    let body_t_lidar = sim.body_t_lidar();
    let truth = sim.ground_truth();
    let mut odom = Vec::new();
    for sample in sim {
        odom.push(StampedPose {
            stamp: sample.stamp,
            pose: sample.odom_t_body,
        });
        slam.process(&sample.scan_input());
    }
    let report = slam.report();
    assert!(report.loops_closed >= 1, "{report:?}");
    assert_eq!(
        report.odometry_faults, 0,
        "clean odometry flagged: {report:?}"
    );
    let (e, _) =
        TrajectoryEvaluation::of_lidar_trajectory(slam.scan_trajectory(), &body_t_lidar, &truth)
            .unwrap();
    let o = TrajectoryEvaluation::compute(
        &odom,
        &truth,
        DEFAULT_MAX_STAMP_DIFFERENCE,
        &INDOOR_SEGMENT_LENGTHS,
    )
    .unwrap();
    assert!(e.end_point.path_length > 100.0, "a loop of at least 100 m");
    assert!(e.ate.rmse <= 0.05, "ATE {} m", e.ate.rmse);
    assert!(
        e.loop_end_point_error <= 0.05,
        "loop end-point error {} m",
        e.loop_end_point_error
    );
    let segments = e.segments.unwrap();
    assert!(
        segments.translation <= 0.002,
        "segment drift {} %",
        100.0 * segments.translation
    );
    // Spot's own odometry drifts about 1.9 %: SLAM must be far better.
    assert!(o.loop_end_point_error > 10.0 * e.loop_end_point_error.max(0.01));
    segments.translation
}

#[test]
fn point_to_plane_slam_meets_the_accuracy_targets() {
    meets_the_accuracy_targets(&mut point_to_plane_slam(slam_config()).unwrap(), false);
}

#[test]
fn loam_slam_meets_the_accuracy_targets() {
    meets_the_accuracy_targets(&mut loam_slam(slam_config()).unwrap(), false);
}

/// The largest height error (metres) and tilt error (radians) of the body along the engine's
/// scan trajectory of the seed-3 lap, against ground truth (both from the first pose: the map
/// frame is the odometry frame there, and the odometry starts at the body).
fn lap_height_and_tilt_errors(config: GraphSlamConfig) -> (f64, f64) {
    let sim = SimulatedSpot::corridor_loop(&SimulationConfig {
        seed: 3,
        ..SimulationConfig::default()
    })
    .unwrap();
    let body_t_lidar = sim.body_t_lidar();
    let truth = sim.ground_truth();
    let mut slam = point_to_plane_slam(config).unwrap();
    for sample in sim {
        slam.process(&sample.scan_input());
    }
    let world_t_start = truth[0].pose;
    let (mut height, mut tilt) = (0.0f64, 0.0f64);
    for s in slam.scan_trajectory() {
        let Some(t) = truth.iter().find(|t| (t.stamp - s.stamp).abs() < 1e-6) else {
            continue;
        };
        let est = s.pose * body_t_lidar.inverse();
        let tru = world_t_start.inverse() * t.pose;
        height = height.max((est.translation.z - tru.translation.z).abs());
        let (up, true_up) = (
            est.rotation * nalgebra::Vector3::z(),
            tru.rotation * nalgebra::Vector3::z(),
        );
        tilt = tilt.max(up.angle(&true_up));
    }
    (height, tilt)
}

/// Spot's odometry frame is level (its roll and pitch come from the IMU) while its position
/// drifts, a fifth of it vertically: with the odometry's roll and pitch
/// (`GraphSlamConfig::odometry_gravity`, the default) the estimate stays level and at the
/// floor's height over the whole lap; registration alone lets it tilt, and walking forward on a
/// tilted estimate climbs.
#[test]
fn the_estimate_keeps_the_odometrys_gravity_and_the_floors_height() {
    let (height, tilt) = lap_height_and_tilt_errors(GraphSlamConfig {
        odometry_gravity: true,
        ..slam_config()
    });
    let (free_height, free_tilt) = lap_height_and_tilt_errors(GraphSlamConfig {
        odometry_gravity: false,
        ..slam_config()
    });
    eprintln!(
        "levelled: height {height:.4} m, tilt {:.3} deg; registration alone: {free_height:.4} m, {:.3} deg",
        tilt.to_degrees(),
        free_tilt.to_degrees()
    );
    assert!(height <= 0.02, "height error {height} m");
    assert!(
        tilt <= 0.05f64.to_radians(),
        "tilt error {} deg",
        tilt.to_degrees()
    );
    assert!(free_tilt > 2.0 * tilt, "{} deg", free_tilt.to_degrees());
}

/// The same lap with the incremental smoother as the engine's optimiser meets the same targets.
/// The engine's graph only grows (nodes and edges appended, the first node fixed once), so the
/// smoother never starts afresh: each loop closure re-factors only the nodes it affects. Its
/// estimate after the walk is a batch optimum: Levenberg-Marquardt on the final graph (the
/// oracle) moves no pose by more than 1 µm or 1e-6 rad (measured 3e-13 m).
#[test]
fn the_incremental_smoother_meets_the_accuracy_targets() {
    let mut slam =
        point_to_plane_slam_optimized_by(slam_config(), IncrementalSmoother::default()).unwrap();
    meets_the_accuracy_targets(&mut slam, false);
    let report = slam.report();
    let statistics = slam.optimizer().statistics();
    eprintln!("{statistics:?}, {} loops closed", report.loops_closed);
    assert_eq!(report.optimizer_failures, 0, "{report:?}");
    assert_eq!(statistics.optimizations, report.loops_closed);
    assert_eq!(statistics.restarts, 0, "{statistics:?}");
    let mut batch = slam.graph().clone();
    LevenbergMarquardt::default().optimize(&mut batch).unwrap();
    let (mut metres, mut radians) = (0.0f64, 0.0f64);
    for (ours, oracle) in slam.graph().nodes().iter().zip(batch.nodes()) {
        let delta = ours.pose.inverse() * oracle.pose;
        metres = metres.max(delta.translation.vector.norm());
        radians = radians.max(delta.rotation.angle());
    }
    eprintln!("LM moved a pose by at most {metres} m, {radians} rad");
    assert!(
        metres <= 1e-6 && radians <= 1e-6,
        "{metres} m, {radians} rad"
    );
}

/// Scans cast while walking (12 cm per sweep), deskewed by the engine with the odometry's
/// velocity, meet the same targets (0.17 % over 10-50 m segments); without deskewing the same
/// lap drifts about twice as much (0.34 % measured), beyond the 0.2 % target.
#[test]
fn deskewed_scans_meet_the_accuracy_targets() {
    let drift = meets_the_accuracy_targets(&mut point_to_plane_slam(slam_config()).unwrap(), true);
    let skewed = run_skewed_lap_without_deskew();
    assert!(
        skewed > 0.002 && drift < 0.6 * skewed,
        "segment drift {} % deskewed, {} % without",
        100.0 * drift,
        100.0 * skewed
    );
}

/// LiDAR-only on the same skewed lap: each sweep deskewed with the constant velocity of the
/// last two scans, its own motion over the sweep taken only where it fits clearly better
/// (`GraphSlamConfig::sweep_min_gain`). Spot's walk is smooth, so it almost never does, and the
/// lap meets the targets (measured ATE 0.8 cm, segment drift 0.09 %). Taking each sweep's own
/// motion whenever it fits no worse (a gain of 0) lets the noise of its twelve unknowns into the
/// deskew: segment drift 0.17 %, nearly twice as much (ATE 1.2 cm; with the map thinned to the
/// scan's own voxel, 0.27 % against 0.14 %).
#[test]
fn a_skewed_lidar_only_lap_meets_the_targets() {
    let lap = |gain: f64| {
        let config = GraphSlamConfig {
            sweep_min_gain: gain,
            ..slam_config()
        };
        skewed_lap(config, true)
    };
    let (ate, drift) = lap(slam_config().sweep_min_gain);
    let (every_ate, every_drift) = lap(0.0);
    eprintln!(
        "ATE {ate} m, segment drift {drift}; every sweep's own motion: {every_ate} m, {every_drift}"
    );
    assert!(ate <= 0.03 && drift <= 0.002, "ATE {ate} m, drift {drift}");
    assert!(
        every_drift > 1.5 * drift,
        "segment drift {every_drift} with a gain of 0, {drift} with the default"
    );
}

/// The segment drift of the seed-3 lap with motion-distorted scans, not deskewed.
fn run_skewed_lap_without_deskew() -> f64 {
    let config = GraphSlamConfig {
        deskew: false,
        ..slam_config()
    };
    skewed_lap(config, false).1
}

/// The seed-3 lap with motion-distorted scans through point-to-plane SLAM with `config`, the
/// robot's odometry left out when `lidar_only`: ATE (m) and segment drift (fraction).
fn skewed_lap(config: GraphSlamConfig, lidar_only: bool) -> (f64, f64) {
    let mut sim_config = SimulationConfig::with_seed(3);
    sim_config.motion_distortion = true;
    let sim = SimulatedSpot::corridor_loop(&sim_config).unwrap();
    let body_t_lidar = sim.body_t_lidar();
    let truth = sim.ground_truth();
    let mut slam = point_to_plane_slam(config).unwrap();
    for sample in sim {
        if lidar_only {
            slam.process(&sample.lidar_only_input());
        } else {
            slam.process(&sample.scan_input());
        }
    }
    let (e, _) =
        TrajectoryEvaluation::of_lidar_trajectory(slam.scan_trajectory(), &body_t_lidar, &truth)
            .unwrap();
    (e.ate.rmse, e.segments.unwrap().translation)
}

/// Loops by appearance: with the search by position cut down to 1 mm (as if the estimate had
/// drifted beyond any search sphere), a lap and a half corridor of building 3 (the east half of
/// the south corridor walked twice) closes no loop by position, yet Scan Context finds the
/// corridor again from the scans alone. Every loop kept agrees with the ground truth (the
/// look-alikes that pass the geometric check, such as the north corridor seen as the south one
/// turned round, are refused by the drift gate), and the map is more accurate.
#[test]
fn place_recognition_closes_the_loop_without_the_search_by_position() {
    let config = GraphSlamConfig {
        loop_search_radius: 1e-3,
        ..slam_config()
    };
    let blind = run_overlapping_lap(point_to_plane_slam(config.clone()).unwrap());
    assert_eq!(blind.report.loops_closed, 0);
    let seen = run_overlapping_lap(
        point_to_plane_slam(config)
            .unwrap()
            .with_place_recognizer(scan_context_places()),
    );
    let report = &seen.report;
    eprintln!(
        "without: ATE {:.4} m; with Scan Context: ATE {:.4} m, {} place candidates, {} loops closed, {} refused beyond the drift, loop errors against the truth {:?}",
        blind.ate,
        seen.ate,
        report.place_candidates,
        report.place_loops_closed,
        report.loop_rejections.get(LoopRejection::BeyondDrift),
        seen.loop_errors
    );
    assert!(
        report.place_loops_closed >= 1,
        "none of {} closed",
        report.place_candidates
    );
    assert!(
        seen.loop_errors.iter().all(|&e| e < 0.1),
        "{:?}",
        seen.loop_errors
    );
    assert!(seen.ate <= 0.05, "ATE {} m", seen.ate);
    assert!(
        seen.ate < blind.ate,
        "ATE {} m with the loop, {} m without",
        seen.ate,
        blind.ate
    );
}

/// What a run gave: ATE, the report, and for every loop edge of the final graph the distance
/// between its measurement and the ground truth's relative pose (metres).
struct Run {
    ate: f64,
    report: slam_core::SlamReport,
    loop_errors: Vec<f64>,
}

/// Building `seed` of `config`, walked from the middle of its south corridor round the loop to
/// its south-east corner again (a lap and half a corridor).
fn overlapping_lap(config: &SimulationConfig) -> SimulatedSpot {
    let building = Building::generate(config.seed, &config.building).unwrap();
    let c = *building.corridor_loop();
    let start = 0.5 * (c[0] + c[1]);
    let route = Route::new(vec![start, c[1], c[2], c[3], c[0], start, c[1]], false).unwrap();
    SimulatedSpot::new(building, &route, config).unwrap()
}

/// Building 3's overlapping lap through `slam`.
fn run_overlapping_lap<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    mut slam: GraphSlam<R, C, O>,
) -> Run {
    let sim = overlapping_lap(&SimulationConfig::with_seed(3));
    let body_t_lidar = sim.body_t_lidar();
    let truth = sim.ground_truth();
    let mut world_t_lidar = std::collections::HashMap::new();
    for sample in sim {
        world_t_lidar.insert(
            sample.stamp.to_bits(),
            sample.ground_truth.unwrap() * body_t_lidar,
        );
        slam.process(&sample.scan_input());
    }
    finished_run(&slam, &world_t_lidar, &body_t_lidar, &truth)
}

/// What `slam` gave, against the true `world_T_lidar` of every scan (by stamp bits).
fn finished_run<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    slam: &GraphSlam<R, C, O>,
    world_t_lidar: &std::collections::HashMap<u64, Pose3>,
    body_t_lidar: &Pose3,
    truth: &[StampedPose],
) -> Run {
    // Whether GNC kept them or not: every loop edge must agree with the truth.
    let loop_errors = crate::common::loop_edges_against_truth(slam, world_t_lidar)
        .into_iter()
        .map(|(_, error)| error)
        .collect();
    let (e, _) =
        TrajectoryEvaluation::of_lidar_trajectory(slam.scan_trajectory(), body_t_lidar, truth)
            .unwrap();
    Run {
        ate: e.ate.rmse,
        report: slam.report().clone(),
        loop_errors,
    }
}

/// Issue 17: a 10 m jump of the odometry between two scans a third of the way round the seed-3
/// lap became a "registered" keyframe and the lap ended 10.2 m off (3 cm without the jump).
/// Now the engine registers from the constant-velocity extrapolation too, keeps the better fit
/// and counts the fault; the simulator's ground truth is the oracle.
#[test]
fn an_odometry_jump_is_detected_and_the_lap_stays_accurate() {
    let config = SimulationConfig {
        seed: 3,
        ..SimulationConfig::default()
    };
    let sim = SimulatedSpot::corridor_loop(&config).unwrap();
    let body_t_lidar = sim.body_t_lidar();
    let truth = sim.ground_truth();
    let at = truth.len() / 3;
    let jump = Pose3::translation(10.0, 0.0, 0.0);
    let mut slam = point_to_plane_slam(slam_config()).unwrap();
    for (k, mut sample) in sim.enumerate() {
        if k >= at {
            sample.odom_t_body = jump * sample.odom_t_body;
        }
        slam.process(&sample.scan_input());
    }
    let report = slam.report();
    assert_eq!(report.odometry_faults, 1, "{report:?}");
    assert!(report.loops_closed >= 1, "{report:?}");
    let (e, _) =
        TrajectoryEvaluation::of_lidar_trajectory(slam.scan_trajectory(), &body_t_lidar, &truth)
            .unwrap();
    eprintln!(
        "with the jump: ATE {:.4} m, loop end-point error {:.4} m, {} fallbacks",
        e.ate.rmse,
        e.loop_end_point_error,
        report.fallbacks()
    );
    assert!(e.ate.rmse <= 0.05, "ATE {} m", e.ate.rmse);
    assert!(
        e.loop_end_point_error <= 0.05,
        "loop end-point error {} m",
        e.loop_end_point_error
    );
}

/// Issue 18's drift world: building 1 with a blank north corridor (doors shut, no pilasters),
/// walked LiDAR-only (the robot's odometry left out), a lap and half a corridor from the middle
/// of the south corridor, without place recognition.
///
/// With its 100 m VLP-16 the tracker sees the corridor's far ends. Seen by a 25 m LiDAR, the
/// middle of the 44 m corridor shows neither end: the scan-to-scan odometry this crate had
/// before slipped along it there and that lap ended 3.5 m off (the `slam` example, seed 1).
/// Every scan registered against the local map, with the tracker's retries of scans that
/// match much less than usual, holds there too: both laps end within 5 cm (measured 2.1 and
/// 2.0 cm, ATE 1.4 and 1.3 cm), and the loops they close are found by position (the estimate
/// never drifts beyond the 0.5 m search), with no place recognition.
#[test]
fn a_lidar_only_lap_through_a_blank_corridor_holds_without_place_recognition() {
    for range in [100.0, 25.0] {
        let lap = run_blank_corridor_lap(point_to_plane_slam(slam_config()).unwrap(), range);
        eprintln!(
            "{range} m LiDAR: end {:.3} m off, ATE {:.3} m, {} loops, tracking {:?}",
            lap.end_error, lap.run.ate, lap.run.report.loops_closed, lap.run.report.tracking
        );
        assert!(
            lap.end_error <= 0.05 && lap.run.ate <= 0.05,
            "{range} m LiDAR: end {} m off, ATE {} m",
            lap.end_error,
            lap.run.ate
        );
        assert_eq!(lap.run.report.fallbacks(), 0, "{range} m LiDAR");
    }
}

/// A run of [`run_blank_corridor_lap`]: the run, and how far the last scan's estimate is from
/// the truth with the first scans' poses made to agree (metres).
struct DriftRun {
    run: Run,
    end_error: f64,
}

/// Building 1 with a blank north corridor, seen by a LiDAR of `range` metres and walked
/// LiDAR-only (the robot's odometry left out) through `slam` on its overlapping lap.
fn run_blank_corridor_lap<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    mut slam: GraphSlam<R, C, O>,
    range: f64,
) -> DriftRun {
    let mut config = SimulationConfig::with_seed(1);
    config.building.blank_corridor = true;
    config.lidar.max_range = range;
    let sim = overlapping_lap(&config);
    let body_t_lidar = sim.body_t_lidar();
    let truth = sim.ground_truth();
    let mut world_t_lidar = std::collections::HashMap::new();
    for s in sim {
        world_t_lidar.insert(s.stamp.to_bits(), s.ground_truth.unwrap() * body_t_lidar);
        slam.process(&s.lidar_only_input());
    }
    let trajectory = slam.scan_trajectory();
    let (first, last) = (trajectory[0], trajectory[trajectory.len() - 1]);
    let world_t_estimate = world_t_lidar[&first.stamp.to_bits()] * first.pose.inverse();
    let end_error = ((world_t_estimate * last.pose).translation.vector
        - world_t_lidar[&last.stamp.to_bits()].translation.vector)
        .norm();
    DriftRun {
        run: finished_run(&slam, &world_t_lidar, &body_t_lidar, &truth),
        end_error,
    }
}
