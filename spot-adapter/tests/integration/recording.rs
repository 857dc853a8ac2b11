//! Recordings and KITTI folders: round trips and malformed input.

// Test helpers outside #[test] functions unwrap too, and exact float equality is the point
// where stored values must round-trip bit for bit.
#![allow(clippy::unwrap_used, clippy::panic, clippy::float_cmp)]

use std::path::PathBuf;

use nalgebra::{Point3, Translation3, UnitQuaternion, Vector2};
use slam_core::io::{write_kitti_bin, write_kitti_poses};
use slam_core::{PointCloud, Pose3};
use spot_adapter::record::{CalibrationProblem, IndexLineProblem, RecordError};
use spot_adapter::record::{
    IndexEntry, KittiOdometry, KittiSequence, MAX_RECORDING_FILE_BYTES, Recording, RecordingWriter,
    calibration_text, parse_calibration, parse_index,
};
use spot_adapter::sim::{Building, BuildingConfig, Route, SimulatedSpot, SimulationConfig};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("spot-adapter-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn short_run() -> SimulatedSpot {
    let b = Building::generate(2, &BuildingConfig::default()).unwrap();
    let c = b.corridor_loop()[0];
    let route = Route::new(vec![c, c + Vector2::new(0.5, 0.0)], false).unwrap();
    SimulatedSpot::new(b, &route, &SimulationConfig::default()).unwrap()
}

fn close(a: &Pose3, b: &Pose3) -> bool {
    (a.translation.vector - b.translation.vector).norm() < 1e-12
        && a.rotation.angle_to(&b.rotation) < 1e-12
}

#[test]
fn recording_round_trip() {
    let dir = temp_dir("round-trip");
    let expected: Vec<_> = short_run().collect();
    assert_eq!(expected.len(), 6);
    let rec = short_run().record(&dir).unwrap();
    assert_eq!(rec.len(), expected.len());
    assert!(close(&rec.body_t_lidar(), &expected[0].body_t_lidar));
    for (got, want) in rec.samples().zip(&expected) {
        let got = got.unwrap();
        assert_eq!(
            got.cloud, want.cloud,
            "clouds are stored exactly, channels included"
        );
        assert_eq!(got.stamp, want.stamp);
        assert!(close(&got.odom_t_body, &want.odom_t_body));
        assert!(close(
            &got.ground_truth.unwrap(),
            &want.ground_truth.unwrap()
        ));
    }
    // The owning iterator yields the same samples, boxed like any other sample source.
    let stream: Box<dyn Iterator<Item = Result<spot_adapter::robot::Sample, RecordError>>> =
        Box::new(Recording::open(&dir).unwrap().into_iter());
    let mut count = 0;
    for (got, want) in stream.map(Result::unwrap).zip(&expected) {
        assert!(got.cloud == want.cloud && close(&got.odom_t_body, &want.odom_t_body));
        count += 1;
    }
    assert_eq!(count, expected.len());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn recording_without_ground_truth() {
    let dir = temp_dir("no-truth");
    let mut samples: Vec<_> = short_run().collect();
    for s in &mut samples {
        s.ground_truth = None;
    }
    let mut w = RecordingWriter::create(&dir, samples[0].body_t_lidar).unwrap();
    for s in &samples {
        w.write(s).unwrap();
    }
    let rec = Recording::open(w.finish().unwrap()).unwrap();
    assert!(!rec.has_ground_truth() && !dir.join("ground_truth.tum").exists());
    assert!(rec.read_ground_truth().unwrap().is_none());
    assert_eq!(rec.len(), samples.len());
    assert!(rec.samples().all(|s| s.unwrap().ground_truth.is_none()));
    // Mixing samples with and without ground truth, out-of-order stamps, or another mounting
    // are errors.
    let mut w = RecordingWriter::create(&dir, samples[0].body_t_lidar).unwrap();
    w.write(&samples[1]).unwrap();
    let mut with_truth = samples[2].clone();
    with_truth.ground_truth = Some(Pose3::identity());
    assert!(matches!(
        w.write(&with_truth),
        Err(RecordError::PartialGroundTruth { sample: 1, .. })
    ));
    assert!(matches!(
        w.write(&samples[0]),
        Err(RecordError::StampNotIncreasing { .. })
    ));
    let mut moved = samples[3].clone();
    moved.body_t_lidar = Pose3::translation(0.0, 0.0, 0.5);
    assert!(matches!(
        w.write(&moved),
        Err(RecordError::MountingChanged { sample: 1, .. })
    ));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn inconsistent_recordings_are_errors() {
    let dir = temp_dir("broken");
    let _ = short_run().record(&dir).unwrap();
    // One odometry line fewer than scans.
    let odo = std::fs::read_to_string(dir.join("odometry.tum")).unwrap();
    let cut: Vec<&str> = odo.lines().collect();
    std::fs::write(dir.join("odometry.tum"), cut[..cut.len() - 1].join("\n")).unwrap();
    assert!(matches!(
        Recording::open(&dir),
        Err(RecordError::MissingPose { .. })
    ));
    std::fs::write(dir.join("odometry.tum"), odo).unwrap();
    assert!(Recording::open(&dir).is_ok());
    std::fs::write(dir.join("calibration.txt"), "body_T_lidar 0 0 0.3 0 0 0\n").unwrap();
    assert!(matches!(
        Recording::open(&dir),
        Err(RecordError::Calibration {
            problem: CalibrationProblem::NotSevenFinite,
            ..
        })
    ));
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(matches!(Recording::open(&dir), Err(RecordError::Io { .. })));
}

/// The index may only name clouds inside the recording's folder, and a broken line is reported
/// with its file and line number; the check runs when the recording is opened.
#[test]
fn index_lines_are_checked_when_opening() {
    let dir = temp_dir("index");
    let _ = short_run().record(&dir).unwrap();
    let index = std::fs::read_to_string(dir.join("index.txt")).unwrap();
    for bad in ["/dev/zero", "../elsewhere.pcd", "clouds/../../x.pcd"] {
        let edited = index.replacen("clouds/000001.pcd", bad, 1);
        std::fs::write(dir.join("index.txt"), edited).unwrap();
        match Recording::open(&dir) {
            Err(RecordError::IndexLine {
                path,
                line,
                problem: IndexLineProblem::CloudOutside(_),
            }) => {
                assert!(path.ends_with("index.txt"), "{path:?}");
                assert_eq!(line, 4);
            }
            other => panic!("{bad}: {other:?}"),
        }
    }
    // A stamp that disagrees with the odometry's names the odometry file and line.
    let edited = index.replacen(" 0.2 ", " 0.25 ", 1);
    assert_ne!(edited, index);
    std::fs::write(dir.join("index.txt"), edited).unwrap();
    match Recording::open(&dir) {
        Err(RecordError::StampMismatch { path, line, .. }) => {
            assert!(path.ends_with("odometry.tum"), "{path:?}");
            // The odometry file has one header line, the index two.
            assert_eq!(line, 3);
        }
        other => panic!("{other:?}"),
    }
    std::fs::write(dir.join("index.txt"), &index).unwrap();
    assert_eq!(Recording::open(&dir).unwrap().len(), 6);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn kitti_folder_reads_scans_poses_times_and_calibration() {
    let dir = temp_dir("kitti");
    std::fs::create_dir_all(dir.join("velodyne")).unwrap();
    let mut poses = Vec::new();
    for i in 0..3u8 {
        let cloud = PointCloud::from_points(vec![Point3::new(f32::from(i), 1.0, 2.0); 4])
            .with_intensity(vec![0.5; 4])
            .unwrap();
        write_kitti_bin(dir.join(format!("velodyne/{i:06}.bin")), &cloud).unwrap();
        poses.push(Pose3::from_parts(
            Translation3::new(f64::from(i), 0.0, 0.5),
            UnitQuaternion::from_euler_angles(0.0, 0.1 * f64::from(i), 0.0),
        ));
    }
    write_kitti_poses(dir.join("poses.txt"), &poses).unwrap();
    std::fs::write(dir.join("times.txt"), "0.0\n0.1036\n0.2072\n").unwrap();
    std::fs::write(
        dir.join("calib.txt"),
        "P0: 1 0 0 0 0 1 0 0 0 0 1 0\nTr: 0 -1 0 0.1 0 0 -1 -0.2 1 0 0 -0.3\n",
    )
    .unwrap();
    let seq = KittiSequence::open(&dir, KittiOdometry::GroundTruth).unwrap();
    assert_eq!(seq.len(), 3);
    let tr = seq.body_t_lidar();
    // Tr maps the LiDAR's x (forward) to the camera's z (forward).
    assert!((tr * nalgebra::Vector3::x() - nalgebra::Vector3::z()).norm() < 1e-12);
    assert!((tr.translation.vector - nalgebra::Vector3::new(0.1, -0.2, -0.3)).norm() < 1e-12);
    for (i, s) in seq.samples().enumerate() {
        let s = s.unwrap();
        assert_eq!(s.cloud.points()[0].x, i as f32);
        assert!((s.stamp - [0.0, 0.1036, 0.2072][i]).abs() < 1e-12);
        assert!(
            close(&s.odom_t_body, &poses[i])
                || (s.odom_t_body.translation.vector - poses[i].translation.vector).norm() < 1e-9
        );
        assert_eq!(
            s.ground_truth.map(|g| g.translation.vector),
            Some(poses[i].translation.vector)
        );
    }
    std::fs::remove_file(dir.join("poses.txt")).unwrap();
    assert!(matches!(
        KittiSequence::open(&dir, KittiOdometry::GroundTruth),
        Err(RecordError::NoGroundTruth { .. })
    ));
    let seq = KittiSequence::open(&dir, KittiOdometry::None).unwrap();
    assert_eq!(
        seq.sample(1).unwrap().unwrap().odom_t_body,
        Pose3::identity()
    );
    std::fs::write(dir.join("times.txt"), "0.0\n0.1\n").unwrap();
    assert!(matches!(
        KittiSequence::open(&dir, KittiOdometry::None),
        Err(RecordError::CountMismatch { what: "times", .. })
    ));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Files a recording names must be regular files within the size limit: a cloud, the index or
/// the calibration linked to `/dev/zero` (endless) or a sparse file past the limit is refused when
/// the recording is opened, without reading it.
#[cfg(unix)]
#[test]
fn devices_and_oversized_files_are_refused() {
    let dir = temp_dir("devices");
    let _ = short_run().record(&dir).unwrap();
    let refused = |dir: &std::path::Path, name: &str, what: &str| {
        let e = Recording::open(dir).unwrap_err();
        let (RecordError::NotRegularFile { path } | RecordError::FileTooLarge { path, .. }) = &e
        else {
            panic!("{name}: {e:?}");
        };
        assert!(path.ends_with(name), "{path:?}");
        assert!(e.to_string().contains(what), "{e}");
    };
    for name in ["clouds/000002.pcd", "index.txt", "calibration.txt"] {
        let file = dir.join(name);
        let saved = std::fs::read(&file).unwrap();
        std::fs::remove_file(&file).unwrap();
        std::os::unix::fs::symlink("/dev/zero", &file).unwrap();
        refused(&dir, name, "not a regular file");
        std::fs::remove_file(&file).unwrap();
        // A sparse file one byte past the limit takes no disk space.
        std::fs::File::create(&file)
            .unwrap()
            .set_len(MAX_RECORDING_FILE_BYTES + 1)
            .unwrap();
        refused(&dir, name, "more than the limit");
        std::fs::write(&file, saved).unwrap();
    }
    assert_eq!(Recording::open(&dir).unwrap().len(), 6);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The index and calibration texts parse from memory and write back to the same entries.
#[test]
fn index_and_calibration_text_round_trip() {
    let text = "# spot-nav recording v1\n# index stamp cloud\n0 0.1 clouds/000000.pcd\n\n7 1e-7 ./a/b.pcd\n";
    let entries = parse_index(text).unwrap();
    assert_eq!(
        entries[1],
        IndexEntry {
            index: 7,
            stamp: 1e-7,
            cloud: PathBuf::from("./a/b.pcd")
        }
    );
    let back: String = entries.iter().map(|e| e.to_line() + "\n").collect();
    assert_eq!(parse_index(&back).unwrap(), entries);
    for (bad, line) in [
        ("x 0.1 a.pcd", 1),
        ("\n0 inf a.pcd", 2),
        ("0 0.1 /dev/zero", 1),
    ] {
        match parse_index(bad) {
            Err(e @ RecordError::IndexLine { line: l, .. }) if l == line => {
                assert!(e.to_string().contains(&format!("line {line}:")), "{e}");
            }
            other => panic!("{bad}: {other:?}"),
        }
    }
    let pose = Pose3::from_parts(
        Translation3::new(0.1, -0.2, 0.45),
        UnitQuaternion::from_euler_angles(0.01, -0.02, 3.0),
    );
    assert_eq!(parse_calibration(&calibration_text(&pose)).unwrap(), pose);
    assert!(parse_calibration("body_T_lidar 0 0 0 0 0 0 2").is_err());
}
