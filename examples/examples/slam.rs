//! Graph-SLAM on a simulated Spot (or a recording): point-to-plane ICP (or LOAM) odometry against
//! the local map, loop closure (point-to-point check, point-to-plane or LOAM refinement),
//! Levenberg-Marquardt. Prints scans, keyframes, loop closures, ATE, drift, loop end-point error
//! and per-scan times, and writes the map (PLY), the trajectory (TUM) and the pose graph (g2o)
//! with `--out`.
//!
//! `cargo run --release --example slam -- [RECORDING_DIR] [--seed N] [--registration p2plane|loam] [--skewed] [--no-deskew] [--out DIR]`

use std::convert::Infallible;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use clap::Parser;
use posegraph::g2o::{G2oGraph, write_g2o};
use slam_core::io::{PcdEncoding, PlyEncoding, StampedPose, write_pcd, write_ply, write_tum};
use slam_core::{GraphSlam, GraphSlamConfig, MapRegistrator, Optimizer, Pose3};
use spot_adapter::pipelines::{loam_slam, point_to_plane_slam, slam_config};
use spot_adapter::record::Recording;
use spot_adapter::robot::Sample;
use spot_adapter::sim::{SimulatedSpot, SimulationConfig};
use spot_nav_examples::{Registration, map_and_evaluate, out};

/// Graph-SLAM on one simulated lap of a generated building, or on a recording.
///
/// LiDAR odometry against the local map, loop closure, Levenberg-Marquardt. Prints scans,
/// keyframes, loop closures, per-scan times and, when the ground truth is known, ATE, drift and
/// loop end-point error. With `--out` it writes the map (`map.ply`, `map.pcd`), the body trajectory
/// (`trajectory.tum`) and the pose graph (`graph.g2o`). Fails when the engine accepts no scan.
#[derive(Debug, Parser)]
#[command(name = "slam")]
struct Args {
    /// A recording folder (as the simulate example writes it) to replay instead of simulating.
    #[arg(value_name = "RECORDING_DIR")]
    recording: Option<PathBuf>,
    /// Seed of the simulated building, sensor noise and odometry drift (without a recording).
    #[arg(
        long,
        value_name = "N",
        allow_negative_numbers = true,
        default_value_t = 1
    )]
    seed: u64,
    /// Odometry and loop refinement backend.
    #[arg(long, value_enum, default_value_t = Registration::PointToPlane)]
    registration: Registration,
    /// Simulate scans cast while walking (motion distortion, 12 cm per sweep).
    #[arg(long)]
    skewed: bool,
    /// Turn off the engine's deskewing of scans with per-point times.
    #[arg(long)]
    no_deskew: bool,
    /// Write the map, trajectory and pose graph to this folder.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

fn main() -> ExitCode {
    spot_nav_examples::run(|| slam(&Args::parse()))
}

fn slam(args: &Args) -> Result<()> {
    let mut config = slam_config();
    if args.no_deskew {
        config.deskew = false;
    }
    if let Some(dir) = &args.recording {
        let rec = Recording::open(dir)?;
        let body_t_lidar = rec.body_t_lidar();
        let truth = rec.read_ground_truth()?;
        backend(
            args,
            config,
            rec.into_iter(),
            body_t_lidar,
            truth.as_deref(),
        )
    } else {
        let mut sim_config = SimulationConfig::with_seed(args.seed);
        sim_config.motion_distortion = args.skewed;
        let sim = SimulatedSpot::corridor_loop(&sim_config)?;
        let body_t_lidar = sim.body_t_lidar();
        let truth = sim.ground_truth();
        let samples = sim.map(Ok::<Sample, Infallible>);
        backend(args, config, samples, body_t_lidar, Some(&truth))
    }
}

/// The engine `--registration` chooses, run on `samples`.
fn backend<I, E>(
    args: &Args,
    config: GraphSlamConfig,
    samples: I,
    body_t_lidar: Pose3,
    truth: Option<&[StampedPose]>,
) -> Result<()>
where
    I: ExactSizeIterator<Item = Result<Sample, E>>,
    E: Into<anyhow::Error>,
{
    let label = if args.recording.is_some() {
        "replaying"
    } else {
        "mapping"
    };
    match args.registration {
        Registration::PointToPlane => {
            let mut slam = point_to_plane_slam(config)?;
            let mapping = map_and_evaluate(&mut slam, samples, &body_t_lidar, truth, label)?;
            report(&slam, &mapping, args.out.as_deref())
        }
        Registration::Loam => {
            let mut slam = loam_slam(config)?;
            let mapping = map_and_evaluate(&mut slam, samples, &body_t_lidar, truth, label)?;
            report(&slam, &mapping, args.out.as_deref())
        }
    }
}

/// Print the run's figures and write the outputs to `out`.
fn report<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    slam: &GraphSlam<R, C, O>,
    mapping: &spot_nav_examples::Mapping,
    out: Option<&std::path::Path>,
) -> Result<()> {
    let report = slam.report();
    out!(
        "scans       {} ({} keyframes, {} skipped)",
        report.scans,
        report.keyframes,
        report.skipped_out_of_order
            + report.skipped_non_finite_odometry
            + report.skipped_too_few_points
            + report.skipped_preparation
            + report.skipped_awaiting_velocity
            + report.skipped_non_finite_pose
    )?;
    out!(
        "loops       {} closed of {} tried; {} odometry fallbacks, {} odometry faults",
        report.loops_closed,
        report.loops_attempted,
        report.odometry_fallbacks,
        report.odometry_faults
    )?;
    let loop_max = report.loop_ms.iter().copied().fold(0.0, f64::max);
    let p99 = report.scan_ms_quantile(0.99);
    let slowest = report
        .scan_ms
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map_or(0, |(i, _)| i + 1);
    out!(
        "time        {:.2} ms mean, {p99:.2} ms p99, {:.2} ms max (scan {slowest}) per scan (odometry path); loop steps max {loop_max:.1} ms; {:.1} s in all",
        report.mean_scan_ms(),
        report.max_scan_ms(),
        mapping.seconds
    )?;
    if let Some(e) = &mapping.evaluation {
        out!(
            "accuracy    ATE {:.3} m, loop end-point error {:.3} m, drift {:.3} % of {:.1} m{}",
            e.ate.rmse,
            e.loop_end_point_error,
            100.0 * e.end_point.relative_drift,
            e.end_point.path_length,
            e.segments.as_ref().map_or_else(String::new, |s| format!(
                ", segments {:.3} %",
                100.0 * s.translation
            ))
        )?;
    }
    if let Some(dir) = out {
        std::fs::create_dir_all(dir)?;
        let map = slam.map(0.05)?;
        write_ply(dir.join("map.ply"), &map, PlyEncoding::BinaryLittleEndian)?;
        write_pcd(dir.join("map.pcd"), &map, PcdEncoding::Binary)?;
        write_tum(dir.join("trajectory.tum"), &mapping.estimate)?;
        write_g2o(dir.join("graph.g2o"), &G2oGraph::Se3(slam.graph().clone()))?;
        out!("wrote       {}", dir.display())?;
    }
    Ok(())
}
