//! Every seed (real files cut small, see `make_seeds.py` and `make_bag_seeds.py`) must parse and
//! read back the same (or keep its invariants, for the bag and ROS message targets), and every
//! input a fuzzing run saved under `regressions/<target>/` must run to its end without a panic,
//! on stable Rust: `cargo test --manifest-path fuzz/Cargo.toml`.

use std::path::Path;

use spot_nav_fuzz::{invariants, round_trip};

/// A target's check: true when the input parsed (and passed), a panic when it broke a rule.
type Check = fn(&[u8]) -> bool;

const TARGETS: [(&str, Check); 16] = [
    ("pcd", round_trip::pcd),
    ("ply", round_trip::ply),
    ("kitti_bin", round_trip::kitti_bin),
    ("kitti_poses", round_trip::kitti_poses),
    ("tum", round_trip::tum),
    ("g2o", round_trip::g2o),
    ("toro", round_trip::toro),
    ("movingai_map", round_trip::movingai_map),
    ("movingai_scen", round_trip::movingai_scen),
    ("ros_map", round_trip::ros_map),
    ("recording_index", round_trip::recording_index),
    ("recording_calibration", round_trip::recording_calibration),
    ("ros1_bag", invariants::ros1_bag),
    ("mcap_bag", invariants::mcap_bag),
    ("point_cloud2", invariants::point_cloud2),
    ("ros_message", invariants::ros_message),
];

/// The files of `dir` (none when it does not exist), sorted.
fn files(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut out: Vec<_> = std::fs::read_dir(dir)
        .map(|d| d.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    out.sort();
    out
}

#[test]
fn every_seed_parses_and_reads_back() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (target, round_trip) in TARGETS {
        let seeds = files(&root.join("seeds").join(target));
        assert!(!seeds.is_empty(), "{target} has no seed");
        for seed in seeds {
            let data = std::fs::read(&seed).unwrap();
            assert!(round_trip(&data), "{} does not parse", seed.display());
        }
    }
}

#[test]
fn saved_fuzzing_inputs_run_without_a_panic() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (target, round_trip) in TARGETS {
        for input in files(&root.join("regressions").join(target)) {
            let data = std::fs::read(&input).unwrap();
            // Parsed or refused, both are fine; a panic fails the test.
            let _ = round_trip(&data);
        }
    }
}
