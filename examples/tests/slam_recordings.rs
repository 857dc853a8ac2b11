//! The `slam` example on recordings: a folder of real scans runs LiDAR-only and writes every
//! output; a folder of a real scan seen from known poses is evaluated against them (TUM and
//! KITTI ground truth) and `summary.json` says what the run printed; a broken bag fails with the
//! file named and leaves no output folder.

// Counts are read back from text as floats and must match exactly.
#![allow(clippy::expect_used, clippy::panic, clippy::float_cmp)]

use std::fmt::Write as _;

use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::example;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("spot-nav-slam-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn a_scan_folder_without_calibration_or_odometry_is_mapped() {
    let scans = temp_dir("folder");
    std::fs::create_dir_all(&scans).expect("temp folder");
    let scan = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../slam-core/tests/data/hdl32e_garage_1503604882.703390000.pcd");
    for i in 0..4 {
        std::fs::copy(
            &scan,
            scans.join(format!("{}.pcd", 20.0 + 0.1 * f64::from(i))),
        )
        .expect("copy the scan");
    }
    let out = temp_dir("folder-out");
    let run = Command::new(example("slam"))
        .arg(&scans)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("slam runs");
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(
        stdout.contains("cloud folder") && stdout.contains("4 scans"),
        "{stdout}"
    );
    assert!(stdout.contains("LiDAR-only"), "{stdout}");
    for file in [
        "map.ply",
        "map.pcd",
        "trajectory.tum",
        "graph.g2o",
        "grid.png",
        "map.yaml",
    ] {
        assert!(out.join(file).is_file(), "{file} missing:\n{stdout}");
    }
    for dir in [&scans, &out] {
        let _ = std::fs::remove_dir_all(dir);
    }
}

#[test]
fn a_broken_bag_fails_naming_it_and_writes_nothing() {
    let dir = temp_dir("broken");
    std::fs::create_dir_all(&dir).expect("temp folder");
    let bag = dir.join("cut.mcap");
    // The MCAP magic and then nothing: a recording cut short.
    std::fs::write(&bag, b"\x89MCAP0\r\n\x01\x10\x00\x00").expect("write");
    slam_fails_leaving_nothing(&[bag.as_os_str()], &dir.join("out"), &["cut.mcap"]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `slam ARGS --out OUT` fails (status 1) naming each of `names` on stderr, and leaves no OUT.
fn slam_fails_leaving_nothing(args: &[&std::ffi::OsStr], out: &Path, names: &[&str]) {
    let run = Command::new(example("slam"))
        .args(args)
        .arg("--out")
        .arg(out)
        .output()
        .expect("slam runs");
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(
        names.iter().all(|n| stderr.contains(n)),
        "{names:?}: {stderr}"
    );
    assert!(!out.exists(), "a failed run left {}", out.display());
}

/// A real HDL-32E scan seen from 8 known poses 0.25 m apart along x, turning 1 degree a step:
/// the folder of scans (named by their stamps) and the poses (`world_T_lidar`, body = LiDAR).
fn moving_folder(name: &str) -> (PathBuf, Vec<(f64, slam_core::Pose3)>) {
    use nalgebra::{Translation3, UnitQuaternion};
    let scans = temp_dir(name);
    std::fs::create_dir_all(&scans).expect("temp folder");
    let world = slam_core::io::read_pcd(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../slam-core/tests/data/hdl32e_garage_1503604882.703390000.pcd"),
    )
    .expect("the bundled scan");
    let poses: Vec<(f64, slam_core::Pose3)> = (0..8)
        .map(|i| {
            let k = f64::from(i);
            let pose = slam_core::Pose3::from_parts(
                Translation3::new(0.25 * k, 0.0, 0.0),
                UnitQuaternion::from_euler_angles(0.0, 0.0, k.to_radians()),
            );
            (100.0 + 0.1 * k, pose)
        })
        .collect();
    for (stamp, pose) in &poses {
        let scan = world.transformed(&pose.inverse());
        slam_core::io::write_pcd(
            scans.join(format!("{stamp:.1}.pcd")),
            &scan,
            slam_core::io::PcdEncoding::Binary,
        )
        .expect("write a scan");
    }
    (scans, poses)
}

/// The number after `key` in `line`, e.g. `number_after("ATE 0.006 m", "ATE ")`.
fn number_after(line: &str, key: &str) -> f64 {
    let rest = &line[line.find(key).unwrap_or_else(|| panic!("{key} in {line}")) + key.len()..];
    let token: String = rest
        .trim_start()
        .chars()
        .take_while(|c| c.is_ascii_digit() || matches!(c, '.' | '-' | '+'))
        .collect();
    token
        .parse()
        .unwrap_or_else(|_| panic!("a number after {key} in {line}"))
}

/// The line of `stdout` that starts with `label`.
fn line<'a>(stdout: &'a str, label: &str) -> &'a str {
    stdout
        .lines()
        .find(|l| l.starts_with(label))
        .unwrap_or_else(|| panic!("no {label} line in:\n{stdout}"))
}

/// `slam RECORDING --ground-truth TRUTH OPTION PATH` succeeds; its stdout.
fn slam_succeeds(recording: &Path, truth: &Path, option: &str, path: &Path) -> String {
    let run = Command::new(example("slam"))
        .arg(recording)
        .arg("--ground-truth")
        .arg(truth)
        .arg(option)
        .arg(path)
        .output()
        .expect("slam runs");
    let stdout = String::from_utf8_lossy(&run.stdout).into_owned();
    assert!(
        run.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    stdout
}

/// `slam SCANS --ground-truth TRUTH --out OUT EXTRA...` succeeds; OUT (a fresh temporary
/// folder named `name`).
fn slam_writes(scans: &Path, truth: &Path, extra: &[&str], name: &str) -> PathBuf {
    let out = temp_dir(name);
    let run = Command::new(example("slam"))
        .arg(scans)
        .arg("--ground-truth")
        .arg(truth)
        .arg("--out")
        .arg(&out)
        .args(extra)
        .output()
        .expect("slam runs");
    assert!(
        run.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr)
    );
    out
}

/// The summary.json at `path`.
fn summary_json(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).expect("summary.json written");
    serde_json::from_str(&text).expect("summary.json is JSON")
}

/// `poses` written as a TUM file and as KITTI poses beside `scans`.
fn truth_files(scans: &Path, poses: &[(f64, slam_core::Pose3)]) -> (PathBuf, PathBuf) {
    let tum = scans.with_extension("tum");
    let kitti = scans.with_extension("kitti.txt");
    let mut tum_text = String::from("# stamp tx ty tz qx qy qz qw\n");
    let mut kitti_text = String::new();
    for (stamp, pose) in poses {
        let t = pose.translation.vector;
        let q = pose.rotation;
        writeln!(
            tum_text,
            "{stamp} {} {} {} {} {} {} {}",
            t.x, t.y, t.z, q.i, q.j, q.k, q.w
        )
        .expect("a string");
        let r = pose.rotation.to_rotation_matrix();
        let m = r.matrix();
        for row in 0..3 {
            write!(
                kitti_text,
                "{} {} {} {} ",
                m[(row, 0)],
                m[(row, 1)],
                m[(row, 2)],
                t[row]
            )
            .expect("a string");
        }
        kitti_text += "\n";
    }
    std::fs::write(&tum, tum_text).expect("write the TUM file");
    std::fs::write(&kitti, kitti_text).expect("write the KITTI file");
    (tum, kitti)
}

/// The run's `summary.json` holds what it printed on `stdout`.
fn check_summary(stdout: &str, json: &serde_json::Value, truth: &Path) {
    let scans_line = line(stdout, "scans ");
    assert_eq!(json["scans"], 8, "{stdout}");
    assert_eq!(number_after(scans_line, "scans"), 8.0);
    assert_eq!(
        json["keyframes"].as_f64(),
        Some(number_after(scans_line, "("))
    );
    let loops = line(stdout, "loops ");
    assert_eq!(
        json["loops"]["closed"].as_f64(),
        Some(number_after(loops, "loops"))
    );
    assert_eq!(
        json["loops"]["tried"].as_f64(),
        Some(number_after(loops, "closed of "))
    );
    let tracking = line(stdout, "tracking ");
    let fallbacks = json["tracking"]["fallbacks"].as_f64().expect("a count");
    assert_eq!(fallbacks, number_after(tracking, "tracking"));
    assert_eq!(json["tracking"]["lost"], false);
    assert_eq!(json["input"]["odometry"], "LiDAR-only");
    assert!(
        json["input"]["ground_truth"]
            .as_str()
            .is_some_and(|g| g.contains(&*truth.to_string_lossy())),
        "{json}"
    );
    let time = line(stdout, "time ");
    let mean = json["time"]["scan_ms_mean"].as_f64().expect("a time");
    assert!((mean - number_after(time, "time")).abs() <= 0.005 + 1e-9);
    let accuracy = line(stdout, "accuracy ");
    let a = &json["accuracy"];
    let ate = a["ate_m"].as_f64().expect("an ATE");
    assert!((ate - number_after(accuracy, "ATE ")).abs() <= 0.0005 + 1e-12);
    let height = a["height_drift_m"].as_f64().expect("a height drift");
    assert!((height - number_after(accuracy, "height drift ")).abs() <= 0.0005 + 1e-12);
    assert_eq!(a["ate_pairs"], 8);
    // The oracle: the truth's path is 7 steps of 0.25 m; a real scan seen from known poses is
    // tracked to a few millimetres.
    let path = a["path_length_m"].as_f64().expect("a path");
    assert!((path - 1.75).abs() < 1e-9, "{path}");
    assert!(ate < 0.01 && height.abs() < 0.01, "{stdout}");
    assert_eq!(a["steps"], 7);
    assert_eq!(a["steps_over_2_deg"], 0);
    // 1.75 m is short of KITTI's 100 m: its ladder a hundredfold smaller, 1 m segments.
    assert_eq!(a["rpe_kitti_lengths"], false);
    assert_eq!(a["rpe_segment_lengths_m"][0].as_f64(), Some(1.0));
    assert!(line(stdout, "rpe ").contains("shorter than KITTI's 100 m"));
}

#[test]
fn a_ground_truth_file_is_evaluated_and_the_summary_says_what_was_printed() {
    let (scans, poses) = moving_folder("moving");
    let (tum, kitti) = truth_files(&scans, &poses);
    let mut accuracies = Vec::new();
    for truth in [&tum, &kitti] {
        let out = temp_dir("moving-out");
        let stdout = slam_succeeds(&scans, truth, "--out", &out);
        let json = summary_json(&out.join("summary.json"));
        check_summary(&stdout, &json, truth);
        accuracies.push(json["accuracy"].clone());
    }
    // TUM and KITTI poses of the same truth give the same figures (KITTI's stamps are the
    // scans').
    let (a, b) = (&accuracies[0], &accuracies[1]);
    for key in [
        "ate_m",
        "path_length_m",
        "end_point_error_m",
        "height_drift_m",
    ] {
        let (x, y) = (
            a[key].as_f64().expect("tum"),
            b[key].as_f64().expect("kitti"),
        );
        assert!((x - y).abs() < 1e-6, "{key}: {x} and {y}");
    }
    // Tidy up (temp_dir empties the last run's output folder).
    temp_dir("moving-out");
    let _ = std::fs::remove_dir_all(&scans);
    let _ = std::fs::remove_file(&tum);
    let _ = std::fs::remove_file(&kitti);
}

#[test]
fn a_bad_ground_truth_fails_naming_its_file_and_line() {
    let (scans, poses) = moving_folder("bad-truth");
    let dir = temp_dir("bad-truth-files");
    std::fs::create_dir_all(&dir).expect("temp folder");
    let short = dir.join("short.txt");
    std::fs::write(&short, "1 0 0 0 0 1 0 0 0 0 1 0\n").expect("write");
    let broken = dir.join("broken.tum");
    std::fs::write(
        &broken,
        format!(
            "{} 0 0 0 0 0 0 1\n{} 0 0 x 0 0 0 1\n",
            poses[0].0, poses[1].0
        ),
    )
    .expect("write");
    for (file, expect) in [(&short, "1 KITTI poses for 8 scans"), (&broken, "line 2")] {
        let args = [
            scans.as_os_str(),
            "--ground-truth".as_ref(),
            file.as_os_str(),
        ];
        slam_fails_leaving_nothing(&args, &dir.join("out"), &[&file.to_string_lossy(), expect]);
    }
    for path in [&scans, &dir] {
        let _ = std::fs::remove_dir_all(path);
    }
}

#[test]
fn a_ground_truth_file_replaces_the_recordings_own_and_says_so() {
    // A KITTI sequence of 4 copies of a real scan, with its own poses.txt (the identity) and no
    // times.txt (10 Hz from 0); the file given replaces it.
    let dir = temp_dir("kitti");
    std::fs::create_dir_all(dir.join("velodyne")).expect("temp folder");
    let scan = slam_core::io::read_pcd(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../slam-core/tests/data/hdl32e_garage_1503604882.703390000.pcd"),
    )
    .expect("the bundled scan");
    let mut own = String::new();
    let mut given = String::new();
    for i in 0..4 {
        slam_core::io::write_kitti_bin(dir.join(format!("velodyne/{i:06}.bin")), &scan)
            .expect("write a scan");
        own += "1 0 0 0 0 1 0 0 0 0 1 0\n";
        writeln!(given, "{} 0 0 0 0 0 0 1", 0.1 * f64::from(i)).expect("a string");
    }
    std::fs::write(dir.join("poses.txt"), own).expect("write poses.txt");
    let truth = dir.with_extension("tum");
    std::fs::write(&truth, given).expect("write the ground truth");
    let summary = dir.with_extension("json");
    let stdout = slam_succeeds(&dir, &truth, "--summary", &summary);
    assert!(
        line(&stdout, "truth ").contains("replacing the recording's own ground truth"),
        "{stdout}"
    );
    let json = summary_json(&summary);
    assert!(
        json["input"]["ground_truth"]
            .as_str()
            .is_some_and(|g| g.contains("replacing")),
        "{json}"
    );
    assert_eq!(json["accuracy"]["ate_pairs"], 4);
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_file(&truth);
    let _ = std::fs::remove_file(&summary);
}

/// `--keyframes-in-memory 2` keeps the older keyframes of an 8-scan walk in a file: the same
/// trajectory and map, byte for byte, as with every keyframe in memory, and the file gone
/// afterwards.
#[test]
fn keyframes_kept_in_a_file_give_the_same_map() {
    let (scans, poses) = moving_folder("stored");
    let (tum, kitti) = truth_files(&scans, &poses);
    let stores = || {
        std::fs::read_dir(std::env::temp_dir()).map_or(0, |d| {
            d.filter_map(Result::ok)
                .filter(|e| {
                    e.file_name()
                        .to_string_lossy()
                        .starts_with("spot-nav-keyframes-")
                })
                .count()
        })
    };
    let before = stores();
    let mut outputs = Vec::new();
    for store in [None, Some("2")] {
        let extra: &[&str] = match store {
            Some(n) => &["--keyframes-in-memory", n],
            None => &[],
        };
        let out = slam_writes(
            &scans,
            &tum,
            extra,
            if store.is_some() {
                "stored-out"
            } else {
                "held-out"
            },
        );
        let read = |name: &str| std::fs::read(out.join(name)).expect(name);
        outputs.push((read("trajectory.tum"), read("map.ply"), read("graph.g2o")));
        let _ = std::fs::remove_dir_all(&out);
    }
    assert!(outputs[0] == outputs[1], "the stored run's outputs differ");
    assert_eq!(stores(), before, "the store's file was left behind");
    let _ = std::fs::remove_dir_all(&scans);
    let _ = std::fs::remove_file(&tum);
    let _ = std::fs::remove_file(&kitti);
}

/// `--tracker-map-voxel 0.1` keeps the tracker's local map at 0.1 m instead of the sparse
/// scans' 0.15 m: the
/// summary says so and the walk's trajectory differs from the default's; a voxel the tracker
/// refuses is named by its setting, and the option is refused with LOAM, each before anything
/// is written.
#[test]
fn the_trackers_map_voxel_is_set_or_refused_by_name() {
    let (scans, poses) = moving_folder("map-voxel");
    let (tum, kitti) = truth_files(&scans, &poses);
    let mut runs = Vec::new();
    for voxel in [None, Some("0.1")] {
        let extra: &[&str] = match voxel {
            Some(v) => &["--tracker-map-voxel", v],
            None => &[],
        };
        let out = slam_writes(
            &scans,
            &tum,
            extra,
            if voxel.is_some() {
                "fine-out"
            } else {
                "coarse-out"
            },
        );
        let json = summary_json(&out.join("summary.json"));
        let trajectory = std::fs::read(out.join("trajectory.tum")).expect("trajectory.tum");
        runs.push((json["tracker_map_voxel"].as_f64(), trajectory));
        let _ = std::fs::remove_dir_all(&out);
    }
    let near = |v: Option<f64>, want: f64| v.is_some_and(|v| (v - want).abs() < 1e-6);
    // The bundled HDL-32E scan holds 42,006 points: a sparse scan's map voxel by default.
    assert!(near(runs[0].0, 0.15), "{:?}", runs[0].0);
    assert!(near(runs[1].0, 0.1), "{:?}", runs[1].0);
    assert!(runs[0].1 != runs[1].1, "the finer map changed nothing");
    let out = temp_dir("refused-out");
    slam_fails_leaving_nothing(
        &[scans.as_os_str(), "--tracker-map-voxel=-1".as_ref()],
        &out,
        &["--tracker-map-voxel -1", "IcpConfig::target_voxel"],
    );
    slam_fails_leaving_nothing(
        &[
            scans.as_os_str(),
            "--registration".as_ref(),
            "loam".as_ref(),
            "--tracker-map-voxel".as_ref(),
            "0.1".as_ref(),
        ],
        &out,
        &["--tracker-map-voxel", "point-to-plane"],
    );
    let _ = std::fs::remove_dir_all(&scans);
    let _ = std::fs::remove_file(&tum);
    let _ = std::fs::remove_file(&kitti);
}
