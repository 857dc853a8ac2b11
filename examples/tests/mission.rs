//! The `mission` example run end to end exploring (its default): on the small building of the
//! exploration test (seed 11, `BuildingConfig::small`) with a quarter of the LiDAR's columns,
//! it explores from a random spot to full coverage, then reaches its goals on the map it built;
//! `summary.json` and the picture are written. Bad explorer settings are refused by name before
//! anything is simulated. `--lap` maps the small building in its scripted lap, then reaches its
//! goals (4 s; on the office building, the lap's default, about 30 s).
#![allow(clippy::expect_used, clippy::panic)]

use std::process::{Command, Output};

mod common;
use common::example;

fn run(args: &[&str]) -> Output {
    Command::new(example("mission"))
        .args(args)
        .output()
        .expect("mission runs")
}

/// About 16 s in release on 2 cores (16 s of CPU): the exploration walks 140 m from a room
/// (`--start anywhere`; from seed 11's corridor start it walks farther).
#[test]
fn explores_the_small_building_then_reaches_its_goals() {
    let dir = std::env::temp_dir().join(format!("spot_nav_mission_explore_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let config = dir.join("lidar.toml");
    // A quarter of the VLP-16's columns (0.8°), as the exploration test: rooms of a few metres
    // are seen as well, and the simulator and the engine take a quarter of the time.
    std::fs::write(&config, "[lidar]\ncolumns = 450\n").expect("the settings are written");
    let out_dir = dir.join("out");
    let out = run(&[
        "--building",
        "small",
        "--seed",
        "11",
        "--start",
        "anywhere",
        "--goals",
        "2",
        "--min-coverage",
        "97",
        "--config",
        config.to_str().expect("UTF-8"),
        "--out",
        out_dir.to_str().expect("UTF-8"),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out_dir.join("summary.json")).expect("summary.json"),
    )
    .expect("JSON");
    assert_eq!(summary["mode"], "explore");
    assert!(summary.get("mapping").is_none(), "no lap: {summary}");
    let exploration = &summary["exploration"];
    assert_eq!(exploration["outcome"], "complete", "{exploration}");
    assert!(
        exploration["coverage"].as_f64().expect("coverage") >= 0.97,
        "{exploration}"
    );
    assert_eq!(exploration["collisions"], 0, "{exploration}");
    assert!(
        exploration["ate_m"].as_f64().expect("ATE") < 0.05,
        "{exploration}"
    );
    assert!(exploration["walked_m"].as_f64().expect("walked") > 20.0);
    assert_eq!(summary["reached"], 2, "{summary}");
    assert_eq!(summary["collisions"], 0, "{summary}");
    assert!(out_dir.join("grid.png").is_file());
    std::fs::remove_dir_all(&dir).ok();
}

/// About 4 s in release: a 40 m lap, then two legs.
#[test]
fn the_lap_maps_the_small_building_then_reaches_its_goals() {
    let dir = std::env::temp_dir().join(format!("spot_nav_mission_lap_{}", std::process::id()));
    let out = run(&[
        "--lap",
        "--building",
        "small",
        "--goals",
        "2",
        "--out",
        dir.to_str().expect("UTF-8"),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("summary.json")).expect("summary.json"),
    )
    .expect("JSON");
    assert_eq!(summary["mode"], "lap");
    assert!(
        summary.get("exploration").is_none(),
        "no exploration: {summary}"
    );
    assert!(
        summary["mapping"]["ate_m"].as_f64().expect("ATE") < 0.05,
        "{summary}"
    );
    assert_eq!(summary["reached"], 2, "{summary}");
    assert_eq!(summary["collisions"], 0, "{summary}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_explorer_settings_are_refused_by_name() {
    let dir = std::env::temp_dir().join(format!("spot_nav_mission_bad_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let config = dir.join("bad.toml");
    std::fs::write(&config, "[explorer]\ndecide_every = 0\n").expect("the settings are written");
    let out = run(&["--config", config.to_str().expect("UTF-8")]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("ExplorerConfig::decide_every"), "{stderr}");
    assert!(
        out.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    std::fs::remove_dir_all(&dir).ok();
}
