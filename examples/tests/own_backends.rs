//! The `own_backends` example: a registrator, an optimizer and a planner written outside the
//! library map a simulated building and walk Spot to its farthest room. The run is checked
//! against the simulator's ground truth: the mapping's ATE, every backend called, the own
//! planner's path followed to the goal.

#![allow(clippy::expect_used, clippy::panic)]

use std::process::Command;

mod common;
use common::example;

/// The number after `label` in `line`, e.g. `ATE 0.012 m`.
fn number_after(line: &str, label: &str) -> f64 {
    let rest = &line[line
        .find(label)
        .unwrap_or_else(|| panic!("{label} in {line}"))
        + label.len()..];
    rest.split_whitespace()
        .next()
        .and_then(|n| n.trim_end_matches([',', ';']).parse().ok())
        .unwrap_or_else(|| panic!("a number after {label} in {line}"))
}

/// The line of `stdout` that starts with `key`.
fn line<'a>(stdout: &'a str, key: &str) -> &'a str {
    stdout
        .lines()
        .find(|l| l.starts_with(key))
        .unwrap_or_else(|| panic!("a {key} line in {stdout}"))
}

#[test]
fn own_backends_map_the_building_and_the_own_planner_walks_spot_to_the_goal() {
    let run = Command::new(example("own_backends"))
        .args(["--seed", "3"])
        .output()
        .expect("own_backends runs");
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    // Mapping: within 5 cm of the ground truth (the pipelines' point-to-plane lap: 1-2 cm).
    let mapping = line(&stdout, "mapping");
    let ate = number_after(mapping, "ATE");
    assert!(ate < 0.05, "{mapping}");
    // Every own backend was called.
    let backends = line(&stdout, "backends");
    assert!(number_after(backends, "registrator") > 0.0, "{backends}");
    assert!(number_after(backends, "optimizer") > 0.0, "{backends}");
    // The navigator planned with the own planner, found a path and followed it to the goal.
    let navigation = line(&stdout, "navigation");
    assert!(navigation.contains("Arrived"), "{navigation}");
    assert!(number_after(navigation, "answered") > 0.0, "{navigation}");
    assert!(number_after(navigation, "queries,") > 0.0, "{navigation}");
    let error = number_after(navigation, "cycles,");
    assert!(error <= 0.10, "{navigation}");
}
