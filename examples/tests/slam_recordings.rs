//! The `slam` example on recordings: a folder of real scans runs LiDAR-only and writes every
//! output; a broken bag fails with the file named and leaves no output folder.

#![allow(clippy::expect_used)]

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
}

#[test]
fn a_broken_bag_fails_naming_it_and_writes_nothing() {
    let dir = temp_dir("broken");
    std::fs::create_dir_all(&dir).expect("temp folder");
    let bag = dir.join("cut.mcap");
    // The MCAP magic and then nothing: a recording cut short.
    std::fs::write(&bag, b"\x89MCAP0\r\n\x01\x10\x00\x00").expect("write");
    let out = dir.join("out");
    let run = Command::new(example("slam"))
        .arg(&bag)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("slam runs");
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("cut.mcap"), "{stderr}");
    assert!(!out.exists(), "a failed run left {}", out.display());
}
