//! Sources without odometry: a folder of scans and a simulated lap with its odometry removed,
//! run LiDAR-only (every scan registered against the engine's local map), checked against the
//! true motion; cloud folders
//! with a TUM odometry file; no-return points in KITTI scans.

#![allow(clippy::unwrap_used, clippy::panic, clippy::float_cmp)]

use std::path::{Path, PathBuf};

use nalgebra::{Point3, Translation3, UnitQuaternion};
use slam_core::io::{StampedPose, write_kitti_bin, write_tum};
use slam_core::{PointCloud, Pose3};
use spot_adapter::eval::{DEFAULT_MAX_STAMP_DIFFERENCE, absolute_trajectory_error};
use spot_adapter::pipelines::{point_to_plane_slam, slam_config};
use spot_adapter::record::{RecordingKind, SourceConfig, open_recording};
use spot_adapter::robot::Sample;
use spot_adapter::sim::{SimulatedSpot, SimulationConfig};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("spot-adapter-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The bundled HDL-32E garage scan (libwave, MIT; see slam-core/tests/data/README.md).
fn garage_scan() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../slam-core/tests/data/hdl32e_garage_1503604882.703390000.pcd")
}

#[test]
fn a_static_scan_folder_runs_lidar_only_without_drifting() {
    if slam_core::skip_without_test_data!("../slam-core/tests/data") {
        return;
    }
    // The same real scan ten times, named by stamp: the true motion is zero.
    let dir = temp_dir("static-folder");
    for i in 0..10 {
        std::fs::copy(
            garage_scan(),
            dir.join(format!("{}.pcd", 100.0 + 0.1 * f64::from(i))),
        )
        .unwrap();
    }
    let source = open_recording(&dir, &SourceConfig::default()).unwrap();
    assert_eq!(source.kind, RecordingKind::CloudFolder);
    assert!(!source.has_odometry);
    let samples = source.samples;
    assert_eq!(samples.len(), 10);
    let mut slam = point_to_plane_slam(slam_config()).unwrap();
    for (i, s) in samples.enumerate() {
        let s = s.unwrap();
        assert!((s.stamp - (100.0 + 0.1 * i as f64)).abs() < 1e-9);
        slam.process(&s.lidar_only_input());
    }
    let trajectory = slam.scan_trajectory();
    assert_eq!(trajectory.len(), 10);
    // The map is thinned to a finer voxel than the scan (`point_to_plane_tracker`), so the
    // scan's centroids do not sit on the map's own: a few hundredths of a degree remain
    // (measured 0.02°; 0 when both voxels were 0.25 m).
    for (i, p) in trajectory.iter().enumerate() {
        let t = p.pose.translation.vector.norm();
        assert!(t < 1e-3, "scan {i}: {t} m from the start");
        let angle = p.pose.rotation.angle();
        assert!(angle < 1e-3, "scan {i}: {angle} rad");
    }
    assert_eq!(slam.report().fallbacks(), 0, "{:?}", slam.report().tracking);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_lap_without_odometry_is_tracked_from_its_scans() {
    let sim = SimulatedSpot::corridor_loop(&SimulationConfig::with_seed(2)).unwrap();
    let truth = sim.ground_truth();
    let body_t_lidar = sim.body_t_lidar();
    let mut slam = point_to_plane_slam(slam_config()).unwrap();
    // The robot's odometry left out.
    for s in sim.take(80) {
        slam.process(&s.lidar_only_input());
    }
    let estimate: Vec<StampedPose> = slam
        .scan_trajectory()
        .into_iter()
        .map(|p| StampedPose {
            stamp: p.stamp,
            pose: p.pose * body_t_lidar.inverse(),
        })
        .collect();
    let ate = absolute_trajectory_error(&estimate, &truth, DEFAULT_MAX_STAMP_DIFFERENCE).unwrap();
    assert_eq!(ate.pairs, 80);
    assert!(
        slam.keyframe_count() > 10,
        "{} keyframes",
        slam.keyframe_count()
    );
    assert!(ate.rmse < 0.10, "ATE {} m", ate.rmse);
    let report = slam.report();
    assert_eq!(report.fallbacks(), 0, "{:?}", report.tracking);
}

fn pose(x: f64, yaw: f64) -> Pose3 {
    Pose3::from_parts(
        Translation3::new(x, 0.0, 0.0),
        UnitQuaternion::from_euler_angles(0.0, 0.0, yaw),
    )
}

#[test]
fn a_folder_with_odometry_takes_it_at_each_scan_stamp() {
    if slam_core::skip_without_test_data!("../slam-core/tests/data") {
        return;
    }
    let dir = temp_dir("folder-odometry");
    let scans = dir.join("scans");
    std::fs::create_dir_all(&scans).unwrap();
    for name in ["10.0", "10.5", "11.0"] {
        std::fs::copy(garage_scan(), scans.join(format!("{name}.pcd"))).unwrap();
    }
    let tum = dir.join("odometry.tum");
    write_tum(
        &tum,
        &[
            StampedPose {
                stamp: 10.0,
                pose: pose(0.0, 0.0),
            },
            StampedPose {
                stamp: 11.0,
                pose: pose(1.0, 0.2),
            },
        ],
    )
    .unwrap();
    let mount = pose(0.1, 0.0);
    let config = SourceConfig {
        body_t_lidar: Some(mount),
        odometry: Some(tum.clone()),
        ..SourceConfig::default()
    };
    let source = open_recording(&scans, &config).unwrap();
    assert!(source.has_odometry);
    let got: Vec<Sample> = source.samples.map(Result::unwrap).collect();
    assert_eq!(got.len(), 3);
    assert_eq!(got[0].odom_t_body, pose(0.0, 0.0));
    let mid = got[1].odom_t_body;
    assert!((mid.translation.vector.x - 0.5).abs() < 1e-12);
    assert!((mid.rotation.angle() - 0.1).abs() < 1e-12);
    assert!((got[2].odom_t_body.translation.vector.x - 1.0).abs() < 1e-12);
    assert_eq!(got[2].body_t_lidar, mount);
    // A scan outside the odometry is an error naming the file.
    std::fs::copy(garage_scan(), scans.join("12.0.pcd")).unwrap();
    let err = open_recording(&scans, &config).unwrap_err();
    assert!(err.to_string().contains("odometry.tum"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn kitti_no_return_points_are_removed_and_counted() {
    let dir = temp_dir("kitti-zeros");
    std::fs::create_dir_all(dir.join("velodyne")).unwrap();
    let mut points: Vec<Point3<f32>> = (0..50)
        .map(|i| Point3::new(2.0 + i as f32 * 0.1, 1.0, 0.5))
        .collect();
    points.extend([Point3::origin(); 7]);
    points.push(Point3::new(0.02, 0.0, 0.0));
    write_kitti_bin(
        dir.join("velodyne/000000.bin"),
        &PointCloud::from_points(points),
    )
    .unwrap();
    let source = open_recording(&dir, &SourceConfig::default()).unwrap();
    assert_eq!(source.kind, RecordingKind::Kitti);
    let mut samples = source.samples;
    let s = samples.next().unwrap().unwrap();
    assert_eq!(s.cloud.len(), 50);
    assert_eq!(samples.dropped_points().no_return, 8);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn nanosecond_times_in_scan_files_are_read_as_seconds() {
    let dir = temp_dir("ns-times");
    let points: Vec<Point3<f32>> = (0..100)
        .map(|i| Point3::new(2.0 + i as f32 * 0.01, 1.0, 0.5))
        .collect();
    // Ouster's convention: nanoseconds since the scan's start, up to 0.099 s.
    let ns: Vec<f32> = (0..100).map(|i| i as f32 * 1.0e6).collect();
    let cloud = PointCloud::from_points(points.clone())
        .with_time(ns)
        .unwrap();
    slam_core::io::write_pcd(
        dir.join("1.0.pcd"),
        &cloud,
        slam_core::io::PcdEncoding::Binary,
    )
    .unwrap();
    let seconds: Vec<f32> = (0..100).map(|i| i as f32 * 1.0e-3).collect();
    let cloud = PointCloud::from_points(points.clone())
        .with_time(seconds.clone())
        .unwrap();
    slam_core::io::write_pcd(
        dir.join("1.1.pcd"),
        &cloud,
        slam_core::io::PcdEncoding::Binary,
    )
    .unwrap();
    let source = open_recording(&dir, &SourceConfig::default()).unwrap();
    let mut samples = source.samples;
    let first = samples.next().unwrap().unwrap();
    for (got, want) in first.cloud.time().unwrap().iter().zip(&seconds) {
        assert!((got - want).abs() < 1e-8, "{got} s, not {want} s");
    }
    // The unit was decided on the first scan: a later one in seconds no longer fits it.
    let err = samples.next().unwrap().unwrap_err();
    assert!(err.to_string().contains("1.1.pcd"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
    // Times that fit no unit are an error naming the file.
    let dir = temp_dir("bad-times");
    let five: Vec<f32> = (0..100).map(|i| i as f32 * 0.05).collect();
    let cloud = PointCloud::from_points(points).with_time(five).unwrap();
    slam_core::io::write_pcd(
        dir.join("1.0.pcd"),
        &cloud,
        slam_core::io::PcdEncoding::Binary,
    )
    .unwrap();
    let mut samples = open_recording(&dir, &SourceConfig::default())
        .unwrap()
        .samples;
    let err = samples.next().unwrap().unwrap_err();
    assert!(err.to_string().contains("no unit"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
