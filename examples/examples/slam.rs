//! Graph-SLAM on a simulated Spot (or a recording): point-to-plane ICP (or LOAM) odometry against
//! the local map, loop closure (point-to-point check, point-to-plane or LOAM refinement),
//! Levenberg-Marquardt. Prints scans, keyframes, loop closures, ATE, drift, loop end-point error
//! and per-scan times, and writes the map (PLY), the trajectory (TUM) and the pose graph (g2o)
//! with `--out`.
//!
//! `cargo run --release --example slam -- [RECORDING_DIR] [--seed N] [--registration p2plane|loam] [--out DIR]`

use std::time::Instant;

use anyhow::{Context, Result, bail};
use posegraph::g2o::{G2oGraph, write_g2o};
use slam_core::io::{PcdEncoding, PlyEncoding, StampedPose, write_pcd, write_ply, write_tum};
use slam_core::{GraphSlam, MapRegistrator, Optimizer, Pose3, ScanOutcome};
use spot_adapter::eval::{
    DEFAULT_MAX_STAMP_DIFFERENCE, INDOOR_SEGMENT_LENGTHS, TrajectoryEvaluation, body_trajectory,
};
use spot_adapter::pipelines::{loam_slam, point_to_plane_slam, slam_config};
use spot_adapter::record::Recording;
use spot_adapter::robot::Sample;
use spot_adapter::sim::{SimulatedSpot, SimulationConfig};

const USAGE: &str = "usage: slam [RECORDING_DIR] [--seed N] [--registration p2plane|loam] \
                     [--skewed] [--no-deskew] [--out DIR]";

/// Samples to feed the engine.
type Samples = Box<dyn Iterator<Item = Result<Sample>>>;

/// Samples, the LiDAR mounting and (when known) the ground truth of a recording or a simulation.
fn open(
    recording: Option<&str>,
    seed: u64,
    skewed: bool,
) -> Result<(Samples, Pose3, Option<Vec<StampedPose>>)> {
    if let Some(dir) = recording {
        let rec = Recording::open(dir)?;
        let body_t_lidar = rec.body_t_lidar();
        let truth = rec.read_ground_truth()?;
        // One scan at a time: memory stays that of one scan however long the recording.
        let samples = rec.into_iter().map(|s| s.map_err(anyhow::Error::from));
        Ok((Box::new(samples), body_t_lidar, truth))
    } else {
        let mut config = SimulationConfig::default();
        config.seed = seed;
        config.motion_distortion = skewed;
        let sim = SimulatedSpot::corridor_loop(&config)?;
        let body_t_lidar = sim.body_t_lidar();
        let truth = Some(sim.ground_truth());
        Ok((Box::new(sim.map(Ok)), body_t_lidar, truth))
    }
}

fn main() -> Result<()> {
    let (mut recording, mut seed, mut out, mut method) =
        (None, 1u64, None, String::from("p2plane"));
    let (mut skewed, mut config) = (false, slam_config());
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--seed" => seed = args.next().context(USAGE)?.parse()?,
            "--out" => out = Some(std::path::PathBuf::from(args.next().context(USAGE)?)),
            "--registration" => method = args.next().context(USAGE)?,
            "--skewed" => skewed = true,
            "--no-deskew" => config.deskew = false,
            "-h" | "--help" => {
                println!("{USAGE}");
                return Ok(());
            }
            _ if recording.is_none() => recording = Some(a),
            _ => bail!("unexpected argument {a:?}; {USAGE}"),
        }
    }
    let (samples, body_t_lidar, truth) = open(recording.as_deref(), seed, skewed)?;
    match method.as_str() {
        "p2plane" => run(
            point_to_plane_slam(config),
            samples,
            body_t_lidar,
            truth.as_deref(),
            out,
        ),
        "loam" => run(
            loam_slam(config),
            samples,
            body_t_lidar,
            truth.as_deref(),
            out,
        ),
        other => bail!("unknown registration {other:?}; {USAGE}"),
    }
}

/// Feed every sample, then report and write the outputs.
fn run<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    mut slam: GraphSlam<R, C, O>,
    samples: Samples,
    body_t_lidar: Pose3,
    truth: Option<&[StampedPose]>,
    out: Option<std::path::PathBuf>,
) -> Result<()> {
    let started = Instant::now();
    let mut n = 0usize;
    for sample in samples {
        let sample = sample?;
        let outcome = slam.process(&sample.scan_input());
        n += 1;
        if n.is_multiple_of(50) {
            eprint!(
                "\r{n} scans, {} keyframes, {} loops",
                slam.keyframe_count(),
                slam.report().loops_closed
            );
        }
        if let ScanOutcome::Skipped(reason) = outcome {
            eprintln!("\rscan {n} skipped: {reason:?}");
        }
    }
    eprintln!();
    let wall = started.elapsed().as_secs_f64();
    let report = slam.report();
    println!(
        "scans       {} ({} keyframes, {} skipped)",
        report.scans,
        report.keyframes,
        report.skipped_out_of_order
            + report.skipped_non_finite_odometry
            + report.skipped_too_few_points
            + report.skipped_preparation
            + report.skipped_awaiting_velocity
    );
    println!(
        "loops       {} closed of {} tried; {} odometry fallbacks",
        report.loops_closed, report.loops_attempted, report.odometry_fallbacks
    );
    let loop_max = report.loop_ms.iter().copied().fold(0.0, f64::max);
    let p99 = report.scan_ms_quantile(0.99);
    let slowest = report
        .scan_ms
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map_or(0, |(i, _)| i + 1);
    println!(
        "time        {:.2} ms mean, {p99:.2} ms p99, {:.2} ms max (scan {slowest}) per scan (odometry path); loop steps max {loop_max:.1} ms; {wall:.1} s in all",
        report.mean_scan_ms(),
        report.max_scan_ms()
    );
    // Body trajectory in the map frame, for comparison with the ground truth.
    let estimate = body_trajectory(slam.scan_trajectory(), &body_t_lidar);
    if let Some(truth) = truth {
        let e = TrajectoryEvaluation::compute(
            &estimate,
            truth,
            DEFAULT_MAX_STAMP_DIFFERENCE,
            &INDOOR_SEGMENT_LENGTHS,
        )?;
        println!(
            "accuracy    ATE {:.3} m, loop end-point error {:.3} m, drift {:.3} % of {:.1} m{}",
            e.ate.rmse,
            e.loop_end_point_error,
            100.0 * e.end_point.relative_drift,
            e.end_point.path_length,
            e.segments.map_or_else(String::new, |s| format!(
                ", segments {:.3} %",
                100.0 * s.translation
            ))
        );
    }
    if let Some(dir) = out {
        std::fs::create_dir_all(&dir)?;
        let map = slam.map(0.05)?;
        write_ply(dir.join("map.ply"), &map, PlyEncoding::BinaryLittleEndian)?;
        write_pcd(dir.join("map.pcd"), &map, PcdEncoding::Binary)?;
        write_tum(dir.join("trajectory.tum"), &estimate)?;
        write_g2o(dir.join("graph.g2o"), &G2oGraph::Se3(slam.graph().clone()))?;
        println!("wrote       {}", dir.display());
    }
    Ok(())
}
