//! A simulated run written as a folder of scans any tool reads (`CloudFolderWriter`): plain
//! files, read back by spot-nav's cloud-folder reader point for point, with the LiDAR's true
//! trajectory and odometry beside the scans.

#![allow(clippy::unwrap_used, clippy::float_cmp)]

use std::fs;
use std::path::PathBuf;

use slam_core::io::read_tum;
use spot_adapter::record::RecordError;
use spot_adapter::record::{
    CloudFolder, CloudFolderConfig, RecordingKind, SourceConfig, open_recording,
};
use spot_adapter::robot::Sample;
use spot_adapter::sim::SimError;
use spot_adapter::sim::{
    CLOUD_FOLDER_GROUND_TRUTH, CLOUD_FOLDER_ODOMETRY, CloudFolderWriter, CloudFormat,
    SimulatedSpot, SimulationConfig,
};

/// A fresh folder under the system's temporary folder.
fn fresh(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("spot-adapter-{name}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    dir
}

/// The first `n` samples of `config`'s corridor lap, and the folder they were written to.
fn write(config: &SimulationConfig, n: usize, format: CloudFormat, dir: &PathBuf) -> Vec<Sample> {
    let samples: Vec<Sample> = SimulatedSpot::corridor_loop(config)
        .unwrap()
        .take(n)
        .collect();
    let mut writer = CloudFolderWriter::create(dir, format).unwrap();
    for s in &samples {
        writer.write(s).unwrap();
    }
    assert_eq!(&writer.finish().unwrap(), dir);
    samples
}

/// The TUM file `name` in `dir` agrees with `expected` pose by pose.
fn trajectory_is(dir: &std::path::Path, name: &str, expected: &[(f64, slam_core::Pose3)]) {
    let read = read_tum(dir.join(name)).unwrap();
    assert_eq!(read.len(), expected.len(), "{name}");
    for (r, (stamp, pose)) in read.iter().zip(expected) {
        assert_eq!(r.stamp, *stamp, "{name}");
        let d = pose.inverse() * r.pose;
        assert!(
            d.translation.vector.norm() < 1e-9 && d.rotation.angle() < 1e-9,
            "{name}"
        );
    }
}

#[test]
fn a_handheld_run_written_as_plain_ply_files_reads_back_point_for_point() {
    let config = SimulationConfig::handheld_os1_128(5);
    let dir = fresh("ply-folder");
    let samples = write(&config, 3, CloudFormat::Ply, &dir);
    let mut names: Vec<String> = fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "000000.000000000.ply",
            "000000.500000000.ply",
            "000001.000000000.ply",
            CLOUD_FOLDER_GROUND_TRUTH,
            CLOUD_FOLDER_ODOMETRY,
        ]
    );
    // Plain binary PLY: x y z and time, all float, nothing else.
    let bytes = fs::read(dir.join(&names[1])).unwrap();
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap();
    let header = String::from_utf8_lossy(&bytes[..end]);
    let properties: Vec<&str> = header
        .lines()
        .filter(|l| l.starts_with("property"))
        .collect();
    assert!(header.contains("format binary_little_endian 1.0"));
    assert_eq!(
        properties,
        [
            "property float x",
            "property float y",
            "property float z",
            "property float time"
        ]
    );
    assert_eq!(bytes.len() - end - 11, 16 * samples[1].cloud.len());
    // The folder opens as a cloud folder, the ground truth file beside the scans ignored.
    let source = open_recording(&dir, &SourceConfig::default()).unwrap();
    assert_eq!(source.kind, RecordingKind::CloudFolder);
    assert_eq!(source.body_t_lidar, slam_core::Pose3::identity());
    let read: Vec<Sample> = source.samples.map(Result::unwrap).collect();
    assert_eq!(read.len(), 3);
    for (r, s) in read.iter().zip(&samples) {
        assert_eq!(r.stamp, s.stamp);
        assert_eq!(r.cloud.points(), s.cloud.points());
        assert_eq!(r.cloud.time(), s.cloud.time());
    }
    // The handheld LiDAR is the body: its trajectory is the ground truth itself.
    let truth: Vec<_> = samples
        .iter()
        .map(|s| (s.stamp, s.ground_truth.unwrap()))
        .collect();
    trajectory_is(&dir, CLOUD_FOLDER_GROUND_TRUTH, &truth);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_spot_run_written_as_pcd_files_carries_the_lidars_poses() {
    let config = SimulationConfig::with_seed(6);
    let dir = fresh("pcd-folder");
    let samples = write(&config, 3, CloudFormat::Pcd, &dir);
    let mount = samples[0].body_t_lidar;
    assert!(
        mount.translation.vector.norm() > 0.1,
        "Spot's LiDAR is not its body"
    );
    let lidar = |pose: slam_core::Pose3| pose * mount;
    let truth: Vec<_> = samples
        .iter()
        .map(|s| (s.stamp, lidar(s.ground_truth.unwrap())))
        .collect();
    trajectory_is(&dir, CLOUD_FOLDER_GROUND_TRUTH, &truth);
    let odometry: Vec<_> = samples
        .iter()
        .map(|s| (s.stamp, lidar(s.odom_t_body)))
        .collect();
    trajectory_is(&dir, CLOUD_FOLDER_ODOMETRY, &odometry);
    // Replayed with its odometry and no calibration: the body is the LiDAR.
    let folder = CloudFolder::open(
        &dir,
        &CloudFolderConfig {
            odometry: Some(dir.join(CLOUD_FOLDER_ODOMETRY)),
            ..CloudFolderConfig::default()
        },
    )
    .unwrap();
    for ((r, s), (_, odom_t_lidar)) in folder.samples().zip(&samples).zip(&odometry) {
        let r = r.unwrap();
        assert_eq!(r.cloud.points(), s.cloud.points());
        let d = odom_t_lidar.inverse() * r.odom_t_body;
        assert!(d.translation.vector.norm() < 1e-9 && d.rotation.angle() < 1e-9);
    }
    // A folder that holds scans already is not written over.
    assert!(matches!(
        CloudFolderWriter::create(&dir, CloudFormat::Ply),
        Err(SimError::Record(RecordError::FolderHoldsScans { .. }))
    ));
    fs::remove_dir_all(&dir).unwrap();
}
