//! Harder simulated motion: Spot turning at corners at its full yaw rate, and a person carrying
//! an OS1-128 at 2 Hz. The ground truth is checked by finite differences of the true pose, and
//! a motion-distorted sweep against the building through the true pose at each point's time.

#![allow(clippy::unwrap_used)]

use slam_core::Pose3;
use spot_adapter::sim::{
    Building, BuildingConfig, LidarConfig, MotionProfile, Route, SimulatedSpot, SimulationConfig,
};

use crate::simulator::on_surface;

/// Heading (yaw, radians) of a pose.
fn yaw(p: &Pose3) -> f64 {
    p.rotation.euler_angles().2
}

/// The signed heading change from `a` to `b`, wrapped to `(-pi, pi]`.
fn heading_change(a: &Pose3, b: &Pose3) -> f64 {
    let d = yaw(b) - yaw(a);
    (d + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
}

/// A run of `config` on one lap of building `seed`'s corridor loop.
fn lap(seed: u64, config: &SimulationConfig) -> SimulatedSpot {
    let b = Building::generate(seed, &BuildingConfig::default()).unwrap();
    let route = Route::corridor_loop(&b);
    SimulatedSpot::new(b, &route, config).unwrap()
}

#[test]
fn fast_turns_reach_but_never_exceed_the_full_yaw_rate() {
    let mut config = SimulationConfig::with_seed(2);
    config.motion = MotionProfile::fast_turns();
    let sim = lap(2, &config);
    let end = sim.ground_truth().last().unwrap().stamp;
    // The true pose every 10 ms: yaw rate and speed by finite differences.
    let dt = 0.01;
    let poses: Vec<Pose3> = (0..=(end / dt).ceil() as usize)
        .map(|k| sim.pose_at(k as f64 * dt))
        .collect();
    let (mut counted, mut corners) = (false, 0);
    for w in poses.windows(2) {
        let rate = w[0].rotation.angle_to(&w[1].rotation) / dt;
        let speed = (w[1].translation.vector - w[0].translation.vector).norm() / dt;
        assert!(rate <= 1.0 + 1e-9, "yaw rate {rate} rad/s");
        assert!(speed <= 0.6 + 1e-9, "speed {speed} m/s");
        // Past the first 25 ms of a turn (2 rad/s^2): a window that straddles the stop and
        // the start of the turn sees both.
        if rate > 0.05 {
            assert!(speed < 1e-9, "turns in place: {speed} m/s while turning");
        }
        // A corner counts once its turn reaches the full rate.
        if rate > 0.999 && !counted {
            corners += 1;
            counted = true;
        }
        counted &= rate > 1e-6;
    }
    assert_eq!(corners, 4, "four corners at the full yaw rate");
    // Between 5 Hz samples the heading changes by up to 1 rad/s * 0.2 s = 11.5 degrees.
    let truth = sim.ground_truth();
    let largest = truth
        .windows(2)
        .map(|w| heading_change(&w[0].pose, &w[1].pose).abs())
        .fold(0.0, f64::max);
    assert!((0.19..=0.2 + 1e-9).contains(&largest), "{largest} rad");
    for w in truth.windows(2) {
        assert!((w[1].stamp - w[0].stamp - 0.2).abs() < 1e-9);
    }
    let (first, last) = (truth[0].pose, truth[truth.len() - 1].pose);
    assert!((first.translation.vector - last.translation.vector).norm() < 1e-9);
    assert!(first.rotation.angle_to(&last.rotation) < 1e-9);
}

/// The handheld defaults with an OS1-128.
fn handheld() -> SimulationConfig {
    let mut config = SimulationConfig::with_seed(4);
    config.lidar = LidarConfig::os1_128();
    config.motion = MotionProfile::handheld();
    config
}

#[test]
fn a_handheld_walk_turns_fast_shakes_and_ends_where_it_started() {
    let sim = lap(4, &handheld());
    assert_eq!(
        sim.body_t_lidar(),
        Pose3::identity(),
        "the LiDAR is the body"
    );
    let truth = sim.ground_truth();
    let changes: Vec<f64> = truth
        .windows(2)
        .map(|w| heading_change(&w[0].pose, &w[1].pose).abs().to_degrees())
        .collect();
    let mut sorted = changes.clone();
    sorted.sort_by(f64::total_cmp);
    let (median, largest) = (sorted[sorted.len() / 2], sorted[sorted.len() - 1]);
    eprintln!(
        "handheld: {} samples, heading change median {median:.1}°, max {largest:.1}°",
        truth.len()
    );
    assert!((40.0..=56.0).contains(&largest), "max {largest}°");
    // Four corners of 90 degrees: at least one sample pair in each turns by more than 30.
    assert!(changes.iter().filter(|&&c| c > 30.0).count() >= 4);
    let (mut roll, mut pitch, mut bob) = (0.0f64, 0.0f64, 0.0f64);
    for w in truth.windows(2) {
        assert!((w[1].stamp - w[0].stamp - 0.5).abs() < 1e-9, "2 Hz");
        let step = (w[1].pose.translation.vector - w[0].pose.translation.vector).xy();
        assert!(
            step.norm() <= 1.2 * 0.5 + 1e-9,
            "{} m in 0.5 s",
            step.norm()
        );
        let (r, p, _) = w[1].pose.rotation.euler_angles();
        (roll, pitch) = (roll.max(r.abs()), pitch.max(p.abs()));
        bob = bob.max((w[1].pose.translation.z - 1.3).abs());
    }
    let few_degrees = 3f64.to_radians() + 1e-9;
    assert!(
        roll > 0.5f64.to_radians() && roll <= few_degrees,
        "roll {roll}"
    );
    assert!(
        pitch > 0.5f64.to_radians() && pitch <= few_degrees,
        "pitch {pitch}"
    );
    assert!(bob > 0.005 && bob <= 0.02 + 1e-9, "bob {bob} m");
    // A flat floor: the lap ends at the height, place and heading it started from.
    let (first, last) = (truth[0].pose, truth[truth.len() - 1].pose);
    assert!((first.translation.z - 1.3).abs() < 1e-12);
    assert!((first.translation.vector - last.translation.vector).norm() < 1e-9);
    assert!(first.rotation.angle_to(&last.rotation) < 1e-9);
}

#[test]
fn a_handheld_sweep_lands_on_the_building_through_the_pose_at_each_points_time() {
    let mut config = handheld();
    config.lidar.range_noise = 0.0;
    config.motion_distortion = true;
    // One corner, from the middle of the south corridor 5 m into the east one.
    let building = Building::generate(4, &BuildingConfig::default()).unwrap();
    let c = building.corridor_loop();
    let east = c[1] + (c[2] - c[1]).normalize() * 5.0;
    let route = Route::new(vec![0.5 * (c[0] + c[1]), c[1], east], false).unwrap();
    let mut sim = SimulatedSpot::new(building.clone(), &route, &config).unwrap();
    let truth = sim.ground_truth();
    // The sample starting the fastest turn between two samples: the sweep turns most there.
    let k = (0..truth.len() - 1)
        .max_by(|&a, &b| {
            let turn = |i: usize| heading_change(&truth[i].pose, &truth[i + 1].pose).abs();
            turn(a).total_cmp(&turn(b))
        })
        .unwrap();
    let reference = sim.clone();
    let sample = sim.nth(k).unwrap();
    eprintln!("sample {k} of {}", truth.len());
    assert_eq!(sample.ground_truth, Some(truth[k].pose));
    let time = sample.cloud.time().unwrap();
    assert!(
        time.iter().all(|&t| (0.0..0.1).contains(&t)),
        "one 0.1 s sweep"
    );
    let at_stamp = truth[k].pose;
    let mut displaced = 0;
    for (i, p) in sample.cloud.points().iter().enumerate().step_by(7) {
        let pose = reference.pose_at(sample.stamp + f64::from(time[i]));
        assert!(
            on_surface(&building, &pose, p, 2e-3),
            "point {i} at {} s",
            time[i]
        );
        // Seen from the pose at the stamp instead, late points land elsewhere.
        let off = (pose * p.cast::<f64>() - at_stamp * p.cast::<f64>()).norm();
        displaced += usize::from(time[i] > 0.05 && off > 0.05);
    }
    assert!(
        displaced > 1000,
        "the sweep is distorted: {displaced} points moved"
    );
}
