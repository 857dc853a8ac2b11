//! `--print-config` and `--config FILE` of the examples that have settings (`slam`, `mission`,
//! `register`): the printed defaults are TOML that reads back to the same settings; a field
//! changed in a file takes effect (in the printed settings, and in a run of `register` and
//! `slam`), an option given on the command line wins over the file; a
//! misspelt field or a value of the wrong type fails naming the file and the field.
#![allow(clippy::expect_used, clippy::panic)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod common;
use common::example;

/// Runs example `name` with `args`.
fn run(name: &str, args: &[&str]) -> Output {
    Command::new(example(name))
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("{name} runs: {e}"))
}

/// The stdout of a run that must succeed.
fn stdout_of(name: &str, args: &[&str]) -> String {
    let out = run(name, args);
    assert!(
        out.status.success(),
        "{name} {args:?}: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8")
}

/// A fresh folder for one test's files.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("spot_nav_settings_{test}_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    dir
}

/// Writes `text` to `dir/name` and gives its path as a string.
fn write(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).expect("the file is written");
    path.to_str().expect("a UTF-8 path").to_owned()
}

/// The value at the dotted `key` of TOML `text`.
fn value(text: &str, key: &str) -> toml::Value {
    let table: toml::Table = toml::from_str(text).expect("--print-config prints TOML");
    let mut v = toml::Value::Table(table);
    for part in key.split('.') {
        v = v
            .get(part)
            .unwrap_or_else(|| panic!("{key} in {text}"))
            .clone();
    }
    v
}

/// `--print-config` prints TOML that `--config` reads back to the same settings.
fn round_trip(name: &str, tables: &[&str]) {
    let dir = scratch(&format!("{name}_round_trip"));
    let defaults = stdout_of(name, &["--print-config"]);
    for table in tables {
        assert!(
            defaults.contains(&format!("[{table}]")),
            "{name}: no [{table}] in {defaults}"
        );
    }
    let path = write(&dir, "defaults.toml", &defaults);
    let again = stdout_of(name, &["--config", &path, "--print-config"]);
    assert_eq!(
        again, defaults,
        "{name}: the printed defaults read back differently"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A misspelt field and a value of the wrong type fail, naming the file and the field.
fn bad_fields(name: &str, misspelt: &str, field: &str, wrong_type: &str) {
    let dir = scratch(&format!("{name}_bad"));
    for (file, text, wanted) in [
        ("misspelt.toml", misspelt, field),
        ("type.toml", wrong_type, ""),
    ] {
        let path = write(&dir, file, text);
        let out = run(name, &["--config", &path, "--print-config"]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{name} {file}: {stderr}");
        assert!(
            stderr.contains(file),
            "{name}: the file is not named: {stderr}"
        );
        let key = if wanted.is_empty() {
            text.lines()
                .find_map(|l| l.split_once(" = ").map(|(k, _)| k.trim()))
                .expect("a key")
        } else {
            wanted
        };
        assert!(
            stderr.contains(key),
            "{name}: `{key}` is not named: {stderr}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn register_settings_round_trip_take_effect_and_yield_to_options() {
    round_trip("register", &["icp", "loam"]);
    let dir = scratch("register_effect");
    // A file that leaves ICP one iteration a stage: the bundled pair (converged in 11 with the
    // defaults) stops at the cap, status 1 after printing the result.
    assert!(stdout_of("register", &[]).contains("(converged)"));
    let path = write(&dir, "one.toml", "[icp]\nmax_iterations = 1\n");
    let out = run("register", &["--config", &path]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    assert!(stdout.contains("(iteration cap)"), "{stdout}");
    // Fields the file leaves out keep the example's defaults (LOAM's wide first threshold, the
    // pair's HDL-32E layout); `--voxel` wins over the file's voxels.
    let path = write(
        &dir,
        "voxel.toml",
        "[icp]\nsource_voxel = 0.3\ntarget_voxel = 0.3\n",
    );
    let printed = stdout_of("register", &["--config", &path, "--print-config"]);
    assert_eq!(value(&printed, "icp.source_voxel").as_float(), Some(0.3));
    assert_eq!(
        value(&printed, "loam.initial_tukey_threshold").as_float(),
        Some(1.0)
    );
    assert_eq!(
        value(&printed, "loam.features.layout.rings").as_integer(),
        Some(32)
    );
    let printed = stdout_of(
        "register",
        &["--config", &path, "--voxel", "0.5", "--print-config"],
    );
    assert_eq!(value(&printed, "icp.source_voxel").as_float(), Some(0.5));
    assert_eq!(value(&printed, "icp.target_voxel").as_float(), Some(0.5));
    std::fs::remove_dir_all(&dir).ok();
    bad_fields(
        "register",
        "[icp]\nmax_iteration = 10\n",
        "max_iteration",
        "[icp]\nmax_iterations = \"ten\"\n",
    );
}

#[test]
fn slam_settings_round_trip_take_effect_and_yield_to_options() {
    round_trip("slam", &["slam", "slam.tracker"]);
    let dir = scratch("slam_effect");
    // A nested table in part: the other tracker fields keep the example's defaults.
    let defaults = stdout_of("slam", &["--print-config"]);
    let path = write(
        &dir,
        "slam.toml",
        "[slam]\nkeyframe_distance = 0.5\nloop_max_drift_rate = 0.05\n\
         loop_kernel = { kind = \"None\" }\n\
         odometry_information = { kind = \"FromRegistration\", scale = 0.5 }\n",
    );
    let printed = stdout_of("slam", &["--config", &path, "--print-config"]);
    assert_eq!(
        value(&printed, "slam.keyframe_distance").as_float(),
        Some(0.5)
    );
    assert_eq!(
        value(&printed, "slam.loop_max_drift_rate").as_float(),
        Some(0.05)
    );
    assert_eq!(
        value(&printed, "slam.loop_kernel.kind").as_str(),
        Some("None")
    );
    assert_eq!(
        value(&printed, "slam.odometry_information.scale").as_float(),
        Some(0.5)
    );
    assert_eq!(
        value(&printed, "slam.tracker"),
        value(&defaults, "slam.tracker")
    );
    // Options given win over the file.
    let printed = stdout_of(
        "slam",
        &[
            "--config",
            &path,
            "--loop-drift-rate",
            "0.03",
            "--no-deskew",
            "--print-config",
        ],
    );
    assert_eq!(
        value(&printed, "slam.loop_max_drift_rate").as_float(),
        Some(0.03)
    );
    assert_eq!(value(&printed, "slam.deskew").as_bool(), Some(false));
    assert_eq!(
        value(&printed, "slam.keyframe_distance").as_float(),
        Some(0.5)
    );
    // A run with a file that asks more points of a scan than the simulated LiDAR gives: every
    // scan is skipped, and the example fails saying so (about 3 s of simulation).
    let path = write(&dir, "skip.toml", "[slam]\nmin_scan_points = 100000000\n");
    let out = run("slam", &["--config", &path]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("accepted none of the"), "{stderr}");
    std::fs::remove_dir_all(&dir).ok();
    bad_fields(
        "slam",
        "[slam.tracker]\nmin_inlier_rati = 0.5\n",
        "min_inlier_rati",
        "[slam]\nkeyframe_distance = \"far\"\n",
    );
}

#[test]
fn mission_settings_round_trip_take_effect_and_yield_to_options() {
    round_trip(
        "mission",
        &["slam", "navigator", "navigator.grid", "explorer", "lidar"],
    );
    let dir = scratch("mission_effect");
    let path = write(
        &dir,
        "nav.toml",
        "[navigator]\nspeed = 0.5\nplanner = \"JumpPointSearch\"\n[navigator.live]\nwindow = 6.0\n",
    );
    let defaults = stdout_of("mission", &["--print-config"]);
    let printed = stdout_of("mission", &["--config", &path, "--print-config"]);
    assert_eq!(value(&printed, "navigator.speed").as_float(), Some(0.5));
    assert_eq!(
        value(&printed, "navigator.planner").as_str(),
        Some("JumpPointSearch")
    );
    // The navigator's own live-layer decay, not the live layer's default, stays.
    assert_eq!(
        value(&printed, "navigator.live.decay"),
        value(&defaults, "navigator.live.decay")
    );
    assert_eq!(
        value(&printed, "navigator.live.window").as_float(),
        Some(6.0)
    );
    let printed = stdout_of(
        "mission",
        &["--config", &path, "--planner", "astar", "--print-config"],
    );
    assert_eq!(value(&printed, "navigator.planner").as_str(), Some("AStar"));
    // The frontier rule: `--frontier` wins over the file, and keeps the file's margin when it
    // names the same rule.
    let path = write(
        &dir,
        "explorer.toml",
        "[explorer]\nchoice = { kind = \"Tour\", keep_margin = 3.0 }\n",
    );
    let printed = stdout_of("mission", &["--config", &path, "--print-config"]);
    assert_eq!(
        value(&printed, "explorer.choice.keep_margin").as_float(),
        Some(3.0)
    );
    let printed = stdout_of(
        "mission",
        &["--config", &path, "--frontier", "tour", "--print-config"],
    );
    assert_eq!(
        value(&printed, "explorer.choice.keep_margin").as_float(),
        Some(3.0)
    );
    let printed = stdout_of(
        "mission",
        &["--config", &path, "--frontier", "greedy", "--print-config"],
    );
    assert_eq!(
        value(&printed, "explorer.choice.kind").as_str(),
        Some("GreedyNearestFrontier")
    );
    std::fs::remove_dir_all(&dir).ok();
    bad_fields(
        "mission",
        "[navigator]\nsped = 0.5\n",
        "sped",
        "[navigator]\nplanner = 3\n",
    );
}

/// YAML beside TOML, for the three examples: the defaults printed as YAML read back to the same
/// settings as the TOML defaults; a YAML file changes what the same TOML file changes (the TOML
/// reading is the oracle); a misspelt field fails naming the file and the field.
#[test]
fn yaml_settings_read_as_the_same_toml_settings() {
    let dir = scratch("yaml");
    for name in ["slam", "mission", "register"] {
        let toml_defaults = stdout_of(name, &["--print-config"]);
        let yaml_defaults = stdout_of(name, &["--print-config", "yaml"]);
        assert_ne!(yaml_defaults, toml_defaults, "{name}: YAML is printed");
        let path = write(&dir, &format!("{name}.yaml"), &yaml_defaults);
        assert_eq!(
            stdout_of(name, &["--config", &path, "--print-config"]),
            toml_defaults,
            "{name}: the YAML defaults read back differently"
        );
    }
    for (name, toml_text, yaml_text) in [
        (
            "slam",
            "[slam]\nkeyframe_distance = 0.5\nloop_kernel = { kind = \"Huber\", delta = 0.5 }\n\
             [slam.tracker.reach]\nmax = 4.0\n",
            "slam:\n  keyframe_distance: 0.5\n  loop_kernel:\n    kind: Huber\n    delta: 0.5\n  \
             tracker:\n    reach:\n      max: 4.0\n",
        ),
        (
            "register",
            "[icp]\nmax_iterations = 7\nsource_voxel = 0.3\n",
            "icp:\n  max_iterations: 7\n  source_voxel: 0.3\n",
        ),
    ] {
        let toml_path = write(&dir, &format!("{name}-part.toml"), toml_text);
        let yaml_path = write(&dir, &format!("{name}-part.yml"), yaml_text);
        let from_toml = stdout_of(name, &["--config", &toml_path, "--print-config"]);
        assert_ne!(from_toml, stdout_of(name, &["--print-config"]), "{name}");
        assert_eq!(
            stdout_of(name, &["--config", &yaml_path, "--print-config"]),
            from_toml,
            "{name}: YAML and TOML differ"
        );
    }
    let path = write(&dir, "misspelt.yaml", "slam:\n  keyframe_distanc: 1.0\n");
    let out = run("slam", &["--config", &path, "--print-config"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("misspelt.yaml") && stderr.contains("keyframe_distanc"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
