//! The spinning LiDAR's presets: the VLP-16 as it always was, and an Ouster OS1-128 whose scans
//! are checked against its data-sheet layout and the building's surfaces.

#![allow(clippy::unwrap_used)]

use std::collections::HashMap;

use nalgebra::{Translation3, UnitQuaternion};
use slam_core::Pose3;
use spot_adapter::sim::{Building, BuildingConfig, LidarConfig, SimRng, SpinningLidar};

use crate::simulator::on_surface;

/// The OS1-128 in the middle of the building's south corridor, 1.3 m up (carried by hand),
/// turned a little off the corridor's axis.
fn corridor_pose(b: &Building) -> Pose3 {
    let c = b.corridor_loop();
    let mid = 0.5 * (c[0] + c[1]);
    Pose3::from_parts(
        Translation3::new(mid.x, mid.y, 1.3),
        UnitQuaternion::from_euler_angles(0.03, -0.02, 0.4),
    )
}

#[test]
fn the_vlp16_preset_is_the_default_and_the_data_sheet() {
    let v = LidarConfig::vlp16();
    assert_eq!(v, LidarConfig::default());
    assert_eq!((v.rings, v.columns, v.rays()), (16, 1800, 28_800));
    assert!((v.lowest_elevation.to_degrees() + 15.0).abs() < 1e-12);
    assert!((v.highest_elevation().to_degrees() - 15.0).abs() < 1e-12);
    assert!((v.rotation_rate - 5.0).abs() < 1e-12);
}

#[test]
fn an_os1_128_scan_has_128_rings_within_plus_minus_22_5_degrees() {
    let b = Building::generate(11, &BuildingConfig::default()).unwrap();
    let config = LidarConfig::os1_128();
    let lidar = SpinningLidar::new(config.clone()).unwrap();
    assert!((lidar.sweep_period() - 0.1).abs() < 1e-12, "10 Hz");
    let cloud = lidar.scan(&b, &corridor_pose(&b), &mut SimRng::new(11, 1));
    // A closed corridor returns nearly all 131,072 rays; those closer than 0.8 m are dropped.
    assert!(
        (100_000..=131_072).contains(&cloud.len()),
        "{} points",
        cloud.len()
    );
    let ring = cloud.ring().unwrap();
    let mut seen = [false; 128];
    let limit = 22.5f64.to_radians() + 1e-6;
    for (p, &r) in cloud.points().iter().zip(ring) {
        // The elevation from the coordinates alone: range noise moves a point along its ray,
        // never off it.
        let el = f64::from(p.z).atan2(f64::from(p.x).hypot(f64::from(p.y)));
        assert!(el.abs() <= limit, "elevation {}°", el.to_degrees());
        let expected = (-22.5 + 45.0 * f64::from(r) / 127.0).to_radians();
        assert!(
            (el - expected).abs() < 1e-5,
            "ring {r} at {}°",
            el.to_degrees()
        );
        seen[usize::from(r)] = true;
    }
    assert!(
        seen.iter().all(|&s| s),
        "every one of the 128 rings returns"
    );
    let time = cloud.time().unwrap();
    assert!(time.iter().all(|&t| (0.0..0.1).contains(&t)));
    assert!(time.iter().any(|&t| t > 0.099), "the sweep lasts 0.1 s");
}

#[test]
fn every_os1_128_point_lies_on_a_surface_of_the_building() {
    let b = Building::generate(12, &BuildingConfig::default()).unwrap();
    let pose = corridor_pose(&b);
    // Without noise: each return on a surface to 2 mm along its ray.
    let mut config = LidarConfig::os1_128();
    config.range_noise = 0.0;
    let clean = SpinningLidar::new(config)
        .unwrap()
        .scan(&b, &pose, &mut SimRng::new(12, 1));
    for (k, p) in clean.points().iter().enumerate().step_by(3) {
        assert!(on_surface(&b, &pose, p, 2e-3), "point {k}");
    }
    // With the data sheet's noise: the same rays (a beam is its ring and firing time), each
    // return within 5 sigma of the surface, the noise of the configured size.
    let noisy = SpinningLidar::new(LidarConfig::os1_128()).unwrap().scan(
        &b,
        &pose,
        &mut SimRng::new(12, 1),
    );
    let beam = |cloud: &slam_core::PointCloud, k: usize| {
        (cloud.ring().unwrap()[k], cloud.time().unwrap()[k].to_bits())
    };
    let surface: HashMap<_, f32> = (0..clean.len())
        .map(|k| (beam(&clean, k), clean.points()[k].coords.norm()))
        .collect();
    let mut squares = 0.0;
    for (k, p) in noisy.points().iter().enumerate() {
        let error = f64::from(p.coords.norm() - surface[&beam(&noisy, k)]);
        assert!(
            error.abs() < 5.0 * 0.015,
            "point {k}: {error} m off the surface"
        );
        squares += error * error;
    }
    let sigma = (squares / noisy.len() as f64).sqrt();
    assert!((sigma - 0.015).abs() < 5e-4, "noise sigma {sigma}");
}

/// The SLAM tracker's local map follows the sensor's density, set from the first scan: a
/// VLP-16 scan (at most 28,800 points) gets the sparse scans' 0.15 m map, an OS1-128 scan (over
/// 100,000) the dense scans' 0.2 m, and a sparse scan after a dense first one changes nothing.
/// The oracle: the scans' point counts against `point_to_plane_tracker`'s 60,000.
#[test]
fn the_trackers_map_voxel_follows_the_first_scans_density() {
    use slam_core::MapRegistrator;
    use spot_adapter::pipelines::{point_to_plane_slam, point_to_plane_tracker, slam_config};

    let b = Building::generate(11, &BuildingConfig::default()).unwrap();
    let scan = |config: LidarConfig| {
        SpinningLidar::new(config)
            .unwrap()
            .scan(&b, &corridor_pose(&b), &mut SimRng::new(11, 1))
    };
    let (sparse, dense) = (scan(LidarConfig::vlp16()), scan(LidarConfig::os1_128()));
    assert!(sparse.len() <= 28_800 && dense.len() > 100_000);
    let rule = point_to_plane_tracker().config;
    assert_eq!(rule.sparse_scan_points, 60_000);
    let input = |stamp: f64, cloud| slam_core::ScanInput {
        stamp,
        odom_t_body: None,
        body_t_lidar: Pose3::identity(),
        cloud,
        gyro_orientation: None,
    };
    for (first, then, voxel) in [(&sparse, &dense, 0.15), (&dense, &sparse, 0.2)] {
        let mut slam = point_to_plane_slam(slam_config()).unwrap();
        assert_eq!(slam.registrator().map_voxel(), Some(0.2), "before any scan");
        slam.process(&input(0.0, first));
        assert_eq!(slam.registrator().map_voxel(), Some(voxel));
        slam.process(&input(0.1, then));
        assert_eq!(slam.registrator().map_voxel(), Some(voxel));
        assert_eq!(
            slam.registrator().config.sparse_scan_points,
            0,
            "the rule is spent"
        );
        assert_eq!(slam.report().keyframes, 1);
    }
}
