//! Simulate Spot walking one lap of a generated building's corridor loop, and report the scan
//! and odometry figures (and optionally write the run as a recording).
//!
//! `cargo run --release -p spot-nav-examples --example simulate -- [--seed N] [--out DIR]`

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Result;
use clap::Parser;
use slam_core::Pose3;
use slam_core::io::StampedPose;
use spot_adapter::eval::{
    DEFAULT_MAX_STAMP_DIFFERENCE, INDOOR_SEGMENT_LENGTHS, TrajectoryEvaluation, path_length,
};
use spot_adapter::record::RecordingWriter;
use spot_adapter::sim::{SimulatedSpot, SimulationConfig};
use spot_nav_examples::{Progress, out};

/// Simulate Spot walking one lap of a generated building's corridor loop.
///
/// VLP-16 scans at 5 Hz and drifting odometry; prints the building, the scan and timing figures,
/// and the odometry's error against the ground truth (ATE, loop end-point error, segment
/// drift). With `--out` the run is written as a recording (about 0.5 MB per scan), which the `slam`
/// example replays.
#[derive(Debug, Parser)]
#[command(name = "simulate")]
struct Args {
    /// Seed of the building, the sensor noise and the odometry drift.
    #[arg(
        long,
        value_name = "N",
        allow_negative_numbers = true,
        default_value_t = 1
    )]
    seed: u64,
    /// Write the recording to this folder.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

fn main() -> ExitCode {
    spot_nav_examples::run(|| simulate(&Args::parse()))
}

fn simulate(args: &Args) -> Result<()> {
    let seed = args.seed;
    let config = SimulationConfig::with_seed(seed);
    let mut sim = SimulatedSpot::corridor_loop(&config)?;
    let size = sim.building().size();
    let truth = sim.ground_truth();
    let gt: Vec<Pose3> = truth.iter().map(|p| p.pose).collect();
    out!(
        "building {seed}: {:.1} x {:.1} m, {} boxes, {} rooms; loop {:.1} m, {} samples",
        size.x,
        size.y,
        sim.building().boxes().len(),
        sim.building().rooms().len(),
        path_length(&gt),
        sim.len()
    )?;
    let mut writer = match &args.out {
        Some(dir) => Some(RecordingWriter::create(dir, sim.body_t_lidar())?),
        None => None,
    };
    let (mut odometry, mut points, mut worst) = (Vec::new(), 0usize, 0.0f64);
    let n = sim.len();
    let mut progress = Progress::new("simulating", "samples", Some(n as u64));
    let started = Instant::now();
    for k in 1..=n {
        let t0 = Instant::now();
        let Some(sample) = sim.next() else { break };
        worst = worst.max(t0.elapsed().as_secs_f64());
        points += sample.cloud.len();
        odometry.push(StampedPose {
            stamp: sample.stamp,
            pose: sample.odom_t_body,
        });
        if let Some(w) = writer.as_mut() {
            w.write(&sample)?;
        }
        progress.update(k as u64, "");
    }
    let elapsed = started.elapsed().as_secs_f64();
    progress.finish();
    out!(
        "{:.0} points per scan; {:.2} ms per sample mean, {:.2} ms max (ray casting, noise, odometry{})",
        points as f64 / n as f64,
        1e3 * elapsed / n as f64,
        1e3 * worst,
        if args.out.is_some() {
            ", PCD writing"
        } else {
            ""
        }
    )?;
    let e = TrajectoryEvaluation::compute(
        &odometry,
        &truth,
        DEFAULT_MAX_STAMP_DIFFERENCE,
        &INDOOR_SEGMENT_LENGTHS,
    )?;
    let segments = e.segments.map_or_else(
        || "n/a (path too short)".into(),
        |s| {
            format!(
                "{:.2} % ({} segments of 10-50 m)",
                100.0 * s.translation,
                s.segments
            )
        },
    );
    out!(
        "odometry: ATE {:.3} m, loop end-point error {:.3} m ({:.2} % of {:.1} m), segment drift {segments}",
        e.ate.rmse,
        e.loop_end_point_error,
        100.0 * e.end_point.relative_drift,
        e.end_point.path_length,
    )?;
    if let Some(w) = writer {
        out!("recording written to {}", w.finish()?.display())?;
    }
    Ok(())
}
