//! Exploration at flat cost: one autonomous exploration of a simulated building (no map, no
//! route; the engine, the explorer and the navigator as the mission runs them: point-to-plane
//! Graph-SLAM, the default frontier rule, the navigator's defaults, the full VLP-16), measured against
//! the exploration issue's bars:
//! - per-scan SLAM time (`GraphSlam::process`, as the engine's report keeps it) over the last
//!   tenth of the scans against the first tenth, mean and p99 (bar: p99 at most 1.5x);
//! - resident memory at the end against that when the grid first knew a quarter of the floor it
//!   knows free at the end (bar: at most 2x), and the run's peak (the kernel's high-water mark,
//!   `VmHWM`);
//! - the navigation cycle with the explorer's decisions spread over it: the engine and the
//!   navigator on every scan plus every decision, divided by the scans (bar: mean at most
//!   10 ms);
//! - coverage of the reachable floor, collisions and the map's ATE on the ground truth.
//!
//! `cargo bench -p spot-nav-benches --bench exploration` explores the office floor (50 m x
//! 30 m, seed 3, from the corridor loop's first corner; about 2 minutes on 2 cores).
//! `EXPLORATION_BENCH_BUILDING=large` explores the 114 m x 59 m building instead (about 10
//! minutes; `small` the 17 m x 17 m one), `EXPLORATION_BENCH_SEED=N` another building, and
//! `EXPLORATION_BENCH_MAX_SCANS=N` sets the scan budget (12,000; 40,000 for `large`).
//! The engine keeps the newest 200 keyframes' map clouds in memory and older ones in a file
//! under the target folder (`GraphSlam::with_keyframe_store`);
//! `EXPLORATION_BENCH_KEYFRAMES_IN_MEMORY=N` keeps N, 0 every one.

use nalgebra::Vector2;
use slam_core::io::StampedPose;
use spot_adapter::eval::TrajectoryEvaluation;
use spot_adapter::nav::{ExplorationReport, ExplorerConfig, NavigatorConfig, explore};
use spot_adapter::pipelines::{
    PointToPlaneSlam, point_to_plane_slam, point_to_plane_tracker, slam_config,
};
use spot_adapter::sim::{
    Building, BuildingConfig, CommandedSpot, SimulationConfig, floor_coverage,
};
use spot_nav_benches::{peak_resident_mb, quantile, resident_mb};

/// Mean of `v`, 0 when empty.
fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// `(mean, p99)` of the first and of the last tenth of `ms`.
fn tenths(ms: &[f64]) -> [(f64, f64); 2] {
    let tenth = (ms.len() / 10).max(1).min(ms.len());
    let first = &ms[..tenth];
    let last = &ms[ms.len() - tenth..];
    [
        (mean(first), quantile(first, 0.99)),
        (mean(last), quantile(last, 0.99)),
    ]
}

fn env_or<T: std::str::FromStr>(name: &str, default: T) -> Result<T, String> {
    match std::env::var(name) {
        Ok(v) => v
            .parse()
            .map_err(|_| format!("{name}={v:?} is not a valid value")),
        Err(_) => Ok(default),
    }
}

/// The building's name, seed and scan budget, and the simulation, from the environment.
fn settings() -> Result<(String, u64, usize, SimulationConfig), String> {
    let name = env_or("EXPLORATION_BENCH_BUILDING", "office".to_owned())?;
    let (building_config, default_scans) = match name.as_str() {
        "office" => (BuildingConfig::default(), 12_000),
        "large" => (BuildingConfig::large(), 40_000),
        "small" => (BuildingConfig::small(), 3_000),
        other => {
            return Err(format!(
                "EXPLORATION_BENCH_BUILDING={other:?}: office, large or small"
            ));
        }
    };
    let seed: u64 = env_or("EXPLORATION_BENCH_SEED", 3)?;
    let max_scans: usize = env_or("EXPLORATION_BENCH_MAX_SCANS", default_scans)?;
    let config = SimulationConfig {
        building: building_config,
        ..SimulationConfig::with_seed(seed)
    };
    Ok((name, seed, max_scans, config))
}

/// Prints the table of the first and last tenths of the scans (SLAM alone, SLAM with the
/// navigator) and of resident memory: `resident` is (MB, scan) at a quarter of the floor
/// known, MB at the end, then the peak MB over the run.
fn print_table(slam_ms: &[f64], compute_ms: &[f64], resident: (f64, usize, f64, f64)) {
    let [(first_mean, first_p99), (last_mean, last_p99)] = tenths(slam_ms);
    let [
        (nav_first_mean, nav_first_p99),
        (nav_last_mean, nav_last_p99),
    ] = tenths(compute_ms);
    let (at_quarter, quarter, at_end, peak) = resident;
    println!("| measure | first tenth | last tenth | last / first | issue's bar |");
    println!("|---|---|---|---|---|");
    println!(
        "| SLAM ms a scan, mean / p99 | {first_mean:.1} / {first_p99:.1} | {last_mean:.1} / {last_p99:.1} | {:.2} (p99) | p99 at most 1.5x |",
        last_p99 / first_p99
    );
    println!(
        "| SLAM + navigator ms a scan, mean / p99 | {nav_first_mean:.1} / {nav_first_p99:.1} | {nav_last_mean:.1} / {nav_last_p99:.1} | {:.2} (p99) | |",
        nav_last_p99 / nav_first_p99
    );
    println!(
        "| resident MB (at a quarter of the floor known / at the end; peak {peak:.0}) | {at_quarter:.0} (scan {}) | {at_end:.0} | {:.2} | at most 2x |",
        quarter + 1,
        at_end / at_quarter
    );
}

/// Prints the frontiers given up by reason and those left at the end.
fn print_frontiers(report: &ExplorationReport) {
    let mut reasons: Vec<(&str, usize)> = Vec::new();
    for g in &report.given_up {
        match reasons.iter_mut().find(|(r, _)| *r == g.reason.name()) {
            Some((_, n)) => *n += 1,
            None => reasons.push((g.reason.name(), 1)),
        }
    }
    println!(
        "Frontiers given up: {reasons:?}; at the end {} reachable, {} unreachable, {} by given-up goals.",
        report.last_decision.reachable,
        report.last_decision.unreachable.len(),
        report.last_decision.given_up,
    );
}

/// The engine as the mission sets it up, keeping the newest keyframes' map clouds in memory and
/// older ones in a file (`EXPLORATION_BENCH_KEYFRAMES_IN_MEMORY`, 200; 0: every one held).
fn engine() -> Result<PointToPlaneSlam, String> {
    let slam = point_to_plane_slam(slam_config()).map_err(|e| e.to_string())?;
    let in_memory: usize = env_or("EXPLORATION_BENCH_KEYFRAMES_IN_MEMORY", 200)?;
    if in_memory == 0 {
        return Ok(slam);
    }
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"));
    slam.with_keyframe_store(dir, in_memory)
        .map_err(|e| format!("the keyframe store in {}: {e}", dir.display()))
}

/// How many keyframe map clouds the engine holds in memory at the end.
fn print_store(slam: &PointToPlaneSlam) {
    println!(
        "Keyframe map clouds in memory at the end: {} of {} ({} refused by the store's file).",
        slam.keyframe_scans_in_memory(),
        slam.keyframe_count(),
        slam.report().keyframe_store_failures
    );
}

fn run() -> Result<(), String> {
    let (name, seed, max_scans, config) = settings()?;
    let building = Building::generate(seed, &config.building).map_err(|e| e.to_string())?;
    let start = building.corridor_loop()[0];
    let mut spot = CommandedSpot::new(building, start, 0.0, &config).map_err(|e| e.to_string())?;
    // The engine's map frame is the odometry frame, which starts at the body's start pose.
    let world_t_map = spot.body_pose();
    let map_t_world = world_t_map.inverse();
    let mut slam = engine()?;
    let navigator = NavigatorConfig::default();
    let explorer = ExplorerConfig::default();
    let resident_at_start = resident_mb();
    let (mut compute_ms, mut known, mut resident) = (Vec::new(), Vec::new(), Vec::new());
    let mut truth: Vec<StampedPose> = Vec::new();
    let (mut walked, mut last) = (0.0, None::<Vector2<f64>>);
    let started = std::time::Instant::now();
    let report = explore(
        &mut spot,
        &mut slam,
        &point_to_plane_tracker(),
        &navigator,
        &explorer,
        max_scans,
        |cycle| {
            compute_ms.push(cycle.compute_ms);
            known.push(cycle.known_free_m2);
            resident.push(resident_mb());
            if let Some(world_t_body) = cycle.sample.ground_truth {
                let here = world_t_body.translation.vector.xy();
                walked += last.map_or(0.0, |p: Vector2<f64>| (here - p).norm());
                last = Some(here);
                truth.push(StampedPose {
                    stamp: cycle.sample.stamp,
                    pose: map_t_world * world_t_body,
                });
            }
        },
    )
    .map_err(|e| e.to_string())?;
    let seconds = started.elapsed().as_secs_f64();
    let resident_at_end = resident_mb();
    let resident_peak = peak_resident_mb();
    let coverage = floor_coverage(
        spot.building(),
        start,
        &world_t_map,
        report.navigation.occupancy(),
        navigator.planning.inflation,
    );
    let (evaluation, _) = TrajectoryEvaluation::of_lidar_trajectory(
        slam.scan_trajectory(),
        &spot.body_t_lidar(),
        &truth,
    )
    .map_err(|e| e.to_string())?;
    let slam_report = slam.report();
    let final_known = known.last().copied().unwrap_or(0.0);
    let quarter = known
        .iter()
        .position(|&k| k >= 0.25 * final_known)
        .unwrap_or(0);
    let resident_at_quarter = resident.get(quarter).copied().unwrap_or(0.0);
    let decisions: f64 = report.decision_ms.iter().sum();
    let cycle_mean = (compute_ms.iter().sum::<f64>() + decisions) / compute_ms.len().max(1) as f64;
    println!(
        "{name} building, seed {seed}: {:?}, {:.1} % of {:.0} m² of reachable floor known free, \
         {walked:.0} m walked in {} scans, {} keyframes, {} loops, ATE {:.3} m, {} collisions, \
         {seconds:.0} s",
        report.outcome,
        100.0 * coverage.share(),
        coverage.reachable_area(),
        report.cycles,
        slam.keyframe_count(),
        slam_report.loops_closed,
        evaluation.ate.rmse,
        spot.collisions(),
    );
    print_table(
        &slam_report.scan_ms,
        &compute_ms,
        (resident_at_quarter, quarter, resident_at_end, resident_peak),
    );
    print_frontiers(&report);
    let stages = report.decision_stages;
    let per = |ms: f64| ms / report.decisions.max(1) as f64;
    println!(
        "Decisions by stage, ms mean: map {:.1}, planning grid {:.1}, choice {:.1}, navigator {:.1}.",
        per(stages.map),
        per(stages.planning),
        per(stages.choice),
        per(stages.navigator)
    );
    println!(
        "Navigation cycle with the decisions spread over it: {cycle_mean:.1} ms mean (issue's bar: at \
         most 10 ms); {} decisions, {:.0} ms mean, {:.0} ms at most. Resident {resident_at_start:.0} \
         MB before the first scan.",
        report.decisions,
        mean(&report.decision_ms),
        report.decision_ms.iter().copied().fold(0.0, f64::max),
    );
    print_store(&slam);
    Ok(())
}

fn main() {
    if let Err(e) = run() {
        eprintln!("exploration bench: {e}");
        std::process::exit(1);
    }
}
