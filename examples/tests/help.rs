//! The examples' command lines, run as the built binaries: `--help` exits 0 and names every
//! option; a malformed value exits non-zero naming its option; a failed job exits 1 with one line
//! on stderr; a closed stdout ends a run quietly with status 0.
//!
//! `cargo test` builds the examples before it runs integration tests, into
//! `target/<profile>/examples/`, beside the `deps` folder this test runs from.
#![allow(clippy::expect_used, clippy::panic)]

use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

mod common;
use common::example;

/// Every example with the options its `--help` must name.
const EXAMPLES: [(&str, &[&str]); 9] = [
    (
        "g2o",
        &[
            "FILE",
            "--optimizer",
            "--init",
            "--error",
            "--robust",
            "--out",
            "--repair-information",
            "gn",
            "lm",
            "chordal",
            "logmap",
            "gnc",
        ],
    ),
    (
        "gridmap",
        &[
            "MAP_CLOUD",
            "--lidar-height",
            "--resolution",
            "--inflate",
            "--out",
        ],
    ),
    (
        "mission",
        &[
            "--seed",
            "--goals",
            "--goal",
            "--obstacles",
            "--kidnap",
            "--lap",
            "--frontier",
            "--max-scans",
            "--min-coverage",
            "--start",
            "--building",
            "--registration",
            "--planner",
            "--out",
            "--config",
            "--print-config",
            "information-gain",
            "greedy",
            "tour",
            "corridor",
            "anywhere",
            "office",
            "small",
            "p2plane",
            "loam",
            "cost-aware",
            "jps",
            "astar",
        ],
    ),
    ("movingai", &["MAP", "SCEN", "--planner", "jps-plus", "all"]),
    ("own_backends", &["--seed", "--max-ate", "--config"]),
    (
        "register",
        &[
            "SOURCE",
            "TARGET",
            "--method",
            "--voxel",
            "--init",
            "--layout",
            "--reference",
            "--repeat",
            "--config",
            "--print-config",
            "os1-128",
        ],
    ),
    ("scan_stats", &["FILE"]),
    (
        "simulate",
        &[
            "--seed",
            "--sensor",
            "--motion",
            "--skewed",
            "--out",
            "--cloud-folder",
            "--cloud-format",
            "vlp16",
            "os1-128",
            "walk",
            "fast-turns",
            "handheld",
        ],
    ),
    (
        "slam",
        &[
            "PATH",
            "--cloud-topic",
            "--odom-topic",
            "--odom-frame",
            "--base-frame",
            "--lidar-frame",
            "--seed",
            "--registration",
            "--skewed",
            "--sensor",
            "--motion",
            "os1-128",
            "handheld",
            "--no-deskew",
            "--no-odometry",
            "--blank-corridor",
            "--lidar-range",
            "--gyro-drift",
            "--odometry-information",
            "--loop-drift-rate",
            "--out",
            "--ground-truth",
            "--summary",
            "--config",
            "--print-config",
        ],
    ),
];

/// A path from the workspace root.
fn bundled(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative)
}

fn run(name: &str, args: &[&str]) -> Output {
    Command::new(example(name))
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("running {name}: {e}"))
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[test]
fn help_exits_zero_and_names_every_option() {
    for (name, options) in EXAMPLES {
        for flag in ["--help", "-h"] {
            let out = run(name, &[flag]);
            let help = text(&out.stdout);
            assert!(out.status.success(), "{name} {flag}: {:?}", out.status);
            assert!(help.contains("Usage:"), "{name} {flag}:\n{help}");
            assert!(
                help.contains(name),
                "{name} {flag} does not name itself:\n{help}"
            );
            for option in options
                .iter()
                .filter(|o| flag == "--help" || o.starts_with("--"))
            {
                assert!(
                    help.contains(option),
                    "{name} {flag} does not mention {option}:\n{help}"
                );
            }
        }
    }
}

/// `name args` fails as a command-line error (status 2, before any work) naming `option`.
fn rejected(name: &str, args: &[&str], option: &str) {
    let out = run(name, args);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{name} {args:?}: {stderr}");
    assert!(
        stderr.contains(option),
        "{name} {args:?} does not name {option}: {stderr}"
    );
    assert!(!stderr.contains("panicked"), "{name} {args:?}: {stderr}");
}

#[test]
fn g2o_rejects_an_unknown_optimizer() {
    // g2o takes no number; its choices are checked the same way.
    rejected(
        "g2o",
        &["graph.g2o", "--optimizer", "newton"],
        "--optimizer",
    );
}

#[test]
fn gridmap_rejects_a_malformed_height() {
    rejected(
        "gridmap",
        &["map.pcd", "--lidar-height", "x", "--out", "dir"],
        "--lidar-height",
    );
    rejected(
        "gridmap",
        &[
            "map.pcd",
            "--lidar-height",
            "0",
            "--resolution",
            "1,5",
            "--out",
            "dir",
        ],
        "--resolution",
    );
}

#[test]
fn mission_rejects_a_malformed_seed_and_goal() {
    rejected("mission", &["--seed", "x"], "--seed");
    rejected("mission", &["--goal", "3"], "--goal");
    rejected("mission", &["--registration", "icp"], "--registration");
    // A goal that is not a finite point is refused before anything is simulated.
    rejected("mission", &["--goal", "nan,nan"], "--goal");
    rejected("mission", &["--kidnap", "0.5"], "--kidnap");
    rejected("mission", &["--goals", "-1"], "--goals");
    rejected("mission", &["--frontier", "nearest"], "--frontier");
    rejected("mission", &["--building", "huge"], "--building");
    rejected("mission", &["--min-coverage", "101"], "--min-coverage");
    // The exploration's options mean nothing on the scripted lap.
    rejected("mission", &["--lap", "--frontier", "greedy"], "--frontier");
    rejected("mission", &["--lap", "--start", "anywhere"], "--start");
}

#[test]
fn movingai_rejects_an_unknown_planner() {
    // movingai takes no number; its planner choice is checked the same way.
    rejected(
        "movingai",
        &["a.map", "a.map.scen", "--planner", "theta"],
        "--planner",
    );
}

#[test]
fn register_rejects_a_malformed_voxel_init_and_repeat() {
    rejected("register", &["--voxel", "x"], "--voxel");
    rejected("register", &["--init", "1,2,3"], "--init");
    rejected("register", &["--repeat", "0"], "--repeat");
    rejected("register", &["--method", "gicp"], "--method");
}

#[test]
fn scan_stats_rejects_an_option() {
    // scan_stats takes only a file: an option is an error naming it.
    rejected("scan_stats", &["--voxel", "0.1"], "--voxel");
}

#[test]
fn simulate_rejects_a_malformed_seed() {
    rejected("simulate", &["--seed", "-1"], "--seed");
}

#[test]
fn simulate_rejects_an_unknown_sensor_motion_or_format() {
    rejected("simulate", &["--sensor", "hdl64"], "--sensor");
    rejected("simulate", &["--motion", "run"], "--motion");
    rejected(
        "simulate",
        &["--cloud-folder", "dir", "--cloud-format", "las"],
        "--cloud-format",
    );
    // A format with no folder to write is a mistake, not a silent no-op.
    rejected("simulate", &["--cloud-format", "pcd"], "--cloud-folder");
}

#[test]
fn slam_rejects_a_malformed_seed() {
    rejected("slam", &["--seed", "1.5"], "--seed");
}

#[test]
fn slam_refuses_simulator_options_with_a_recording() {
    rejected("slam", &["scans", "--blank-corridor"], "--blank-corridor");
    rejected("slam", &["scans", "--lidar-range", "25"], "--lidar-range");
    rejected("slam", &["scans", "--gyro-drift", "0.2"], "--gyro-drift");
    rejected("slam", &["scans", "--skewed"], "--skewed");
    rejected("slam", &["scans", "--sensor", "os1-128"], "--sensor");
    rejected("slam", &["scans", "--motion", "handheld"], "--motion");
    rejected("slam", &["--motion", "jog"], "--motion");
}

#[test]
fn slam_takes_a_ground_truth_file_with_a_recording_only() {
    // The simulator has its own ground truth.
    rejected("slam", &["--ground-truth", "truth.tum"], "<PATH>");
}

/// `slam args` fails as a job (status 1, one line) naming `setting`, before it maps anything.
fn slam_fails_naming(args: &[&str], setting: &str) {
    let out = run("slam", args);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
    assert!(
        stderr.starts_with("error: ") && stderr.contains(setting),
        "{args:?} does not name {setting}: {stderr}"
    );
    assert!(
        out.stdout.is_empty(),
        "{args:?} mapped: {}",
        text(&out.stdout)
    );
}

#[test]
fn slam_refuses_a_bad_lidar_range_or_drift_rate() {
    for range in ["-5", "0", "nan", "inf"] {
        slam_fails_naming(&["--lidar-range", range], "max_range");
    }
    for drift in ["-1", "nan", "inf"] {
        slam_fails_naming(&["--gyro-drift", drift], "--gyro-drift");
    }
    for rate in ["-1", "nan"] {
        slam_fails_naming(&["--loop-drift-rate", rate], "loop_max_drift_rate");
    }
}

#[test]
fn a_failed_job_exits_one_with_one_line() {
    let out = run("scan_stats", &["/nonexistent/scan.pcd"]);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.starts_with("error: reading /nonexistent/scan.pcd"),
        "{stderr}"
    );
}

/// Status and stderr of `name args` when its stdout is a pipe whose reader reads `lines` lines
/// and goes away.
fn closed_after(name: &str, args: &[&str], lines: usize) -> (std::process::ExitStatus, String) {
    let mut child = Command::new(example(name))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("running {name}: {e}"));
    let mut stdout = BufReader::new(child.stdout.take().expect("piped"));
    for _ in 0..lines {
        let mut line = String::new();
        stdout.read_line(&mut line).expect("a line");
        assert!(!line.is_empty(), "{name} ended before {lines} lines");
    }
    drop(stdout);
    let mut stderr = String::new();
    child
        .stderr
        .take()
        .expect("piped")
        .read_to_string(&mut stderr)
        .expect("stderr");
    (child.wait().expect("the example ends"), stderr)
}

#[test]
fn scan_stats_piped_to_head_ends_quietly() {
    let (status, stderr) = closed_after("scan_stats", &[], 1);
    assert!(status.success(), "{status:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn a_stdout_closed_before_any_output_ends_every_quick_example_quietly() {
    let scan = bundled("slam-core/tests/data/hdl32e_garage_1503604882.703390000.pcd");
    let graph = bundled("posegraph/tests/data/tinyGrid3D.g2o");
    let map = bundled("pathfind/tests/data/arena.map");
    let scen = bundled("pathfind/tests/data/arena.map.scen");
    let grid_dir = std::env::temp_dir().join(format!("spot-nav-help-test-{}", std::process::id()));
    let s = |p: &Path| p.to_str().expect("UTF-8 path").to_owned();
    let runs: [(&str, Vec<String>); 5] = [
        ("scan_stats", vec![]),
        ("register", vec![]),
        ("g2o", vec![s(&graph)]),
        ("movingai", vec![s(&map), s(&scen)]),
        (
            "gridmap",
            vec![
                s(&scan),
                "--lidar-height".into(),
                "0".into(),
                "--out".into(),
                s(&grid_dir),
            ],
        ),
    ];
    for (name, args) in runs {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (status, stderr) = closed_after(name, &args, 0);
        assert!(status.success(), "{name}: {status:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{name}: {stderr}");
    }
    let _ = std::fs::remove_dir_all(grid_dir);
}
