//! ROS bags written by the Python `rosbags` package (an independent implementation of both bag
//! formats and of CDR and ROS 1 serialisation) from a simulated lap: replaying them gives what
//! feeding the simulator directly gives, every cloud layout decodes to the recorded cloud, and
//! bad bags are clear errors.
//!
//! The bags are written at test time by `tests/bags/write_bags.py` in a virtual environment this
//! test makes on first use under `target/` with the pinned packages of
//! `tests/bags/requirements.txt`. Without Python or the package registry the tests fail with the
//! reason (a skipped test would pass without checking anything).

#![allow(
    clippy::unwrap_used,
    clippy::panic,
    clippy::expect_used,
    clippy::float_cmp
)]

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use slam_core::PointCloud;
use slam_core::io::StampedPose;
use spot_adapter::MessageError;
use spot_adapter::pipelines::{point_to_plane_slam, slam_config};
use spot_adapter::record::RecordError;
use spot_adapter::record::{
    Bag, BagConfig, ImuSource, OdometrySource, PointCloud2Config, Recording, ResolvedOdometry,
    TimeUnit,
};
use spot_adapter::robot::Sample;
use spot_adapter::sim::{SimulatedSpot, SimulationConfig};

/// Scans of the simulated lap put in the bags.
const SCANS: usize = 40;

fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR").map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("../target"),
        PathBuf::from,
    )
}

fn run(cmd: &mut Command, what: &str) {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("{what}: cannot start {cmd:?}: {e}"));
    assert!(
        out.status.success(),
        "{what} failed ({}):\n{}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The venv's python, made on first use.
fn python() -> PathBuf {
    let requirements = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bags/requirements.txt");
    let venv = target_dir().join("rosbags-venv-0.11.9");
    let python = venv.join("bin/python");
    if !python.exists() {
        // Built beside and renamed into place, so an interrupted install is never taken as done
        // (only its `bin/python` is run, which finds the moved venv by its `pyvenv.cfg`).
        let building = target_dir().join(format!("rosbags-venv-building-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&building);
        run(
            Command::new("python3").arg("-m").arg("venv").arg(&building),
            "making a Python venv (python3 with venv is required)",
        );
        run(
            Command::new(building.join("bin/pip"))
                .args(["install", "--quiet", "--no-input", "-r"])
                .arg(&requirements),
            "installing the pinned rosbags from PyPI",
        );
        if std::fs::rename(&building, &venv).is_err() {
            // Another test process finished first.
            let _ = std::fs::remove_dir_all(&building);
        }
    }
    python
}

/// The simulation: scans cast while walking, so every cloud carries per-point times.
fn sim_config() -> SimulationConfig {
    let mut config = SimulationConfig::with_seed(3);
    config.motion_distortion = true;
    config
}

fn lap() -> impl Iterator<Item = Sample> {
    SimulatedSpot::corridor_loop(&sim_config())
        .unwrap()
        .take(SCANS)
}

/// The folder of bags written from the lap (`bags/` holds the bags, see
/// `tests/bags/write_bags.py`): written once for this build of the tests and this script, and
/// reused by every test and test process after (a runner such as cargo-nextest runs each test in
/// a process of its own; they take turns by a lock on a file beside the folder, so that none
/// reads bags another is still writing).
pub(crate) fn bags() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let python = python();
        let tmp = target_dir().join("tmp");
        std::fs::create_dir_all(&tmp).unwrap();
        let lock = std::fs::File::create(tmp.join("bags-fixture.lock")).unwrap();
        lock.lock().unwrap();
        let dir = tmp.join("bags-fixture");
        let stamp = dir.join("written-for");
        let written_for = fixture_key();
        if std::fs::read_to_string(&stamp).is_ok_and(|s| s == written_for) {
            return dir;
        }
        let _ = std::fs::remove_dir_all(&dir);
        let recording = dir.join("recording");
        let sim = SimulatedSpot::corridor_loop(&sim_config()).unwrap();
        let mut writer =
            spot_adapter::record::RecordingWriter::create(&recording, sim.body_t_lidar()).unwrap();
        for sample in lap() {
            writer.write(&sample).unwrap();
        }
        writer.finish().unwrap();
        run(
            Command::new(python)
                .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bags/write_bags.py"))
                .arg(&recording)
                .arg(dir.join("bags")),
            "writing the bags with rosbags",
        );
        // Last: a folder without its stamp (an interrupted run) is written again.
        std::fs::write(&stamp, written_for).unwrap();
        dir
    })
    .as_path()
}

/// What the bags were written by: this test binary (its path and modification time: a rebuilt
/// simulator or test rebuilds it) and the script with its pinned packages.
fn fixture_key() -> String {
    use std::hash::{DefaultHasher, Hash, Hasher};
    let exe = std::env::current_exe().unwrap();
    let built = std::fs::metadata(&exe).and_then(|m| m.modified()).unwrap();
    let mut script = DefaultHasher::new();
    for file in ["tests/bags/write_bags.py", "tests/bags/requirements.txt"] {
        std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join(file))
            .unwrap()
            .hash(&mut script);
    }
    format!("{} {built:?} {:016x}", exe.display(), script.finish())
}

fn mcap(dir: &Path) -> PathBuf {
    dir.join("bags/lap_ros2/lap_ros2.mcap")
}

fn ros1(dir: &Path) -> PathBuf {
    dir.join("bags/lap.bag")
}

fn layouts(dir: &Path) -> PathBuf {
    dir.join("bags/layouts/layouts.mcap")
}

fn trajectory<I: Iterator<Item = Sample>>(samples: I) -> Vec<StampedPose> {
    let mut slam = point_to_plane_slam(slam_config()).unwrap();
    for s in samples {
        slam.process(&s.scan_input());
    }
    slam.scan_trajectory()
}

fn assert_same_trajectory(got: &[StampedPose], want: &[StampedPose]) {
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(want) {
        assert!(
            (g.stamp - w.stamp).abs() < 1e-9,
            "{} vs {}",
            g.stamp,
            w.stamp
        );
        let d = g.pose.inverse() * w.pose;
        assert!(
            d.translation.vector.norm() < 1e-9 && d.rotation.angle() < 1e-9,
            "at {}: {} m, {} rad apart",
            g.stamp,
            d.translation.vector.norm(),
            d.rotation.angle()
        );
    }
}

#[test]
fn replaying_either_bag_gives_the_simulators_trajectory() {
    let dir = bags();
    let want = trajectory(lap());
    // The first skewed scan waits for a velocity to deskew with.
    assert_eq!(want.len(), SCANS - 1);
    for path in [mcap(dir), ros1(dir)] {
        // The lap's IMU is a constant placeholder reading, not the simulated body's rotation;
        // the simulator's samples have no gyro, so neither do these.
        let config = BagConfig {
            imu: ImuSource::None,
            ..BagConfig::default()
        };
        let bag = Bag::open(&path, &config).unwrap();
        let summary = bag.summary();
        assert_eq!(summary.cloud_topic, "/points");
        assert_eq!(summary.odometry, ResolvedOdometry::Topic("/odom".into()));
        assert_eq!(
            (summary.base_frame.as_str(), summary.lidar_frame.as_str()),
            ("base_link", "velodyne")
        );
        assert_eq!(bag.len(), SCANS);
        let sim = lap().next().unwrap();
        let d = bag.body_t_lidar().inverse() * sim.body_t_lidar;
        assert!(d.translation.vector.norm() < 1e-12);
        let mut samples = bag.samples().unwrap();
        let mut read = Vec::new();
        for (got, want) in (&mut samples).zip(lap()) {
            let got = got.unwrap();
            assert_eq!(
                got.cloud,
                want.cloud,
                "{}: clouds arrive exactly",
                path.display()
            );
            assert_eq!(got.gyro_orientation, None);
            read.push(got);
        }
        assert_eq!(samples.dropped_points().no_return, 0);
        assert!(!samples.imu_before_last_sample().is_empty());
        assert_same_trajectory(&trajectory(read.into_iter()), &want);
    }
}

#[test]
fn odometry_from_tf_equals_odometry_from_its_topic() {
    let dir = bags();
    let by_topic = Bag::open(mcap(dir), &BagConfig::default()).unwrap();
    let by_tf = Bag::open(
        mcap(dir),
        &BagConfig {
            odometry: OdometrySource::Tf {
                odom_frame: "odom".into(),
            },
            ..BagConfig::default()
        },
    )
    .unwrap();
    assert_eq!(by_tf.summary().base_frame, "base_link");
    for (a, b) in by_topic.samples().unwrap().zip(by_tf.samples().unwrap()) {
        let (a, b) = (a.unwrap(), b.unwrap());
        assert_eq!(a.odom_t_body, b.odom_t_body);
    }
}

/// The recording's clouds, as the simulator gave them.
fn recorded_clouds(dir: &Path) -> Vec<PointCloud> {
    Recording::open(dir.join("recording"))
        .unwrap()
        .samples()
        .map(|s| s.unwrap().cloud)
        .collect()
}

fn layout_bag(dir: &Path, topic: &str) -> Result<Bag, RecordError> {
    layout_bag_in(&layouts(dir), topic)
}

fn layout_bag_in(path: &Path, topic: &str) -> Result<Bag, RecordError> {
    Bag::open(
        path,
        &BagConfig {
            cloud_topic: Some(topic.into()),
            ..BagConfig::default()
        },
    )
}

#[test]
fn every_layout_decodes_to_the_recorded_cloud() {
    let dir = bags();
    let want = recorded_clouds(dir);
    let cases = [
        ("/f64_ring8_ns", TimeUnit::NanosecondsRelative, true),
        ("/ouster", TimeUnit::NanosecondsRelative, true),
        ("/split_time", TimeUnit::SecondsAbsolute, true),
        ("/absolute_seconds", TimeUnit::SecondsAbsolute, true),
        ("/relative_f64", TimeUnit::SecondsRelative, false),
        ("/big_endian_rows", TimeUnit::SecondsRelative, true),
        ("/with_zeros", TimeUnit::SecondsRelative, false),
    ];
    for ((topic, unit, ring), path) in cases
        .iter()
        .copied()
        .flat_map(|case| [(case, layouts(dir)), (case, dir.join("bags/layouts.bag"))])
    {
        let bag = layout_bag_in(&path, topic).unwrap();
        assert_eq!(bag.summary().odometry, ResolvedOdometry::None, "{topic}");
        let mut samples = bag.samples().unwrap();
        let mut n = 0;
        for (got, want) in (&mut samples).zip(&want) {
            let got = got.unwrap();
            // Without an IMU topic, no gyro.
            assert_eq!(got.gyro_orientation, None);
            let got = got.cloud;
            n += 1;
            // The organised big-endian cloud drops an odd last point.
            let len = if topic == "/big_endian_rows" {
                want.len() & !1
            } else {
                want.len()
            };
            assert_eq!(got.len(), len, "{topic}");
            assert_eq!(got.points(), &want.points()[..len], "{topic}");
            if ring {
                assert_eq!(got.ring().unwrap(), &want.ring().unwrap()[..len], "{topic}");
            }
            let (gt, wt) = (got.time().unwrap(), want.time().unwrap());
            // Nanosecond integers and absolute float seconds carry the time to about 1e-7 s.
            let worst = gt
                .iter()
                .zip(wt)
                .map(|(a, b)| (a - b).abs())
                .fold(0f32, f32::max);
            assert!(worst < 2e-6, "{topic}: times {worst} s off");
        }
        assert_eq!(n, 3, "{topic}");
        let dropped = samples.dropped_points();
        let zeros = if topic == "/with_zeros" { 300 } else { 0 };
        assert_eq!(
            (dropped.no_return, dropped.non_finite),
            (zeros, 0),
            "{topic}"
        );
        assert_eq!(bag.time_unit(), Some(unit), "{topic} in {}", path.display());
    }
}

/// The topic, index and reason of a message error.
fn message_error(err: &RecordError) -> Option<(&str, usize, &MessageError)> {
    match err {
        RecordError::Message {
            topic,
            index,
            source,
            ..
        } => Some((topic, *index, source)),
        _ => None,
    }
}

/// Open `path` and read every sample: whatever the bytes, an answer and no panic.
fn read_all(path: &Path) -> Result<usize, RecordError> {
    let bag = Bag::open(path, &BagConfig::default())?;
    let mut n = 0;
    for s in bag.samples()? {
        s?;
        n += 1;
    }
    Ok(n)
}

#[test]
fn cut_and_corrupted_bags_never_panic() {
    let dir = bags();
    for (path, name) in [(mcap(dir), "mangled.mcap"), (ros1(dir), "mangled.bag")] {
        let bytes = std::fs::read(&path).unwrap();
        let out = dir.join(name);
        // Cut anywhere: inside the magic, the header, a chunk, the index.
        for k in 0..12u64 {
            let len = (bytes.len() as u64 * k * k / 144) as usize;
            std::fs::write(&out, &bytes[..len.max(k as usize)]).unwrap();
            assert!(
                read_all(&out).is_err(),
                "{name} cut at {len} bytes read as whole"
            );
        }
        // Bytes overwritten in the header, the first chunk, the middle and the index.
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        for _ in 0..24 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let mut bad = bytes.clone();
            let at = match state % 4 {
                0 => (state >> 8) as usize % 4096,
                1 => 4096 + (state >> 8) as usize % 65536,
                2 => bytes.len() / 2 + (state >> 8) as usize % 4096,
                _ => bytes.len() - 1 - (state >> 8) as usize % 4096,
            };
            for b in &mut bad[at..(at + 8).min(bytes.len())] {
                *b ^= (state >> 40) as u8 | 1;
            }
            std::fs::write(&out, &bad).unwrap();
            // An error or (when the bytes hit an unused field) a whole read; never a panic.
            let _ = read_all(&out);
        }
    }
}

#[test]
fn bad_bags_are_clear_errors() {
    let dir = bags();
    // Truncated files.
    for (path, name) in [(mcap(dir), "cut.mcap"), (ros1(dir), "cut.bag")] {
        let bytes = std::fs::read(&path).unwrap();
        let cut = dir.join(name);
        std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
        let err = Bag::open(&cut, &BagConfig::default()).unwrap_err();
        assert!(
            matches!(
                err,
                RecordError::Mcap { .. }
                    | RecordError::Unindexed { .. }
                    | RecordError::Ros1Header { .. }
            ),
            "{err}"
        );
        assert!(err.to_string().contains(name), "{err}");
    }
    // A topic of another type chosen as the clouds.
    let err = Bag::open(
        mcap(dir),
        &BagConfig {
            cloud_topic: Some("/odom".into()),
            ..BagConfig::default()
        },
    )
    .unwrap_err();
    assert!(
        matches!(&err, RecordError::Message { topic, index: 0, source, .. } if topic == "/odom" && matches!(**source, MessageError::UnknownType { .. })),
        "{err}"
    );
    // A LiDAR frame the tf tree does not hold.
    let err = Bag::open(
        ros1(dir),
        &BagConfig {
            lidar_frame: Some("camera".into()),
            ..BagConfig::default()
        },
    )
    .unwrap_err();
    assert!(
        matches!(&err, RecordError::UnlinkedLidar { body_frame, lidar_frame, .. } if body_frame == "base_link" && lidar_frame == "camera"),
        "{err}"
    );
    // A cloud without coordinates, and times that fit no unit.
    let err = layout_bag(dir, "/no_xyz").unwrap_err();
    assert!(
        matches!(
            message_error(&err),
            Some((_, _, MessageError::MissingCoordinate { axis: "x", .. }))
        ),
        "{err}"
    );
    let err = layout_bag(dir, "/five_second_sweep").unwrap_err();
    assert!(
        matches!(
            message_error(&err),
            Some((_, _, MessageError::TimeUnit { .. }))
        ),
        "{err}"
    );
    assert!(err.to_string().contains("layouts.mcap"), "{err}");
    // Several cloud topics and none chosen.
    let err = Bag::open(layouts(dir), &BagConfig::default()).unwrap_err();
    assert!(err.to_string().contains("several cloud topics"), "{err}");
    // A forced unit that the data contradicts.
    let err = Bag::open(
        layouts(dir),
        &BagConfig {
            cloud_topic: Some("/ouster".into()),
            cloud: PointCloud2Config {
                time_unit: Some(TimeUnit::SecondsRelative),
                ..PointCloud2Config::default()
            },
            ..BagConfig::default()
        },
    )
    .unwrap_err();
    assert!(
        matches!(
            message_error(&err),
            Some((_, _, MessageError::TimeUnit { .. }))
        ),
        "{err}"
    );
}
