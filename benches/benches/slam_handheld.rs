//! The hand-held walk over many seeds: an OS1-128 carried by a walking person (2 Hz scans, each
//! a 0.1 s sweep skewed by the hand's shake, turns of up to 50° between scans), LiDAR-only,
//! through the engine set up as `slam --sensor os1-128 --motion handheld --skewed
//! --no-odometry` sets it up, one seed after the other, printing a row a seed: accuracy against
//! the simulator's truth (ATE, end-point drift, height drift, steps whose rotation is more than
//! 2° off and the largest), the scans recovered by a retry and the fallbacks, and the engine's
//! own mean / p99 ms a scan (the ray casting between scans is not counted).
//!
//! Which scans of such a walk tip a few degrees wrong moves with small changes to the tracker;
//! one seed says little, the spread over many says what a change did. Not a criterion bench: a
//! walk is one long run whose accuracy is the point, and the times are those of one run.
//!
//! `cargo bench -p spot-nav-benches --bench slam_handheld` (seeds 1-12, about 3 minutes on 2
//! cores); `SLAM_HANDHELD_SEEDS=1,5,8` picks seeds.

use slam_core::GraphSlam;
use spot_adapter::eval::TrajectoryEvaluation;
use spot_adapter::pipelines::{
    point_to_plane_slam_with, point_to_plane_tracker, scan_context_places, slam_config,
};
use spot_adapter::sim::{LidarConfig, MotionProfile, SimulatedSpot, SimulationConfig};

/// One seed's walk, or why it could not be run.
fn walk(seed: u64) -> Result<String, String> {
    let mut config = SimulationConfig::with_seed(seed);
    config.lidar = LidarConfig::os1_128();
    config.motion = MotionProfile::handheld();
    config.motion_distortion = true;
    let sim = SimulatedSpot::floors_tour(&config).map_err(|e| format!("simulation: {e}"))?;
    let body_t_lidar = sim.body_t_lidar();
    let truth = sim.ground_truth();
    let slam: GraphSlam<_, _, _> =
        point_to_plane_slam_with(slam_config(), point_to_plane_tracker())
            .map_err(|e| format!("engine: {e}"))?;
    let mut slam = slam.with_place_recognizer(scan_context_places());
    for sample in sim {
        slam.process(&sample.lidar_only_input());
    }
    let report = slam.report();
    let (e, _) =
        TrajectoryEvaluation::of_lidar_trajectory(slam.scan_trajectory(), &body_t_lidar, &truth)
            .map_err(|e| format!("evaluation: {e}"))?;
    Ok(format!(
        "| {seed} | {} / {} | {} | {:.1} cm | {:.1} cm ({:.3} %) | {:+.1} cm | {} ({:.2}°) | {} / {} | {:.1} / {:.1} |",
        report.scans,
        report.keyframes,
        report.loops_closed,
        e.ate.rmse * 100.0,
        e.end_point.end_point_error * 100.0,
        e.end_point.relative_drift * 100.0,
        e.height_drift * 100.0,
        e.steps_over(2.0),
        e.max_step_rotation_error_deg(),
        report.tracking.recovered,
        report.fallbacks(),
        report.mean_scan_ms(),
        report.scan_ms_quantile(0.99),
    ))
}

fn main() {
    let seeds: Vec<String> = std::env::var("SLAM_HANDHELD_SEEDS").map_or_else(
        |_| (1..=12).map(|s| s.to_string()).collect(),
        |v| v.split(',').map(|s| s.trim().to_string()).collect(),
    );
    println!(
        "| seed | scans / keyframes | loops closed | ATE | end-point drift | height drift | steps > 2° (largest) | recovered / fallbacks | mean / p99 ms a scan |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let mut failed = false;
    for seed in &seeds {
        let Ok(n) = seed.parse::<u64>() else {
            eprintln!("slam_handheld bench: seed {seed:?} is not a number");
            failed = true;
            continue;
        };
        match walk(n) {
            Ok(row) => println!("{row}"),
            Err(e) => {
                eprintln!("slam_handheld bench: seed {n}: {e}");
                failed = true;
            }
        }
    }
    if failed {
        std::process::exit(1);
    }
}
