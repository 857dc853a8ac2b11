//! Graph-SLAM per-scan time on the simulated Spot: one lap per seed with each engine setup
//! (point-to-plane and LOAM odometry), printing the table (accuracy against the ground
//! truth, and mean / p99 / max milliseconds per scan on the odometry path, loop steps apart).
//! The engine times each scan itself, so the simulator's ray casting between scans is not
//! counted. Not a criterion bench: a lap is one long run whose distribution (p99, max) is the
//! point. Single-scan maxima on a shared VM include preemptions; `python3
//! benches/machine_jitter.py` shows how large they get.
//!
//! `cargo bench -p spot-nav-benches --bench slam` (about 2 minutes; `SLAM_BENCH_SEEDS=1,3` and
//! `SLAM_BENCH_SETUPS=loam` pick runs)

use slam_core::{GraphSlam, MapRegistrator, Optimizer, Pose3};
use spot_adapter::{
    SimulatedSpot, SimulationConfig, TrajectoryEvaluation, loam_slam, point_to_plane_slam,
    slam_config,
};

/// Runs one lap of `sim` through `slam` and returns the table row after `seed | setup |`.
fn lap<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    mut slam: GraphSlam<R, C, O>,
    sim: SimulatedSpot,
) -> Result<String, String> {
    let body_t_lidar = sim.body_t_lidar();
    let truth = sim.ground_truth();
    for sample in sim {
        slam.process(&sample.scan_input());
    }
    let report = slam.report();
    let p99 = report.scan_ms_quantile(0.99);
    let loop_max = report.loop_ms.iter().copied().fold(0.0, f64::max);
    let (e, _) =
        TrajectoryEvaluation::of_lidar_trajectory(slam.scan_trajectory(), &body_t_lidar, &truth)
            .map_err(|e| e.to_string())?;
    Ok(format!(
        "{} / {} | {} | {:.1} cm | {:.1} cm | {} | {} | {:.1} / {:.1} / {:.1} | {loop_max:.1} ms |",
        report.scans,
        report.keyframes,
        report.loops_closed,
        100.0 * e.ate.rmse,
        100.0 * e.loop_end_point_error,
        e.segments
            .map_or_else(|| "-".into(), |s| format!("{:.3} %", 100.0 * s.translation)),
        report.odometry_fallbacks,
        report.mean_scan_ms(),
        p99,
        report.max_scan_ms(),
    ))
}

fn main() {
    let pick = |var: &str, all: &[&str]| -> Vec<String> {
        std::env::var(var).map_or_else(
            |_| all.iter().map(|s| (*s).to_string()).collect(),
            |v| v.split(',').map(|s| s.trim().to_string()).collect(),
        )
    };
    let seeds = pick("SLAM_BENCH_SEEDS", &["1", "2", "3"]);
    let setups = pick("SLAM_BENCH_SETUPS", &["p2plane", "loam"]);
    println!(
        "| seed | setup | scans / keyframes | loops closed | ATE | loop end-point error | segment drift | odometry fallbacks | mean / p99 / max ms per scan | loop step max |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for seed in &seeds {
        let Ok(seed_n) = seed.parse::<u64>() else {
            eprintln!("slam bench: seed {seed:?} is not a number; skipped");
            continue;
        };
        for setup in &setups {
            let mut config = SimulationConfig::default();
            config.seed = seed_n;
            let sim = match SimulatedSpot::corridor_loop(seed_n, &config) {
                Ok(sim) => sim,
                Err(e) => {
                    eprintln!("slam bench: seed {seed}: simulation failed: {e}");
                    continue;
                }
            };
            let row = match setup.as_str() {
                "p2plane" => lap(point_to_plane_slam(slam_config()), sim),
                "loam" => lap(loam_slam(slam_config()), sim),
                other => Err(format!("unknown setup {other:?} (p2plane, loam)")),
            };
            match row {
                Ok(row) => println!("| {seed} | {setup} | {row}"),
                Err(e) => eprintln!("slam bench: seed {seed} {setup}: {e}"),
            }
        }
    }
}
