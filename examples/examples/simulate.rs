//! Simulate Spot walking one lap of a generated building's corridor loop, and report the scan
//! and odometry figures (and optionally write the run as a recording).
//!
//! `cargo run --release -p spot-nav-examples --example simulate -- [--seed N] [--out DIR]`

use std::time::Instant;

use anyhow::{Context, bail};
use slam_core::Pose3;
use slam_core::io::StampedPose;
use spot_adapter::eval::{
    DEFAULT_MAX_STAMP_DIFFERENCE, INDOOR_SEGMENT_LENGTHS, TrajectoryEvaluation,
};
use spot_adapter::record::RecordingWriter;
use spot_adapter::sim::{SimulatedSpot, SimulationConfig};

fn main() -> anyhow::Result<()> {
    let mut seed = 1u64;
    let mut out = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--seed" => seed = args.next().context("--seed needs a value")?.parse()?,
            "--out" => out = Some(args.next().context("--out needs a folder")?),
            other => bail!("unknown argument {other}; usage: simulate [--seed N] [--out DIR]"),
        }
    }
    let mut config = SimulationConfig::default();
    config.seed = seed;
    let mut sim = SimulatedSpot::corridor_loop(&config)?;
    let size = sim.building().size();
    let truth = sim.ground_truth();
    let gt: Vec<Pose3> = truth.iter().map(|p| p.pose).collect();
    println!(
        "building {seed}: {:.1} x {:.1} m, {} boxes, {} rooms; loop {:.1} m, {} samples",
        size.x,
        size.y,
        sim.building().boxes().len(),
        sim.building().rooms().len(),
        spot_adapter::eval::path_length(&gt),
        sim.len()
    );
    let mut writer = match &out {
        Some(dir) => Some(RecordingWriter::create(dir, sim.body_t_lidar())?),
        None => None,
    };
    let (mut odometry, mut points, mut worst) = (Vec::new(), 0usize, 0.0f64);
    let started = Instant::now();
    let n = sim.len();
    for k in 0..n {
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
        if k % 100 == 0 {
            eprint!("\r{k}/{n} samples");
        }
    }
    let elapsed = started.elapsed().as_secs_f64();
    eprintln!("\r{n}/{n} samples");
    println!(
        "{:.0} points per scan; {:.2} ms per sample mean, {:.2} ms max (ray casting, noise, odometry{})",
        points as f64 / n as f64,
        1e3 * elapsed / n as f64,
        1e3 * worst,
        if out.is_some() { ", PCD writing" } else { "" }
    );
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
    println!(
        "odometry: ATE {:.3} m, loop end-point error {:.3} m ({:.2} % of {:.1} m), segment drift {segments}",
        e.ate.rmse,
        e.loop_end_point_error,
        100.0 * e.end_point.relative_drift,
        e.end_point.path_length,
    );
    if let Some(w) = writer {
        println!("recording written to {}", w.finish()?.display());
    }
    Ok(())
}
