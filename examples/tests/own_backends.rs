//! The `own_backends` example: a registrator, an optimizer and a planner written outside the
//! library map a simulated building and walk Spot to its farthest room. The run is checked
//! against the simulator's ground truth: the mapping's ATE, every backend called, the own
//! planner's path followed to the goal; the settings of the bundled TOML file (an `IcpConfig`
//! and a `NavigatorConfig`, each different from its default) in the backends built.

#![allow(clippy::expect_used, clippy::panic)]

use std::process::Command;

use spot_adapter::prelude::{IcpConfig, IcpKernel, NavigatorConfig};

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
    // The file's settings, read back from the backends, and not the defaults.
    let settings = line(&stdout, "settings");
    assert!(settings.contains("own_backends.toml"), "{settings}");
    assert!(settings.contains("kernel Tukey { k: 0.1 }"), "{settings}");
    assert!(settings.contains("replans every 20 cycles"), "{settings}");
    assert!(!matches!(
        IcpConfig::default().kernel,
        IcpKernel::Tukey { .. }
    ));
    assert_ne!(NavigatorConfig::default().replan_every, 20);
}

#[test]
fn own_backends_names_the_file_and_the_field_of_a_bad_setting() {
    let dir = std::env::temp_dir().join(format!("own_backends_settings_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let path = dir.join("bad.toml");
    std::fs::write(&path, "[navigator]\nreplan_evry = 20\n").expect("the file is written");
    let run = Command::new(example("own_backends"))
        .arg("--config")
        .arg(&path)
        .output()
        .expect("own_backends runs");
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(
        stderr.contains("bad.toml") && stderr.contains("replan_evry"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
