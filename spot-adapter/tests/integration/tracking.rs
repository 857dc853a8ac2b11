//! The LiDAR-only tracker on real and harder motion, against ground truth: a sensor that does
//! not move (real HDL-32E scans), turns of up to 52 degrees between scans (the simulated Spot's
//! lap kept at one scan in five), and a person carrying a dense OS1-128 at 2 Hz (shaking,
//! pitching, rolling, each sweep distorted by its own motion). Each moving case also runs with
//! the tracker this crate had before (a fixed reach, no retries, scans deskewed with the
//! constant velocity of the last two), which loses it: the test would fail without the change.
//! A gyro, where the scans carry one, predicts the turns between them.

#![allow(clippy::unwrap_used)]

use std::path::{Path, PathBuf};

use slam_core::tracking::{ReachConfig, TrackerConfig};
use slam_core::{GraphSlamConfig, PointCloud, Pose3, TurnPrediction};
use spot_adapter::eval::{
    DEFAULT_MAX_STAMP_DIFFERENCE, INDOOR_SEGMENT_LENGTHS, TrajectoryEvaluation,
};
use spot_adapter::pipelines::{
    point_to_plane_slam, point_to_plane_slam_with, point_to_plane_tracker, slam_config,
};
use spot_adapter::robot::Sample;
use spot_adapter::sim::{SimulatedSpot, SimulationConfig};

/// The engine's settings with the tracker this crate had before the adaptive reach: pairs
/// within the fine stage's fixed reach only, no retries, no second fine stage from the predicted
/// position, no estimate of a sweep's own motion.
fn fixed_reach_config() -> GraphSlamConfig {
    GraphSlamConfig {
        tracker: TrackerConfig {
            reach: ReachConfig {
                initial: 1.0,
                min: 1.0,
                max: 1.0,
                ..ReachConfig::default()
            },
            retry: false,
            recheck_distance: 0.0,
            ..TrackerConfig::default()
        },
        sweep_motion: false,
        ..slam_config()
    }
}

/// `samples` fed LiDAR-only (their odometry left out) to the point-to-plane engine with
/// `config`, evaluated against their ground truth.
fn lidar_only(config: GraphSlamConfig, samples: &[Sample], body_t_lidar: &Pose3) -> Outcome {
    lidar_only_with(point_to_plane_slam(config).unwrap(), samples, body_t_lidar)
}

/// As [`lidar_only`], with the engine given.
fn lidar_only_with(
    mut slam: spot_adapter::pipelines::PointToPlaneSlam,
    samples: &[Sample],
    body_t_lidar: &Pose3,
) -> Outcome {
    for s in samples {
        slam.process(&s.lidar_only_input());
    }
    let truth: Vec<_> = samples
        .iter()
        .map(|s| slam_core::io::StampedPose {
            stamp: s.stamp,
            pose: s.ground_truth.unwrap(),
        })
        .collect();
    let estimate = spot_adapter::eval::body_trajectory(slam.scan_trajectory(), body_t_lidar);
    let e = TrajectoryEvaluation::compute(
        &estimate,
        &truth,
        DEFAULT_MAX_STAMP_DIFFERENCE,
        &INDOOR_SEGMENT_LENGTHS,
    )
    .unwrap();
    // Roll and pitch of each estimated pose against the truth's, with the first poses aligned.
    let first = truth[0].pose * estimate[0].pose.inverse();
    let tilt = estimate
        .iter()
        .zip(&truth)
        .map(|(est, gt)| {
            let (r0, p0, _) = (first * est.pose).rotation.euler_angles();
            let (r1, p1, _) = gt.pose.rotation.euler_angles();
            (r0 - r1).abs().max((p0 - p1).abs()).to_degrees()
        })
        .fold(0.0, f64::max);
    Outcome {
        ate: e.ate.rmse,
        height: e.height_drift,
        worst_step_deg: e.max_step_rotation_error_deg(),
        steps_over_2_deg: e.steps_over(2.0),
        tilt_deg: tilt,
        fallbacks: slam.report().fallbacks(),
        recovered: slam.report().tracking.recovered,
        gyro_predictions: slam.report().gyro_predictions,
        turn_shares: slam.report().turn_shares,
    }
}

/// What a run gave against the truth.
#[derive(Debug)]
struct Outcome {
    ate: f64,
    height: f64,
    worst_step_deg: f64,
    steps_over_2_deg: usize,
    /// The largest roll or pitch error of a pose (degrees).
    tilt_deg: f64,
    fallbacks: usize,
    /// Scans taken after a retry.
    recovered: usize,
    /// Scans whose orientation the gyro predicted.
    gyro_predictions: usize,
    /// Scans predicted with none, half and all of the last step's turn.
    turn_shares: [usize; 3],
}

#[test]
fn turns_of_fifty_degrees_between_scans_are_tracked() {
    // Spot's lap kept at one scan in five (1 Hz, 0.6 m apart): the corners turn it by up to 52
    // degrees from one scan to the next.
    let sim = SimulatedSpot::corridor_loop(&SimulationConfig::with_seed(1)).unwrap();
    let body_t_lidar = sim.body_t_lidar();
    let samples: Vec<Sample> = sim.step_by(5).collect();
    let largest_turn = samples
        .windows(2)
        .map(|w| {
            let (a, b) = (w[0].ground_truth.unwrap(), w[1].ground_truth.unwrap());
            (a.inverse() * b).rotation.angle().to_degrees()
        })
        .fold(0.0, f64::max);
    assert!(largest_turn > 45.0, "{largest_turn} degrees");
    let now = lidar_only(slam_config(), &samples, &body_t_lidar);
    eprintln!("adaptive reach: {now:?}");
    // 6.7 cm measured: at 0.6 m a step the tracker slides a few centimetres along corridors
    // now and then (at 5 Hz the same lap ends 1.4 cm ATE).
    assert!(now.ate <= 0.10 && now.height.abs() <= 0.05, "{now:?}");
    assert!(now.worst_step_deg <= 2.0 && now.fallbacks == 0, "{now:?}");
    let before = lidar_only(fixed_reach_config(), &samples, &body_t_lidar);
    eprintln!("fixed reach, no retries: {before:?}");
    assert!(
        before.ate > 1.0 && before.worst_step_deg > 10.0,
        "{before:?}"
    );
}

/// The first `scans` of the hand-held OS1-128 walk (seed 1, sweeps distorted by their motion)
/// and the LiDAR's pose on the body.
fn hand_held_walk(scans: usize) -> (Vec<Sample>, Pose3) {
    hand_held_walk_of_seed(1, scans)
}

/// The first `scans` of the hand-held OS1-128 walk of `seed` and the LiDAR's pose on the body.
fn hand_held_walk_of_seed(seed: u64, scans: usize) -> (Vec<Sample>, Pose3) {
    let config = SimulationConfig::handheld_os1_128(seed);
    let sim = SimulatedSpot::corridor_loop(&config).unwrap();
    let body_t_lidar = sim.body_t_lidar();
    (sim.take(scans).collect(), body_t_lidar)
}

#[test]
fn a_shaking_hand_held_dense_lidar_is_tracked_in_six_degrees_of_freedom() {
    // An OS1-128 (131,072 rays a sweep) carried by a walking person: 2 Hz scans, each a 0.1 s
    // sweep distorted by a hand shaking by 3 degrees of roll and pitch and 8 of yaw, turns of
    // up to 43 degrees between scans. The first 80 scans: 40 s, two corners.
    let (samples, body_t_lidar) = hand_held_walk(80);
    assert!(samples[0].cloud.len() > 80_000);
    let now = lidar_only(slam_config(), &samples, &body_t_lidar);
    eprintln!("adaptive reach, sweep motion: {now:?}");
    assert_eq!(now.fallbacks, 0, "{now:?}");
    assert!(now.worst_step_deg <= 2.0, "{now:?}");
    // Measured: 2.9 cm ATE, 0.5 degrees of roll or pitch at worst, 4.6 cm lower than the truth
    // after the 45 m walked (no loop closes in these 40 s; the whole lap ends within 1 cm).
    assert!(now.ate <= 0.05 && now.tilt_deg <= 1.0, "{now:?}");
    assert!(now.height.abs() <= 0.10, "{now:?}");
    let before = lidar_only(fixed_reach_config(), &samples, &body_t_lidar);
    eprintln!("fixed reach, constant-velocity deskew: {before:?}");
    assert!(before.steps_over_2_deg > 5, "{before:?}");
}

/// Seed 11's hand-held walk to just past its fourth corner (150 scans, 75 s), where at 71 s the
/// sensor turns 39° between two scans and the wide stages once slid the scan 1.9 m along the new
/// corridor; on the way, scans carried about 0.2 m short (10.5 s). The fine stage and the sweep's
/// motion run again from the predicted position (`TrackerConfig::recheck_distance`) hold it.
/// Measured (no loop closes in these 75 s), with every recheck run whole
/// (`TrackerConfig::recheck_basin` 0, where this walk's knife edge was measured): ATE 4.0 cm and
/// no step more than 0.9° off with the recheck; without it ATE 6.8 cm and two steps 3.6° off at
/// 39 s. As set up, a recheck whose cheap first pass ends in the registration's basin stops
/// there: ATE 4.9 cm, no step more than 0.9° off, held to the same bounds. (Before the sweep's
/// points were moved along a blended path, `slam_core::SweepPath`, the run without the recheck
/// slid at the corner: ATE 0.30 m and a step 23° off. Which scan a run without the recheck loses
/// moves with such changes; that it loses one does not.)
#[test]
fn a_scan_slid_along_a_corridor_at_a_sharp_corner_is_found_again_from_the_predicted_position() {
    let (samples, body_t_lidar) = hand_held_walk_of_seed(11, 150);
    let held = |o: &Outcome| o.worst_step_deg <= 2.0 && o.fallbacks == 0 && o.ate <= 0.08;
    let set_up = lidar_only(slam_config(), &samples, &body_t_lidar);
    eprintln!("recheck as set up: {set_up:?}");
    assert!(held(&set_up), "{set_up:?}");
    let mut whole = slam_config();
    whole.tracker.recheck_basin = 0.0;
    let with = lidar_only(whole.clone(), &samples, &body_t_lidar);
    eprintln!("recheck run whole: {with:?}");
    assert!(held(&with), "{with:?}");
    let mut config = whole;
    config.tracker.recheck_distance = 0.0;
    let without = lidar_only(config, &samples, &body_t_lidar);
    eprintln!("no recheck: {without:?}");
    assert!(
        without.worst_step_deg > 2.0 && without.ate > with.ate + 0.02,
        "{without:?}"
    );
}

/// Seed 35's hand-held walk through its first corner (45 scans, 22 s). Mid-turn at 17.5 s the
/// scan is deskewed with the last step's turn rate (96°/s) where the hand had nearly stopped, and
/// registers 5.5° off; its sweep's own motion matches 74 % of it against 61 % but cuts the RMS
/// error by 4.9 %, just short of `GraphSlamConfig::sweep_min_gain`. Taken for matching clearly
/// more (`GraphSlamConfig::sweep_min_inlier_gain`), no step is more than 2° off; judged by the
/// RMS error alone, a step is 9° off. Measured with every recheck run whole
/// (`TrackerConfig::recheck_basin` 0); as set up, the rechecks' cheap first pass keeps that scan
/// within 2° either way (1.1° at worst over these scans), held to the same bound.
#[test]
fn a_sweep_that_matches_clearly_more_of_a_turning_scan_is_taken() {
    let (samples, body_t_lidar) = hand_held_walk_of_seed(35, 45);
    let set_up = lidar_only(slam_config(), &samples, &body_t_lidar);
    eprintln!("as set up: {set_up:?}");
    assert!(
        set_up.worst_step_deg <= 2.0 && set_up.fallbacks == 0,
        "{set_up:?}"
    );
    let whole = GraphSlamConfig {
        tracker: TrackerConfig {
            recheck_basin: 0.0,
            ..slam_config().tracker
        },
        ..slam_config()
    };
    let with = lidar_only(whole.clone(), &samples, &body_t_lidar);
    eprintln!("sweep taken for matching more: {with:?}");
    assert!(
        with.worst_step_deg <= 2.0 && with.fallbacks == 0,
        "{with:?}"
    );
    let rmse_only = GraphSlamConfig {
        sweep_min_inlier_gain: 1.0,
        ..whole
    };
    let without = lidar_only(rmse_only, &samples, &body_t_lidar);
    eprintln!("RMS error alone: {without:?}");
    assert!(without.worst_step_deg > 5.0, "{without:?}");
}

/// A hand's turns come in jolts: at 2 Hz the last step's turn says little about the next. The
/// first 100 scans of the hand-held walk of seed 6, where a constant-velocity prediction put
/// scan 81 so far off that the widest coarse stage pulled it 16° the wrong way along a corridor
/// (measured: ATE 27 cm over these scans, steps up to 19.7° off). Predicting with the share of
/// the last turn that has predicted best lately (mostly none here) keeps every step within 2°.
#[test]
fn a_hand_helds_jolts_are_predicted_with_its_heading_held() {
    let (samples, body_t_lidar) = hand_held_walk_of_seed(6, 100);
    let now = lidar_only(slam_config(), &samples, &body_t_lidar);
    eprintln!("adaptive turn share: {now:?}");
    let [held, _, all] = now.turn_shares;
    assert!(held > 2 * all, "{now:?}");
    assert!(now.fallbacks == 0 && now.worst_step_deg <= 2.0, "{now:?}");
    assert!(now.ate <= 0.05, "{now:?}");
    // The retry from the refused registration's turn rescues constant velocity here too (ATE
    // 2.4 cm, 1.9° at worst): without it, the prediction alone tells them apart.
    let mut config = slam_config();
    config.tracker.retry_found_turn = false;
    let held = lidar_only(config.clone(), &samples, &body_t_lidar);
    eprintln!("adaptive turn share, no retry from the found turn: {held:?}");
    assert!(
        held.fallbacks == 0 && held.worst_step_deg <= 2.0,
        "{held:?}"
    );
    let constant = GraphSlamConfig {
        turn_prediction: TurnPrediction::ConstantVelocity,
        ..config
    };
    let before = lidar_only(constant, &samples, &body_t_lidar);
    eprintln!("constant velocity: {before:?}");
    assert_eq!(before.turn_shares[..2], [0, 0], "{before:?}");
    assert!(before.worst_step_deg > 10.0, "{before:?}");
}

/// The first 80 scans of the hand-held OS1-128 walk, as simulated and with every point moved
/// 10 micrometres along x: a nudge that small must not change where the walk ends up. With the
/// local map thinned to the scan's own 0.25 m voxel, the scan's centroids and the map's form one
/// lattice and the fine stage locks onto its steps along corridors: on these scans the walk
/// then ends 9.6 cm ATE (and the same map rebuilt whole instead of in place, a difference of
/// rounding only, 2.3 cm) unless the fine stage is run again from the predicted position
/// (`TrackerConfig::recheck_distance`, on by default: 2.3 cm). The tracker's own map (0.2 m)
/// under 0.25 m scans: 2.8 cm both times. Without the recheck, other map voxels sit on the same knife edge at the walk's second corner (scans
/// 71-73): 0.15 m and 0.16 m each end 2.3 cm one way and 9.5 or 5.0 cm (a step 5.8° off) the
/// other; 0.1 m and 0.18 m end within 0.1 cm of themselves.
#[test]
fn a_micrometre_nudge_leaves_the_hand_held_walk_where_it_was() {
    let (samples, body_t_lidar) = hand_held_walk(80);
    let nudged: Vec<Sample> = samples
        .iter()
        .map(|s| {
            let mut s = s.clone();
            for p in s.cloud.points_mut() {
                p.x += 1e-5;
            }
            s
        })
        .collect();
    let run = |voxel: f32, recheck: f64, samples: &[Sample]| {
        let mut tracker = point_to_plane_tracker();
        tracker.config.target_voxel = voxel;
        let mut config = slam_config();
        config.tracker.recheck_distance = recheck;
        let slam = point_to_plane_slam_with(config, tracker).unwrap();
        lidar_only_with(slam, samples, &body_t_lidar)
    };
    let voxel = point_to_plane_tracker().config.target_voxel;
    let recheck = slam_config().tracker.recheck_distance;
    let (a, b) = (run(voxel, recheck, &samples), run(voxel, recheck, &nudged));
    eprintln!("{voxel} m map: {a:?}\nnudged: {b:?}");
    assert!((a.ate - b.ate).abs() <= 0.005, "{a:?}\n{b:?}");
    assert!(a.ate <= 0.05 && b.ate <= 0.05, "{a:?}\n{b:?}");
    // The map on the scan's own lattice locks onto its steps unless the fine stage is run
    // again from the predicted position (`TrackerConfig::recheck_distance`).
    let locked = run(0.25, 0.0, &samples);
    eprintln!("0.25 m map, no recheck: {locked:?}");
    assert!(locked.ate > 0.05, "{locked:?}");
    let rechecked = run(0.25, recheck, &samples);
    eprintln!("0.25 m map: {rechecked:?}");
    assert!(rechecked.ate <= 0.05, "{rechecked:?}");
}

/// A gyro's rotation between two scans predicts the next scan's orientation
/// (`ScanInput::gyro_orientation`): Spot's lap with scans skewed by walking (12 cm a sweep),
/// kept at one scan in five (turns of up to 52° between scans), with a gyro drifting 0.2°/s.
/// Measured: ATE 5.8 cm, the end at the start's height, 4 scans recovered by a retry, no step
/// more than 0.3° off; predicted from the last step alone (its turn repeated in part, as the
/// engine judges best) ATE 8.0 cm, 2.7 cm of height drift, 7 recovered and two steps more than
/// 2° off (4.0° at worst).
#[test]
fn a_gyro_predicts_the_turns_between_scans() {
    let mut config = SimulationConfig::with_seed(1);
    config.motion_distortion = true;
    config.gyro_drift = Some(0.2f64.to_radians());
    let sim = SimulatedSpot::corridor_loop(&config).unwrap();
    let body_t_lidar = sim.body_t_lidar();
    let samples: Vec<Sample> = sim.step_by(5).collect();
    assert!(samples.iter().all(|s| s.gyro_orientation.is_some()));
    let with = lidar_only(slam_config(), &samples, &body_t_lidar);
    eprintln!("gyro: {with:?}");
    assert_eq!(with.gyro_predictions, samples.len() - 1, "{with:?}");
    assert!(with.ate <= 0.08 && with.fallbacks == 0, "{with:?}");
    assert!(
        with.height.abs() <= 0.05 && with.worst_step_deg <= 1.0,
        "{with:?}"
    );
    let no_gyro: Vec<Sample> = samples
        .into_iter()
        .map(|s| Sample {
            gyro_orientation: None,
            ..s
        })
        .collect();
    let without = lidar_only(slam_config(), &no_gyro, &body_t_lidar);
    eprintln!("no gyro: {without:?}");
    assert_eq!(without.gyro_predictions, 0);
    assert!(
        without.ate > with.ate
            && without.recovered > with.recovered
            && without.worst_step_deg > 2.0,
        "{without:?}"
    );
}

/// The static HDL-32E garage sequence: all 30 frames of the shared data set when it is there
/// (`SPOT_NAV_DATA`, default `../shared/data`), else the first 10, bundled with the
/// registration crate's tests (see `registration/tests/data/README.md`).
fn garage_frames() -> Vec<(f64, PointCloud)> {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    let root = std::env::var_os("SPOT_NAV_DATA")
        .map_or_else(|| here.join("../../shared/data"), PathBuf::from);
    let shared = root.join("lidar/hdl32e_garage_seq");
    let dir = if shared.is_dir() {
        shared
    } else {
        here.join("../registration/tests/data/hdl32e_garage")
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "pcd"))
        .collect();
    files.sort();
    files
        .iter()
        .map(|p| {
            let stamp: f64 = p.file_stem().unwrap().to_str().unwrap().parse().unwrap();
            (stamp, slam_core::io::read_pcd(p).unwrap())
        })
        .collect()
}

/// The real garage frames fed LiDAR-only, each with `extra` points added; each scan's pose
/// and the points the engine dropped.
fn standing(extra: &[nalgebra::Point3<f32>]) -> (Vec<slam_core::io::StampedPose>, usize) {
    let frames = garage_frames();
    assert!(frames.len() >= 10);
    let mut slam = point_to_plane_slam(slam_config()).unwrap();
    for (stamp, cloud) in &frames {
        // The extra points with the channels the frame has (ring 0, intensity 0, time 0).
        let (mut points, ring, intensity, time) = cloud.clone().into_parts();
        points.extend_from_slice(extra);
        let mut cloud = PointCloud::from_points(points);
        let pad = |v: Option<Vec<f32>>| {
            v.map(|mut v| {
                v.resize(v.len() + extra.len(), 0.0);
                v
            })
        };
        if let Some(mut r) = ring {
            r.resize(r.len() + extra.len(), 0);
            cloud = cloud.with_ring(r).unwrap();
        }
        if let Some(i) = pad(intensity) {
            cloud = cloud.with_intensity(i).unwrap();
        }
        if let Some(t) = pad(time) {
            cloud = cloud.with_time(t).unwrap();
        }
        let sample = Sample {
            stamp: *stamp,
            odom_t_body: Pose3::identity(),
            body_t_lidar: Pose3::identity(),
            cloud,
            ground_truth: None,
            gyro_orientation: None,
        };
        slam.process(&sample.lidar_only_input());
    }
    let trajectory = slam.scan_trajectory();
    assert_eq!(trajectory.len(), frames.len());
    (trajectory, slam.report().dropped_points)
}

#[test]
fn a_standing_sensor_stays_put() {
    if slam_core::skip_without_test_data!("../registration/tests/data") {
        return;
    }
    // Real scans of a sensor that did not move: every pose must stay at the first.
    let (trajectory, _) = standing(&[]);
    let start = trajectory[0].pose;
    for p in &trajectory {
        let d = start.inverse() * p.pose;
        let (moved, turned) = (d.translation.vector.norm(), d.rotation.angle().to_degrees());
        assert!(
            moved <= 0.005 && turned <= 0.2,
            "{}: {moved} m, {turned} degrees",
            p.stamp
        );
    }
    let end = start.inverse() * trajectory[trajectory.len() - 1].pose;
    eprintln!(
        "{} frames: ends {:.4} m and {:.3} degrees from the start",
        trajectory.len(),
        end.translation.vector.norm(),
        end.rotation.angle().to_degrees()
    );
    // The same frames, each with a garbled return 1e30 m out (beyond any voxel key: it made
    // the thinning fail, then the whole scan degenerate) and one 1e5 m out: the same poses,
    // and the garbled ones counted as dropped.
    let (absurd, dropped) = standing(&[
        nalgebra::Point3::new(1e30, 0.0, 0.0),
        nalgebra::Point3::new(0.0, -1e5, 3.0),
    ]);
    assert_eq!(dropped, trajectory.len());
    for (a, b) in trajectory.iter().zip(&absurd) {
        let d = a.pose.inverse() * b.pose;
        assert!(
            d.translation.vector.norm() < 1e-4 && d.rotation.angle() < 1e-4,
            "{}: {d:?}",
            a.stamp
        );
    }
}
