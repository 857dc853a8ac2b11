//! The simulated robot: LiDAR returns at the ray-cast distance, determinism, odometry drift.

// Test helpers outside #[test] functions unwrap too, and exact float equality is the point
// where stored values must round-trip bit for bit.
#![allow(clippy::unwrap_used, clippy::panic, clippy::float_cmp)]

use nalgebra::{Point3, Translation3, UnitQuaternion, Vector3};
use slam_core::Pose3;
use spot_adapter::eval::end_point_drift;
use spot_adapter::robot::SpotGeometry;
use spot_adapter::sim::{
    Building, BuildingConfig, LidarConfig, OdometryDriftConfig, OdometryModel, Route, SimRng,
    SimulatedSpot, SimulationConfig, SpinningLidar,
};

/// Whether `q` is in solid matter: inside a box, below the floor or above the ceiling.
fn inside(b: &Building, q: Point3<f64>) -> bool {
    q.z <= 0.0
        || q.z >= b.ceiling_height()
        || b.boxes()
            .iter()
            .any(|bx| (0..3).all(|i| q[i] >= bx.min[i] && q[i] <= bx.max[i]))
}

/// Whether `q` is within `tolerance` metres of solid matter (a box, the floor or the ceiling).
fn near_solid(b: &Building, q: Point3<f64>, tolerance: f64) -> bool {
    q.z <= tolerance
        || q.z >= b.ceiling_height() - tolerance
        || b.boxes().iter().any(|bx| {
            let outside = (0..3).map(|i| (bx.min[i] - q[i]).max(q[i] - bx.max[i]).max(0.0));
            outside.map(|d| d * d).sum::<f64>() <= tolerance * tolerance
        })
}

/// Whether the point `local` (LiDAR frame) seen from `world_t_lidar` is a return from a surface
/// of `b` to within `tolerance` metres along its ray: free space just before it, and solid
/// matter just behind it (or, for a ray that clips a box's corner, within `tolerance` of the
/// point). An oracle independent of the ray caster.
pub(crate) fn on_surface(
    b: &Building,
    world_t_lidar: &Pose3,
    local: &Point3<f32>,
    tolerance: f64,
) -> bool {
    let local = nalgebra::convert::<_, Vector3<f64>>(local.coords);
    let (o, dir, r) = (
        Point3::from(world_t_lidar.translation.vector),
        world_t_lidar.rotation * local.normalize(),
        local.norm(),
    );
    !inside(b, o + dir * (r - tolerance))
        && (inside(b, o + dir * (r + tolerance)) || near_solid(b, o + dir * r, tolerance))
}

fn noiseless() -> LidarConfig {
    LidarConfig {
        range_noise: 0.0,
        ..LidarConfig::default()
    }
}

#[test]
fn scan_points_lie_at_the_ray_cast_distance() {
    let b = Building::generate(21, &BuildingConfig::default()).unwrap();
    let lidar = SpinningLidar::new(noiseless()).unwrap();
    let start = b.corridor_loop()[1];
    let world_t_lidar = Pose3::from_parts(
        Translation3::new(start.x - 0.3, start.y + 0.2, 0.8),
        UnitQuaternion::from_euler_angles(0.02, -0.03, 0.7),
    );
    let cloud = lidar.scan(&b, &world_t_lidar, &mut SimRng::new(0, 0));
    let (ring, time) = (cloud.ring().unwrap(), cloud.time().unwrap());
    assert!(
        cloud.len() > 28_000,
        "closed building: nearly every ray returns"
    );
    for (k, p) in cloud.points().iter().enumerate().step_by(37) {
        // Rebuild the ray from the ring and time channels alone.
        let col = (f64::from(time[k]) / 0.2 * 1800.0).round();
        let az = col * 0.2f64.to_radians();
        let el = (-15.0 + 2.0 * f64::from(ring[k])).to_radians();
        let dir = Vector3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
        let p64 = nalgebra::convert::<_, Vector3<f64>>(p.coords);
        assert!(
            (p64.normalize() - dir).norm() < 1e-5,
            "point {k} off its beam"
        );
        // Independent oracle: free space 2 mm before the return, solid matter (a box, below the
        // floor or above the ceiling) 2 mm behind it.
        let o = Point3::from(world_t_lidar.translation.vector);
        let wd = world_t_lidar.rotation * dir;
        let r = p64.norm();
        assert!(
            !inside(&b, o + wd * (r - 2e-3)),
            "point {k}: free space ends before the return"
        );
        assert!(
            inside(&b, o + wd * (r + 2e-3)),
            "point {k}: no surface at the return"
        );
    }
}

/// A scan at rest is the same cloud as a plain scan (same noise stream) with every time 0.
#[test]
fn scan_at_rest_has_the_points_of_a_scan_and_zero_times() {
    let b = Building::generate(6, &BuildingConfig::default()).unwrap();
    let lidar = SpinningLidar::new(LidarConfig::default()).unwrap();
    let c = b.corridor_loop()[0];
    let pose = Pose3::translation(c.x + 1.0, c.y, 0.8);
    let scan = lidar.scan(&b, &pose, &mut SimRng::new(4, 4));
    let rest = lidar.scan_at_rest(&b, &pose, &mut SimRng::new(4, 4));
    assert_eq!(scan.points(), rest.points());
    assert_eq!(scan.ring(), rest.ring());
    assert!(scan.time().unwrap().iter().any(|&t| t > 0.1));
    assert!(rest.time().unwrap().iter().all(|&t| t == 0.0));
}

#[test]
fn moving_scan_casts_each_column_from_its_firing_pose() {
    let b = Building::generate(6, &BuildingConfig::default()).unwrap();
    let lidar = SpinningLidar::new(noiseless()).unwrap();
    let c = b.corridor_loop()[0];
    let start = Pose3::from_parts(
        Translation3::new(c.x + 2.0, c.y, 0.8),
        UnitQuaternion::from_euler_angles(0.0, 0.0, 0.1),
    );
    // 0.12 m forward and 3 degrees of turn during the sweep.
    let end = start
        * Pose3::from_parts(
            Translation3::new(0.12, 0.0, 0.0),
            UnitQuaternion::from_euler_angles(0.0, 0.0, 3f64.to_radians()),
        );
    let moving = lidar.scan_moving(&b, &start, &end, &mut SimRng::new(0, 0));
    let still = lidar.scan(&b, &start, &mut SimRng::new(0, 0));
    let time = moving.time().unwrap();
    // Column 0 fires at the start pose: identical points.
    let first = time.iter().take_while(|&&t| t == 0.0).count();
    assert_eq!(moving.points()[..first], still.points()[..first]);
    let mut moved = 0;
    for (k, p) in moving.points().iter().enumerate().step_by(41) {
        let pose = slam_core::interpolate(&start, &end, f64::from(time[k]) / 0.2);
        let local = nalgebra::convert::<_, Vector3<f64>>(p.coords);
        assert!(on_surface(&b, &pose, p, 2e-3), "point {k}");
        // The same point seen as if from the start pose lands off the surface late in the sweep.
        let naive = start * Point3::from(local);
        moved +=
            usize::from(time[k] > 0.15 && (naive - (pose * Point3::from(local))).norm() > 0.05);
    }
    assert!(
        moved > 50,
        "late columns are displaced by the motion: {moved}"
    );
}

#[test]
fn noise_and_dropouts_have_the_configured_size() {
    let b = Building::generate(3, &BuildingConfig::default()).unwrap();
    let start = b.corridor_loop()[2];
    let pose = Pose3::translation(start.x, start.y, 0.8);
    let clean = SpinningLidar::new(noiseless())
        .unwrap()
        .scan(&b, &pose, &mut SimRng::new(0, 0));
    let noisy_cfg = LidarConfig {
        range_noise: 0.02,
        ..LidarConfig::default()
    };
    let noisy = SpinningLidar::new(noisy_cfg)
        .unwrap()
        .scan(&b, &pose, &mut SimRng::new(0, 0));
    assert_eq!(clean.len(), noisy.len());
    let n = clean.len() as f64;
    let var = clean
        .points()
        .iter()
        .zip(noisy.points())
        .map(|(a, b)| f64::from(b.coords.norm() - a.coords.norm()).powi(2))
        .sum::<f64>()
        / n;
    assert!((var.sqrt() - 0.02).abs() < 0.001, "sigma {}", var.sqrt());
    let mut drop_cfg = noiseless();
    drop_cfg.dropout_probability = 0.1;
    let dropped = SpinningLidar::new(drop_cfg)
        .unwrap()
        .scan(&b, &pose, &mut SimRng::new(0, 0));
    let kept = dropped.len() as f64 / n;
    assert!((kept - 0.9).abs() < 0.01, "kept {kept}");
}

#[test]
fn same_seeds_same_samples() {
    let config = SimulationConfig {
        seed: 9,
        ..SimulationConfig::default()
    };
    let building = Building::generate(5, &BuildingConfig::default()).unwrap();
    let lap = Route::corridor_loop(&building);
    let run = |config: &SimulationConfig| -> Vec<_> {
        SimulatedSpot::new(building.clone(), &lap, config)
            .unwrap()
            .take(3)
            .collect()
    };
    let a = run(&config);
    let b = run(&config);
    assert!(a == b, "same seeds, same samples");
    let other = SimulationConfig {
        seed: 10,
        ..SimulationConfig::default()
    };
    let c = run(&other);
    assert!(a[2].cloud != c[2].cloud);
    assert_ne!(a[2].odom_t_body, c[2].odom_t_body);
    // The ground truth depends only on the building and the route.
    assert_eq!(a[2].ground_truth, c[2].ground_truth);
}

#[test]
fn walk_is_a_closed_lap_at_walking_speed() {
    let config = SimulationConfig::with_seed(8);
    let sim = SimulatedSpot::corridor_loop(&config).unwrap();
    let gt = sim.ground_truth();
    let first = gt[0].pose;
    let last = gt[gt.len() - 1].pose;
    assert!((first.translation.vector - last.translation.vector).norm() < 1e-9);
    assert!((first.rotation.angle_to(&last.rotation)).abs() < 0.05);
    for w in gt.windows(2) {
        let step = (w[1].pose.translation.vector - w[0].pose.translation.vector).norm();
        assert!((w[1].stamp - w[0].stamp - 0.2).abs() < 1e-9);
        assert!(step <= 0.12 + 1e-9, "speed {} m/s", step / 0.2);
        // Smooth heading: at most 0.6 m of chord per 0.12 m step turns under 0.3 rad.
        assert!(w[0].pose.rotation.angle_to(&w[1].pose.rotation) < 0.3);
        assert!((w[0].pose.translation.z - SpotGeometry::default().body_height).abs() < 1e-12);
    }
}

#[test]
fn odometry_drifts_about_1_9_percent() {
    let b = Building::generate(1, &BuildingConfig::default()).unwrap();
    let lap = Route::corridor_loop(&b);
    let walk = lap.walk(0.6, 5.0, 0.5).unwrap();
    // Two laps (> 200 m) per seed.
    let truth: Vec<Pose3> = walk
        .iter()
        .chain(walk.iter().skip(1))
        .map(|w| w.pose)
        .collect();
    let mut drifts = Vec::new();
    let mut vertical = Vec::new();
    for seed in 0..12 {
        let mut odo = OdometryModel::new(OdometryDriftConfig::default(), seed).unwrap();
        let est: Vec<Pose3> = truth.iter().map(|p| odo.step(p)).collect();
        let d = end_point_drift(&est, &truth).unwrap();
        drifts.push(d.relative_drift);
        let e = est[0].inverse() * est[est.len() - 1];
        vertical.push(e.translation.z.abs() / d.path_length);
    }
    let mean = drifts.iter().sum::<f64>() / drifts.len() as f64;
    assert!((mean - 0.019).abs() < 0.002, "mean drift {mean}");
    assert!(
        drifts.iter().all(|d| (0.012..0.026).contains(d)),
        "{drifts:?}"
    );
    let vmean = vertical.iter().sum::<f64>() / vertical.len() as f64;
    assert!((0.002..0.006).contains(&vmean), "vertical drift {vmean}");
}

#[test]
fn gait_sway_moves_the_body_within_its_amplitudes() {
    let mut config = SimulationConfig::default();
    config.lidar.range_noise = 0.0;
    config.gait_sway.height = 0.01;
    config.gait_sway.tilt = 0.01;
    let b = Building::generate(4, &BuildingConfig::default()).unwrap();
    let lap = Route::corridor_loop(&b);
    let level = lap.walk(0.6, 5.0, 0.5).unwrap();
    let mut sim = SimulatedSpot::new(b.clone(), &lap, &config).unwrap();
    let (mut max_dz, mut max_tilt) = (0.0f64, 0.0f64);
    for (g, l) in sim.ground_truth().iter().zip(&level) {
        let d = l.pose.inverse() * g.pose;
        max_dz = max_dz.max(d.translation.z.abs());
        max_tilt = max_tilt.max(d.rotation.angle());
        assert!(d.translation.vector.xy().norm() < 1e-12);
    }
    assert!(max_dz <= 0.01 + 1e-12 && max_dz > 0.005, "{max_dz}");
    assert!(
        max_tilt <= 0.01 * 2f64.sqrt() + 1e-9 && max_tilt > 0.005,
        "{max_tilt}"
    );
    // Scans are cast from the swaying pose: points land on surfaces through it.
    let sample = sim.nth(7).unwrap();
    let world_t_lidar = sample.ground_truth.unwrap() * sample.body_t_lidar;
    for p in sample.cloud.points().iter().step_by(97) {
        assert!(on_surface(&b, &world_t_lidar, p, 2e-3));
    }
}
