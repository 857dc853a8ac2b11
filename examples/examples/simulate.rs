//! Simulate Spot walking one lap of a generated building's corridor loop (or a person carrying
//! the LiDAR round it), and report the motion, scan and odometry figures; optionally write the
//! run as a recording and as a folder of scans any tool reads.
//!
//! `cargo run --release -p spot-nav-examples --example simulate -- [--seed N] [--sensor vlp16|os1-128] [--motion walk|fast-turns|handheld] [--skewed] [--out DIR] [--cloud-folder DIR [--cloud-format ply|pcd]]`

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Result;
use clap::{Parser, ValueEnum};
use slam_core::Pose3;
use slam_core::io::StampedPose;
use spot_adapter::eval::{
    DEFAULT_MAX_STAMP_DIFFERENCE, INDOOR_SEGMENT_LENGTHS, TrajectoryEvaluation, path_length,
};
use spot_adapter::record::RecordingWriter;
use spot_adapter::sim::{CloudFolderWriter, CloudFormat, SimulatedSpot, SimulationConfig};
use spot_nav_examples::{Motion, Progress, Sensor, out, quantile, value_name};

/// Steps (seconds) at which the true pose is differentiated for the top yaw rate.
const RATE_STEP: f64 = 0.01;

/// A scan file format, as `--cloud-format` gives it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum CloudFormatArg {
    /// Binary little-endian PLY (x y z time, float).
    Ply,
    /// Binary PCD (x y z t, float).
    Pcd,
}

/// Simulate Spot walking one lap of a generated building's corridor loop.
///
/// By default Spot walks at 0.6 m/s with a VLP-16 at 5 Hz and drifting odometry; `--sensor`
/// and `--motion` choose another LiDAR and motion (Spot turning corners in place at 1 rad/s, or
/// a person carrying the LiDAR with 2 Hz samples). Prints the building, the motion (heading
/// change between samples, top yaw rate, tilt, height), the scan and timing figures, and the
/// odometry's error against the ground truth (ATE, loop end-point error, segment drift). With
/// `--out` the run is written as a recording (about 0.5 MB per VLP-16 scan) that the `slam`
/// example replays; with `--cloud-folder` as one PLY (or PCD) file per sample named by its
/// stamp, with `ground_truth.tum` and `odometry.tum` of the LiDAR beside them, for any tool.
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
    /// The simulated LiDAR.
    #[arg(long, value_enum, value_name = "SENSOR", default_value_t = Sensor::Vlp16)]
    sensor: Sensor,
    /// How the LiDAR moves along the lap.
    #[arg(long, value_enum, value_name = "MOTION", default_value_t = Motion::Walk)]
    motion: Motion,
    /// Cast each column of a sweep from the true pose at its firing time (motion distortion;
    /// every point's `time` says when), instead of the whole sweep from the pose at its stamp.
    #[arg(long)]
    skewed: bool,
    /// Floors of the building (1 to 3). Above one, Spot walks a lap of the ground floor,
    /// climbs the stairs, walks a lap of each floor above and comes back down (Spot's walk:
    /// `--motion` is for one floor).
    #[arg(long, value_name = "N", default_value_t = 1)]
    floors: usize,
    /// With `--floors`: every floor a copy of the ground floor's plan (by default each floor
    /// above has rooms of its own round the same corridor and core).
    #[arg(long, requires = "floors")]
    repeat_floor_plan: bool,
    /// Write the recording to this folder.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Write the scans to this folder, one file per sample named by its stamp, with the
    /// LiDAR's true trajectory (`ground_truth.tum`) and odometry (`odometry.tum`) beside them.
    #[arg(long, value_name = "DIR")]
    cloud_folder: Option<PathBuf>,
    /// The scan files' format in `--cloud-folder`.
    #[arg(
        long,
        value_enum,
        value_name = "FORMAT",
        default_value_t = CloudFormatArg::Ply,
        requires = "cloud_folder"
    )]
    cloud_format: CloudFormatArg,
}

fn main() -> ExitCode {
    spot_nav_examples::run(|| simulate(&Args::parse()))
}

/// Degrees from radians, wrapped to `[-180, 180)`.
fn wrapped_degrees(radians: f64) -> f64 {
    (radians.to_degrees() + 180.0).rem_euclid(360.0) - 180.0
}

/// The motion's figures: the heading change between consecutive samples, the top yaw rate of
/// the true motion (finite differences every 10 ms), the largest roll or pitch and the height
/// of the body over the floor.
fn motion_figures(sim: &SimulatedSpot, truth: &[StampedPose]) -> String {
    let euler = |p: &StampedPose| p.pose.rotation.euler_angles();
    let mut turns: Vec<f64> = truth
        .windows(2)
        .map(|w| wrapped_degrees(euler(&w[1]).2 - euler(&w[0]).2).abs())
        .collect();
    turns.sort_by(f64::total_cmp);
    let end = truth.last().map_or(0.0, |p| p.stamp);
    let poses: Vec<Pose3> = (0..=(end / RATE_STEP).ceil() as usize)
        .map(|k| sim.pose_at(k as f64 * RATE_STEP))
        .collect();
    let yaw_rate = poses
        .windows(2)
        .map(|w| w[0].rotation.angle_to(&w[1].rotation) / RATE_STEP)
        .fold(0.0, f64::max);
    let tilt = truth
        .iter()
        .map(|p| euler(p).0.abs().max(euler(p).1.abs()))
        .fold(0.0, f64::max);
    let heights = truth.iter().map(|p| p.pose.translation.z);
    let (low, high) = heights.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), z| {
        (lo.min(z), hi.max(z))
    });
    let period = truth.get(1).map_or(0.0, |p| p.stamp - truth[0].stamp);
    format!(
        "{end:.1} s, a sample every {period:.2} s; heading change between samples median {:.1}°, max {:.1}°, above 10° {} times; top yaw rate {yaw_rate:.2} rad/s; roll/pitch up to {:.1}°; body {low:.3}-{high:.3} m above the floor",
        quantile(&turns, 0.5).unwrap_or(0.0),
        quantile(&turns, 1.0).unwrap_or(0.0),
        turns.iter().filter(|&&t| t > 10.0).count(),
        tilt.to_degrees(),
    )
}

/// The odometry's error against the ground truth, on one line.
fn report_odometry(odometry: &[StampedPose], truth: &[StampedPose]) -> Result<()> {
    let e = TrajectoryEvaluation::compute(
        odometry,
        truth,
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
    Ok(())
}

fn simulate(args: &Args) -> Result<()> {
    let seed = args.seed;
    let mut config = SimulationConfig::with_seed(seed);
    config.lidar = args.sensor.lidar();
    config.motion = args.motion.profile();
    config.motion_distortion = args.skewed;
    config.building.floors = args.floors;
    config.building.repeat_floor_plan = args.repeat_floor_plan;
    let mut sim = SimulatedSpot::floors_tour(&config)?;
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
    if sim.building().floors() > 1 {
        let stairs = sim.on_stairs().iter().filter(|&&on| on).count();
        let flights: Vec<String> = sim
            .building()
            .staircases()
            .iter()
            .map(flight_line)
            .collect();
        out!(
            "{} floors {:.2} m apart; flights of {}; {stairs} samples on the stairs",
            sim.building().floors(),
            sim.building().floor_height(1),
            flights.join("; "),
        )?;
    }
    out!(
        "{} with {}: {}",
        value_name(&args.motion),
        value_name(&args.sensor),
        motion_figures(&sim, &truth)
    )?;
    let mut writer = match &args.out {
        Some(dir) => Some(RecordingWriter::create(dir, sim.body_t_lidar())?),
        None => None,
    };
    let mut folder = match &args.cloud_folder {
        Some(dir) => Some(CloudFolderWriter::create(
            dir,
            match args.cloud_format {
                CloudFormatArg::Ply => CloudFormat::Ply,
                CloudFormatArg::Pcd => CloudFormat::Pcd,
            },
        )?),
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
        if let Some(f) = folder.as_mut() {
            f.write(&sample)?;
        }
        progress.update(k as u64, "");
    }
    let elapsed = started.elapsed().as_secs_f64();
    progress.finish();
    let writing = match (&args.out, &args.cloud_folder) {
        (None, None) => "",
        (Some(_), None) => ", PCD writing",
        (None, Some(_)) => ", scan file writing",
        (Some(_), Some(_)) => ", PCD and scan file writing",
    };
    out!(
        "{:.0} points per scan; {:.2} ms per sample mean, {:.2} ms max (ray casting, noise, odometry{writing})",
        points as f64 / n as f64,
        1e3 * elapsed / n as f64,
        1e3 * worst,
    )?;
    report_odometry(&odometry, &truth)?;
    if let Some(w) = writer {
        out!("recording written to {}", w.finish()?.display())?;
    }
    if let Some(f) = folder {
        out!("scans written to {}", f.finish()?.display())?;
    }
    Ok(())
}

/// A flight's steps, rise, tread, run and landing, for the summary line.
fn flight_line(f: &spot_adapter::sim::Staircase) -> String {
    let landing = f.landing.map_or_else(String::new, |l| {
        format!(", a {:.1} m landing after step {}", l.depth, l.after)
    });
    format!(
        "{} steps ({:.3} m rise, {:.2} m tread, {:.1} m run{landing})",
        f.steps,
        f.rise,
        f.tread,
        f.run()
    )
}
