//! A long walk at flat cost: N laps of one simulated building in one continuous walk, fed to
//! the engine set up as the `slam` example sets it up (point-to-plane odometry, Scan Context,
//! graduated non-convexity over Levenberg-Marquardt), printing per lap the keyframes and loops
//! so far, the scans that rode on a keyframe already there, mean / p99 ms a scan (each
//! `GraphSlam::process` timed whole, inline loop steps included), the slowest loop step,
//! resident memory and the ATE of the walk so far.
//!
//! Setups, each in its own child process so that resident memory is its own:
//! - `every-keyframe`: a new keyframe wherever the robot moved far enough, revisits included
//!   (`GraphSlamConfig::revisit_radius` 0; the engine's behaviour before revisits were
//!   tracked);
//! - `revisits` (the default settings): a scan registered within the revisit radius of a
//!   keyframe the local map holds rides on it instead of making a new one;
//! - `every-keyframe-incremental` and `revisits-incremental`: the same with
//!   `posegraph::IncrementalSmoother` (iSAM2-style, no robust back end) in place of graduated
//!   non-convexity over Levenberg-Marquardt; after its table rows, a line on stderr with the
//!   smoother's counters (optimisations, updates, restarts, share of the free nodes re-factored
//!   per update; `SLAM_LAPS_SMOOTHER_ITERATIONS=1` caps its updates per loop closure, as
//!   iSAM2 runs, instead of converging each time). With revisits the walk closes about one
//!   loop (each later lap rides on the first lap's keyframes), so the back end matters only
//!   with a keyframe every 0.2 m.
//!
//! `cargo bench -p spot-nav-benches --bench slam_laps` (10 laps of seeds 5 and 6, all four
//! setups: well over 20 minutes on 2 cores, most of it the `every-keyframe` ones). `SLAM_LAPS=3`,
//! `SLAM_LAPS_SEEDS=5` and `SLAM_LAPS_SETUPS=revisits,revisits-incremental` pick runs. Each lap
//! after the first walks the route shifted 0.25 m to one side or another (`SLAM_LAPS_OFFSET`),
//! as a patrol never walks one line twice.

use std::process::Command;
use std::time::Instant;

use posegraph::IncrementalSmoother;
use slam_core::{GraphSlam, GraphSlamConfig, MapRegistrator, Optimizer, Pose3};
use spot_adapter::eval::TrajectoryEvaluation;
use spot_adapter::pipelines::{
    point_to_plane_slam, point_to_plane_slam_optimized_by, scan_context_places, slam_config,
};
use spot_adapter::sim::{Building, BuildingConfig, Route, SimulatedSpot, SimulationConfig};
use spot_nav_benches::{quantile, resident_mb};

/// The environment variable that makes the binary run one setup as a child.
const CHILD: &str = "SLAM_LAPS_CHILD";

/// The environment variable that caps the smoother's updates per optimisation (default 100,
/// to convergence; 1 is iSAM2's one update per new loop).
const SMOOTHER_ITERATIONS: &str = "SLAM_LAPS_SMOOTHER_ITERATIONS";

/// The suffix of a setup with the incremental smoother as its back end.
const INCREMENTAL: &str = "-incremental";

/// The engine settings of `setup` (its keyframe policy, the part before [`INCREMENTAL`]).
fn config(setup: &str) -> Option<GraphSlamConfig> {
    let mut config = slam_config();
    match setup.strip_suffix(INCREMENTAL).unwrap_or(setup) {
        "every-keyframe" => config.revisit_radius = 0.0,
        "revisits" => {}
        _ => return None,
    }
    Some(config)
}

/// One setup's walk of `laps` laps of seed `seed`'s building, a table row per lap on stdout.
fn child(seed: u64, setup: &str, laps: usize, offset: f64) -> Result<(), String> {
    let config = config(setup).ok_or_else(|| format!("unknown setup {setup:?}"))?;
    if setup.ends_with(INCREMENTAL) {
        let mut smoother = IncrementalSmoother::default();
        if let Some(cap) = std::env::var(SMOOTHER_ITERATIONS)
            .ok()
            .and_then(|v| v.parse().ok())
        {
            smoother.config.max_iterations = cap;
        }
        let mut slam = point_to_plane_slam_optimized_by(config, smoother)
            .map_err(|e| e.to_string())?
            .with_place_recognizer(scan_context_places());
        walk(&mut slam, seed, setup, laps, offset)?;
        let s = slam.optimizer().statistics();
        eprintln!(
            "slam_laps: seed {seed} {setup}: {} optimisations, {} updates, {} restarts, {:.1} % of the free nodes re-factored per update",
            s.optimizations,
            s.updates,
            s.restarts,
            100.0 * s.refactored as f64 / s.variables.max(1) as f64,
        );
        return Ok(());
    }
    let mut slam = point_to_plane_slam(config)
        .map_err(|e| e.to_string())?
        .with_place_recognizer(scan_context_places());
    walk(&mut slam, seed, setup, laps, offset)
}

/// Feeds `slam` the walk of `laps` laps of seed `seed`'s building, a table row per lap.
fn walk<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    slam: &mut GraphSlam<R, C, O>,
    seed: u64,
    setup: &str,
    laps: usize,
    offset: f64,
) -> Result<(), String> {
    let building =
        Building::generate(seed, &BuildingConfig::default()).map_err(|e| e.to_string())?;
    let lap = Route::corridor_loop(&building);
    // Each lap a little to the side of the last, as a patrol never walks the same line twice.
    let points: Vec<_> = (0..laps)
        .flat_map(|k| {
            let a = 2.4 * k as f64;
            let shift =
                if k == 0 { 0.0 } else { offset } * nalgebra::Vector2::new(a.cos(), a.sin());
            lap.points().iter().map(move |p| p + shift)
        })
        .collect();
    let route = Route::new(points, true).map_err(|e| e.to_string())?;
    let sim = SimulatedSpot::new(building, &route, &SimulationConfig::with_seed(seed))
        .map_err(|e| e.to_string())?;
    let body_t_lidar = sim.body_t_lidar();
    let truth = sim.ground_truth();
    // The sample that ends each lap.
    let last = sim.len() - 1;
    let lap_ends: Vec<usize> = (1..=laps).map(|k| k * last / laps).collect();
    let (mut ms, mut loops_seen) = (Vec::new(), 0);
    for (i, sample) in sim.enumerate() {
        let t = Instant::now();
        slam.process(&sample.scan_input());
        ms.push(t.elapsed().as_secs_f64() * 1e3);
        let Some(lap) = lap_ends.iter().position(|&e| e == i) else {
            continue;
        };
        let report = slam.report();
        let loop_max = report.loop_ms[loops_seen.min(report.loop_ms.len())..]
            .iter()
            .copied()
            .fold(0.0, f64::max);
        loops_seen = report.loop_ms.len();
        let (e, _) = TrajectoryEvaluation::of_lidar_trajectory(
            slam.scan_trajectory(),
            &body_t_lidar,
            &truth[..=i],
        )
        .map_err(|e| e.to_string())?;
        println!(
            "| {seed} | {setup} | {} | {} | {} | {} | {:.1} / {:.1} | {loop_max:.0} | {:.0} | {:.2} |",
            lap + 1,
            report.keyframes,
            report.loops_closed,
            report.revisits,
            ms.iter().sum::<f64>() / ms.len() as f64,
            quantile(&ms, 0.99),
            resident_mb(),
            100.0 * e.ate.rmse,
        );
        ms.clear();
    }
    Ok(())
}

fn main() {
    if let Ok(job) = std::env::var(CHILD) {
        let mut parts = job.splitn(3, ',');
        let (Some(seed), Some(setup), Some(laps)) = (parts.next(), parts.next(), parts.next())
        else {
            eprintln!("slam_laps: bad {CHILD} {job:?}");
            std::process::exit(2);
        };
        let (Ok(seed), Ok(laps)) = (seed.parse(), laps.parse()) else {
            eprintln!("slam_laps: bad {CHILD} {job:?}");
            std::process::exit(2);
        };
        let offset = std::env::var("SLAM_LAPS_OFFSET")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(0.25);
        if let Err(e) = child(seed, setup, laps, offset) {
            eprintln!("slam_laps: seed {seed} {setup}: {e}");
            std::process::exit(1);
        }
        return;
    }
    let pick = |var: &str, all: &str| std::env::var(var).unwrap_or_else(|_| all.to_string());
    let laps = pick("SLAM_LAPS", "10");
    let seeds = pick("SLAM_LAPS_SEEDS", "5,6");
    let setups = pick(
        "SLAM_LAPS_SETUPS",
        "every-keyframe,every-keyframe-incremental,revisits,revisits-incremental",
    );
    let Ok(exe) = std::env::current_exe() else {
        eprintln!("slam_laps: cannot find this binary to run its setups");
        std::process::exit(1);
    };
    println!(
        "| seed | setup | lap | keyframes | loops closed | scans riding on an old keyframe | mean / p99 ms a scan | slowest loop step (ms) | resident MB | ATE so far (cm) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let mut failed = false;
    for seed in seeds.split(',').map(str::trim) {
        for setup in setups.split(',').map(str::trim) {
            let status = Command::new(&exe)
                .env(CHILD, format!("{seed},{setup},{laps}"))
                .status();
            if !status.is_ok_and(|s| s.success()) {
                eprintln!("slam_laps: seed {seed} {setup} failed");
                failed = true;
            }
        }
    }
    if failed {
        std::process::exit(1);
    }
}
