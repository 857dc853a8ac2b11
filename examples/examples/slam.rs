//! Graph-SLAM on a simulated Spot or on any recording: a ROS 1 bag (`.bag`), a ROS 2 bag
//! (`.mcap`, or its folder), a KITTI sequence, a folder of PCD/PLY scans or a spot-nav
//! recording, detected from PATH. Point-to-plane ICP (or LOAM) odometry against the local map,
//! loop closure (point-to-point check, point-to-plane or LOAM refinement), Levenberg-Marquardt.
//! Prints what the recording holds, then scans, keyframes, loop closures, tracking health
//! (fallbacks, faults, skipped scans; a warning when tracking was lost on more than 5 % of the
//! scans), per-scan times and, with ground truth (the recording's, or `--ground-truth FILE`),
//! ATE, RPE per 100 m, end-point and height drift and each step's rotation error; writes the map
//! (PLY, PCD), the trajectory (TUM), the pose graph (g2o), the occupancy grid (PNG, ROS map) and
//! `summary.json` with `--out`.
//!
//! `cargo run --release --example slam -- [PATH] [--cloud-topic T] [--odom-topic T | --odom-frame F | --no-odometry] [--base-frame F] [--lidar-frame F] [--calibration tx,ty,tz,qx,qy,qz,qw] [--odometry FILE] [--blank-corridor] [--lidar-range M] [--out DIR] [--ground-truth FILE] [--summary FILE]`

use std::convert::Infallible;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, ValueEnum};
use gridmap::{UnknownCells, inflate};
use nalgebra::{Translation3, Vector2};
use posegraph::g2o::{G2oGraph, write_g2o};
use slam_core::io::{PcdEncoding, PlyEncoding, StampedPose, write_pcd, write_ply, write_tum};
use slam_core::{
    EdgeInformation, GraphSlam, GraphSlamConfig, MapRegistrator, Optimizer, Pose3,
    quaternion_from_xyzw,
};
use spot_adapter::nav::{NavigationMap, NavigationMapConfig};
use spot_adapter::pipelines::{loam_slam, point_to_plane_slam, scan_context_places, slam_config};
use spot_adapter::record::{
    BagConfig, DroppedPoints, ImuSource, OdometrySource, PointCloud2Config, ReadAhead,
    ReturnFilter, SampleSource, SourceConfig, TimeUnit, open_recording,
};
use spot_adapter::robot::Sample;
use spot_adapter::sim::{SimulatedSpot, SimulationConfig};
use spot_nav_examples::health::skip_reasons;
use spot_nav_examples::summary::{
    Accuracy, Input, Loops, Points, SlamSummary, Times, write_summary,
};
use spot_nav_examples::{
    GroundTruthFile, MappedScans, Mapping, Motion, Registration, Sensor, evaluate, map_samples,
    out, parse_numbers, print_tracking_health, value_name,
};

/// Obstacles in the grid picture are inflated by Spot's half width and a margin (metres).
const INFLATION: f64 = 0.30;

/// A per-point time unit, as `--time-unit` gives it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum TimeUnitArg {
    /// Seconds since the cloud's stamp (Velodyne).
    S,
    /// Nanoseconds since the cloud's stamp (Ouster, Livox).
    Ns,
    /// Seconds on the stamp's clock (Hesai).
    SAbsolute,
    /// Nanoseconds on the stamp's clock.
    NsAbsolute,
}

/// The information of odometry edges, as `--odometry-information` gives it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum OdometryInformation {
    /// Fixed 1 cm / 0.2° sigmas.
    Fixed,
    /// The fixed sigmas' covariance plus the registration's own.
    Registration,
}

/// Graph-SLAM on one simulated lap of a generated building, or on a recording.
///
/// PATH is a ROS 1 bag (.bag), a ROS 2 bag (.mcap, or its folder with metadata.yaml), a KITTI
/// sequence (velodyne/*.bin, times.txt, calib.txt, poses.txt as ground truth), a folder of PCD
/// or PLY scans (names that are numbers are stamps), or a spot-nav recording (index.txt). What
/// it holds is printed first. A recording without odometry runs LiDAR-only (every scan
/// registered against the local map from a constant-velocity guess). Prints scans, keyframes, loop closures, per-scan
/// times, tracking health (fallbacks, odometry faults, skipped scans by reason; a `warning:` on
/// stderr when more than 5 % of the scans fell back, i.e. tracking was lost there) and, when the
/// ground truth is known (the recording's, or `--ground-truth`), ATE, RPE per 100 m, end-point
/// and height drift, loop end-point error and each step's rotation error. With `--out` it
/// writes the map (`map.ply`, `map.pcd`), the body trajectory (`trajectory.tum`), the pose graph
/// (`graph.g2o`), the occupancy grid (`grid.png`, `map.yaml` + `map.pgm`) and `summary.json`,
/// all after the run: a failed run leaves nothing. Fails when the recording or the ground truth
/// cannot be read or the engine accepts no scan.
#[derive(Debug, Parser)]
#[command(name = "slam")]
#[allow(clippy::struct_excessive_bools)]
struct Args {
    /// A recording to replay instead of simulating (bag, KITTI, PCD/PLY folder, spot-nav).
    #[arg(value_name = "PATH")]
    recording: Option<PathBuf>,
    /// Bags: the `sensor_msgs/PointCloud2` topic (default: the only one).
    #[arg(long, value_name = "TOPIC")]
    cloud_topic: Option<String>,
    /// Bags: the `nav_msgs/Odometry` topic (default: the only one, else `/tf` from `odom`).
    #[arg(long, value_name = "TOPIC", conflicts_with_all = ["odom_frame", "no_odometry"])]
    odom_topic: Option<String>,
    /// Bags: take the odometry from /tf, from this frame to the body frame.
    #[arg(long, value_name = "FRAME", conflicts_with = "no_odometry")]
    odom_frame: Option<String>,
    /// Ignore the odometry (the recording's, or the simulated legs'): LiDAR-only, every scan
    /// registered against the local map from a constant-velocity guess.
    #[arg(long)]
    no_odometry: bool,
    /// Bags: the body frame (default: the odometry's child frame).
    #[arg(long, value_name = "FRAME")]
    base_frame: Option<String>,
    /// Bags: the LiDAR frame (default: the clouds' `frame_id`).
    #[arg(long, value_name = "FRAME")]
    lidar_frame: Option<String>,
    /// Bags: the `sensor_msgs/Imu` topic whose gyro gives each scan the body's orientation
    /// (default: the only one, when its frame is joined to the body frame).
    #[arg(long, value_name = "TOPIC", conflicts_with = "no_imu")]
    imu_topic: Option<String>,
    /// Bags: read no IMU.
    #[arg(long)]
    no_imu: bool,
    /// Scan folders: the LiDAR pose in the body frame, `tx,ty,tz,qx,qy,qz,qw` (default
    /// identity).
    #[arg(long, value_name = "POSE", value_parser = parse_pose, allow_negative_numbers = true)]
    calibration: Option<Pose3>,
    /// Scan folders: a TUM file of the body's odometry (default: none, LiDAR-only).
    #[arg(long, value_name = "FILE")]
    odometry: Option<PathBuf>,
    /// Points closer than this to the sensor (metres) are no-returns and removed.
    #[arg(long, value_name = "M", default_value_t = 0.1)]
    min_range: f32,
    /// Bags: the longest sweep (seconds) per-point times may span.
    #[arg(long, value_name = "S", default_value_t = 0.25)]
    max_scan_period: f64,
    /// Bags: the per-point time unit (default: decided from the first cloud).
    #[arg(long, value_enum, value_name = "UNIT")]
    time_unit: Option<TimeUnitArg>,
    /// Height of the LiDAR above the floor (metres), where the grid looks for the floor.
    #[arg(long, value_name = "H", default_value_t = 0.8)]
    lidar_height: f64,
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
    #[arg(long, conflicts_with = "recording")]
    skewed: bool,
    /// The simulated LiDAR: a VLP-16 (5 Hz) or an Ouster OS1-128 (10 Hz).
    #[arg(long, value_enum, value_name = "SENSOR", default_value_t = Sensor::Vlp16, conflicts_with = "recording")]
    sensor: Sensor,
    /// How the simulated LiDAR moves: Spot's walk, Spot turning corners in place at 1 rad/s,
    /// or a person carrying it (1.2 m/s, shaking, quick turns, a sample every 0.5 s).
    #[arg(long, value_enum, value_name = "MOTION", default_value_t = Motion::Walk, conflicts_with = "recording")]
    motion: Motion,
    /// Simulate a blank north corridor: plain walls and shut doors, where LiDAR odometry has
    /// little to hold on to along the corridor.
    #[arg(long, conflicts_with = "recording")]
    blank_corridor: bool,
    /// The simulated LiDAR's largest range (metres; default the sensor's: 100 for the VLP-16,
    /// 120 for the OS1-128).
    #[arg(
        long,
        value_name = "M",
        conflicts_with = "recording",
        allow_negative_numbers = true
    )]
    lidar_range: Option<f64>,
    /// Simulate a gyro on the body drifting this many degrees a second: each sample carries
    /// the orientation integrated from it, and without odometry the engine predicts the turn
    /// between two scans from it.
    #[arg(
        long,
        value_name = "DEG_PER_S",
        conflicts_with = "recording",
        allow_negative_numbers = true
    )]
    gyro_drift: Option<f64>,
    /// How stiff the odometry edges are: fixed sigmas (the default), or fixed sigmas softened
    /// where the registration was weak (see `EdgeInformation::FixedAndRegistration`).
    #[arg(long, value_enum, value_name = "KIND", default_value_t = OdometryInformation::Fixed)]
    odometry_information: OdometryInformation,
    /// The drift a loop may correct, as a fraction of the distance walked between its two
    /// keyframes (default 0.02; raise it for a front end that drifts more).
    #[arg(long, value_name = "RATE", allow_negative_numbers = true)]
    loop_drift_rate: Option<f64>,
    /// Turn off the engine's deskewing of scans with per-point times.
    #[arg(long)]
    no_deskew: bool,
    /// LiDAR-only: deskew each scan with the constant velocity of the last two scans only,
    /// without estimating the sweep's own motion (`GraphSlamConfig::sweep_motion`).
    #[arg(long)]
    no_sweep_motion: bool,
    /// Seek loops by position only: no Scan Context place recognition (on by default, so that
    /// loops are found however far the estimate drifted).
    #[arg(long)]
    no_place_recognition: bool,
    /// Write the map, trajectory, pose graph, grid and summary.json to this folder.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Recordings: the body's ground truth (`world_T_body`; a scan folder without
    /// `--calibration` has body = LiDAR). A TUM file (8 numbers a line: stamp tx ty tz qx qy qz
    /// qw, matched to the scans by stamp within 0.01 s) or KITTI poses (12 numbers a line, a
    /// row-major [R|t], one line per scan in the recording's order, stamped with the scans'
    /// stamps), told apart by the count of numbers on the first line whatever the file's
    /// extension. Replaces the recording's own ground truth (KITTI poses.txt, a spot-nav
    /// recording's) when it has one.
    #[arg(long, value_name = "FILE", requires = "recording")]
    ground_truth: Option<PathBuf>,
    /// Write summary.json (what `--out` writes) to this file too, or alone.
    #[arg(long, value_name = "FILE")]
    summary: Option<PathBuf>,
}

/// `tx,ty,tz,qx,qy,qz,qw` as a pose.
fn parse_pose(text: &str) -> Result<Pose3, String> {
    let v = parse_numbers::<7>(text)?;
    let q = quaternion_from_xyzw([v[3], v[4], v[5], v[6]])
        .ok_or_else(|| "the quaternion is not of unit length".to_owned())?;
    Ok(Pose3::from_parts(Translation3::new(v[0], v[1], v[2]), q))
}

fn main() -> ExitCode {
    spot_nav_examples::run(|| slam(&Args::parse()))
}

/// How to open the recording, from the options.
fn source_config(args: &Args) -> SourceConfig {
    let odometry = match (&args.odom_topic, &args.odom_frame, args.no_odometry) {
        (_, _, true) => OdometrySource::None,
        (Some(t), _, _) => OdometrySource::Topic(t.clone()),
        (_, Some(f), _) => OdometrySource::Tf {
            odom_frame: f.clone(),
        },
        _ => OdometrySource::Auto,
    };
    SourceConfig {
        bag: BagConfig {
            cloud_topic: args.cloud_topic.clone(),
            odometry,
            base_frame: args.base_frame.clone(),
            lidar_frame: args.lidar_frame.clone(),
            imu: match (&args.imu_topic, args.no_imu) {
                (_, true) => ImuSource::None,
                (Some(t), _) => ImuSource::Topic(t.clone()),
                _ => ImuSource::Auto,
            },
            cloud: PointCloud2Config {
                returns: ReturnFilter {
                    min_range: args.min_range,
                },
                max_scan_period: args.max_scan_period,
                time_unit: args.time_unit.map(|u| match u {
                    TimeUnitArg::S => TimeUnit::SecondsRelative,
                    TimeUnitArg::Ns => TimeUnit::NanosecondsRelative,
                    TimeUnitArg::SAbsolute => TimeUnit::SecondsAbsolute,
                    TimeUnitArg::NsAbsolute => TimeUnit::NanosecondsAbsolute,
                }),
            },
        },
        body_t_lidar: args.calibration,
        odometry: if args.no_odometry {
            None
        } else {
            args.odometry.clone()
        },
    }
}

/// Scans read ahead of the engine (each a few hundred kB to a few MB).
const READ_AHEAD: usize = 4;

fn slam(args: &Args) -> Result<()> {
    let mut config = slam_config();
    if args.no_deskew {
        config.deskew = false;
    }
    if args.no_sweep_motion {
        config.sweep_motion = false;
    }
    if let Some(rate) = args.loop_drift_rate {
        config.loop_max_drift_rate = rate;
    }
    // The engine's own fixed sigmas, with the registration's covariance added to them.
    if let (
        OdometryInformation::Registration,
        EdgeInformation::Fixed {
            translation_sigma,
            rotation_sigma,
        },
    ) = (args.odometry_information, config.odometry_information)
    {
        config.odometry_information = EdgeInformation::FixedAndRegistration {
            translation_sigma,
            rotation_sigma,
            scale: 1.0,
        };
    }
    if let Some(path) = &args.recording {
        replay(args, config, path)
    } else {
        let mut sim_config = SimulationConfig::with_seed(args.seed);
        sim_config.lidar = args.sensor.lidar();
        sim_config.motion = args.motion.profile();
        sim_config.motion_distortion = args.skewed;
        sim_config.building.blank_corridor = args.blank_corridor;
        if let Some(range) = args.lidar_range {
            sim_config.lidar.max_range = range;
        }
        if let Some(drift) = args.gyro_drift {
            // Checked here, in the unit given: the simulator names the setting in rad/s.
            anyhow::ensure!(
                drift.is_finite() && drift >= 0.0,
                "--gyro-drift {drift}: must be finite and non-negative (degrees a second)"
            );
        }
        sim_config.gyro_drift = args.gyro_drift.map(f64::to_radians);
        let sim = SimulatedSpot::corridor_loop(&sim_config)?;
        let body_t_lidar = sim.body_t_lidar();
        let truth = sim.ground_truth();
        let context = RunContext {
            input: Input {
                source: "simulator".to_owned(),
                path: None,
                description: simulation_description(args),
                odometry: if args.no_odometry {
                    "LiDAR-only"
                } else {
                    "simulated legs"
                }
                .to_owned(),
                ground_truth: Some("the simulator's".to_owned()),
            },
            truth: Truth::Stamped(&truth),
            lidar_only: args.no_odometry,
        };
        if args.no_odometry {
            out!("odometry    none: LiDAR-only, every scan registered against the local map")?;
        }
        let mut samples = sim.map(Ok::<Sample, Infallible>);
        backend(args, config, &mut samples, |_| None, body_t_lidar, &context)
    }
}

/// Replays the recording at `path` through the engine.
fn replay(args: &Args, config: GraphSlamConfig, path: &Path) -> Result<()> {
    let truth_file = args
        .ground_truth
        .as_deref()
        .map(GroundTruthFile::read)
        .transpose()?;
    let source = open_recording(path, &source_config(args))?;
    out!("{}", source.description)?;
    let own_truth = source.ground_truth.as_deref();
    let ground_truth = match (&truth_file, own_truth) {
        (Some(file), own) => {
            file.check_count(source.samples.len())?;
            let replacing = if own.is_some() {
                ", replacing the recording's own ground truth"
            } else {
                ""
            };
            out!("truth       {}{replacing}", file.describe())?;
            Some(format!("{}{replacing}", file.describe()))
        }
        (None, Some(_)) => Some("the recording's".to_owned()),
        (None, None) => None,
    };
    let lidar_only_run = !source.has_odometry || args.no_odometry;
    if lidar_only_run {
        out!("odometry    none: LiDAR-only, every scan registered against the local map")?;
    }
    let samples = source.samples;
    let context = RunContext {
        input: Input {
            source: "recording".to_owned(),
            path: Some(path.display().to_string()),
            description: source.description.clone(),
            odometry: if lidar_only_run {
                "LiDAR-only"
            } else {
                "recording"
            }
            .to_owned(),
            ground_truth,
        },
        truth: match (&truth_file, own_truth) {
            (Some(file), _) => Truth::File(file),
            (None, Some(own)) => Truth::Stamped(own),
            (None, None) => Truth::None,
        },
        lidar_only: lidar_only_run,
    };
    // Reading runs on a thread of its own, a few scans ahead of the engine.
    let mut samples = ReadAhead::new(samples, READ_AHEAD);
    backend(
        args,
        config,
        &mut samples,
        |s| Some(s.dropped_points()),
        source.body_t_lidar,
        &context,
    )
}

/// The simulated run in a few words, for `summary.json`.
fn simulation_description(args: &Args) -> String {
    let range = args
        .lidar_range
        .map_or_else(String::new, |r| format!(", LiDAR range {r} m"));
    let gyro = args
        .gyro_drift
        .map_or_else(String::new, |d| format!(", a gyro drifting {d} deg/s"));
    format!(
        "simulated corridor lap, seed {}{}{}{range}{gyro}",
        args.seed,
        if args.skewed { ", skewed scans" } else { "" },
        if args.blank_corridor {
            ", blank corridor"
        } else {
            ""
        }
    )
}

/// Where the ground truth comes from; a file of KITTI poses takes the scans' stamps once they
/// are read.
enum Truth<'a> {
    /// None known.
    None,
    /// The source's own, stamped.
    Stamped(&'a [StampedPose]),
    /// `--ground-truth`.
    File(&'a GroundTruthFile),
}

/// What a run reports besides the engine's own figures.
struct RunContext<'a> {
    input: Input,
    truth: Truth<'a>,
    /// Whether the scans go to the engine without their odometry.
    lidar_only: bool,
}

/// The engine `--registration` chooses, run on `samples`; `dropped` reads the points the
/// reader removed once they are all read.
fn backend<S, E>(
    args: &Args,
    config: GraphSlamConfig,
    samples: &mut S,
    dropped: fn(&S) -> Option<DroppedPoints>,
    body_t_lidar: Pose3,
    context: &RunContext<'_>,
) -> Result<()>
where
    S: ExactSizeIterator<Item = Result<Sample, E>>,
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
            if !args.no_place_recognition {
                slam = slam.with_place_recognizer(scan_context_places());
            }
            let run = map_samples(&mut slam, &mut *samples, label, context.lidar_only)?;
            let points = dropped(samples);
            finish(&slam, &run, &body_t_lidar, points, args, context)
        }
        Registration::Loam => {
            let mut slam = loam_slam(config)?;
            if !args.no_place_recognition {
                slam = slam.with_place_recognizer(scan_context_places());
            }
            let run = map_samples(&mut slam, &mut *samples, label, context.lidar_only)?;
            let points = dropped(samples);
            finish(&slam, &run, &body_t_lidar, points, args, context)
        }
    }
}

/// Evaluates the run against the ground truth (when known), prints its figures and writes the
/// outputs.
fn finish<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    slam: &GraphSlam<R, C, O>,
    run: &MappedScans,
    body_t_lidar: &Pose3,
    points: Option<DroppedPoints>,
    args: &Args,
    context: &RunContext<'_>,
) -> Result<()> {
    let truth = match context.truth {
        Truth::None => None,
        Truth::Stamped(poses) => Some(poses.to_vec()),
        Truth::File(file) => Some(file.stamped(&run.stamps)?),
    };
    let (evaluation, estimate) =
        evaluate(slam, body_t_lidar, truth.as_deref()).with_context(|| {
            format!(
                "evaluating {} scan poses against the ground truth ({})",
                slam.scan_trajectory().len(),
                context.input.ground_truth.as_deref().unwrap_or("none")
            )
        })?;
    let mapping = Mapping {
        estimate,
        evaluation,
        seconds: run.seconds,
    };
    let summary = report(slam, &mapping, points, args, context)?;
    if let Some(dir) = &args.out {
        write_outputs(slam, &mapping, dir, args.lidar_height, &summary)?;
    }
    if let Some(path) = &args.summary {
        write_summary(path, &summary)?;
        out!("wrote       {}", path.display())?;
    }
    Ok(())
}

/// Prints the run's figures; returns them as `summary.json` holds them.
fn report<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    slam: &GraphSlam<R, C, O>,
    mapping: &Mapping,
    points: Option<DroppedPoints>,
    args: &Args,
    context: &RunContext<'_>,
) -> Result<SlamSummary> {
    let report = slam.report();
    let skipped: usize = skip_reasons(report).iter().map(|&(_, n)| n).sum();
    out!(
        "scans       {} ({} keyframes, {skipped} skipped)",
        report.scans,
        report.keyframes
    )?;
    let loops = Loops::new(report);
    let rejected = if loops.rejected.is_empty() {
        "none".to_string()
    } else {
        loops
            .rejected
            .iter()
            .map(|(reason, n)| format!("{n} {reason}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    out!(
        "loops       {} closed of {} tried ({} by appearance; {} refused beyond the drift, {} weighted out by the back end; rejected: {rejected})",
        loops.closed,
        loops.tried,
        loops.by_appearance,
        loops.refused_beyond_drift,
        loops.weighted_out
    )?;
    let health = print_tracking_health(report)?;
    let time = Times::new(report, mapping.seconds);
    out!(
        "time        {:.2} ms mean, {:.2} ms p99, {:.2} ms max (scan {}) per scan (odometry path); loop steps max {:.1} ms; {:.1} s in all",
        time.scan_ms_mean,
        time.scan_ms_p99,
        time.scan_ms_max,
        time.slowest_scan,
        time.loop_ms_max,
        time.seconds
    )?;
    let points = points.map(|p| Points {
        no_return: p.no_return,
        non_finite: p.non_finite,
    });
    if let Some(p) = &points {
        out!(
            "points      {} no-return and {} non-finite points removed",
            p.no_return,
            p.non_finite
        )?;
    }
    let accuracy = mapping.evaluation.as_ref().map(Accuracy::new);
    if let Some(a) = &accuracy {
        print_accuracy(a)?;
    }
    Ok(SlamSummary {
        input: context.input.clone(),
        registration: value_name(&args.registration),
        scans: report.scans,
        keyframes: report.keyframes,
        loops,
        tracking: health,
        time,
        points,
        accuracy,
    })
}

/// The accuracy lines: ATE and drifts, KITTI's RPE, each step's rotation error.
fn print_accuracy(a: &Accuracy) -> Result<()> {
    let drift = a.end_point_drift_percent.map_or_else(
        || "the truth did not move".to_owned(),
        |d| format!("{d:.3} % of {:.1} m", a.path_length_m),
    );
    let segments = a
        .segment_drift_percent
        .map_or_else(String::new, |s| format!(", segments (10-50 m) {s:.3} %"));
    out!(
        "accuracy    ATE {:.3} m (RMSE after SE(3) alignment, {} poses), end point {:.3} m ({drift}), height drift {:+.3} m, loop end-point error {:.3} m{segments}",
        a.ate_m,
        a.ate_pairs,
        a.end_point_error_m,
        a.height_drift_m,
        a.loop_end_point_error_m
    )?;
    match (a.rpe_percent, a.rpe_rotation_deg_per_100m) {
        (Some(t), Some(r)) => {
            let lengths = match (
                a.rpe_segment_lengths_m.first(),
                a.rpe_segment_lengths_m.last(),
            ) {
                (Some(first), Some(last)) if first < last => format!("{first}-{last} m"),
                (Some(first), _) => format!("{first} m"),
                _ => String::new(),
            };
            let which = if a.rpe_kitti_lengths {
                format!("KITTI's segments of {lengths}")
            } else {
                format!(
                    "the path, {:.1} m, is shorter than KITTI's 100 m segments: over {lengths} instead",
                    a.path_length_m
                )
            };
            out!(
                "rpe         {t:.3} % per 100 m, {r:.3} deg per 100 m ({which}; {} segments)",
                a.rpe_segments
            )?;
        }
        _ => out!(
            "rpe         none: the path ({:.3} m) is too short for any segment",
            a.path_length_m
        )?,
    }
    out!(
        "steps       {} of {} steps with more than 2 deg of rotation error against the truth, {} with more than 5 deg (largest {:.2} deg)",
        a.steps_over_2_deg,
        a.steps,
        a.steps_over_5_deg,
        a.step_rotation_error_max_deg
    )
}

/// The map, trajectory, graph, grid and summary in `dir` (made here, after the run).
fn write_outputs<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    slam: &GraphSlam<R, C, O>,
    mapping: &Mapping,
    dir: &Path,
    lidar_height: f64,
    summary: &SlamSummary,
) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    write_summary(&dir.join("summary.json"), summary)?;
    let map = slam.map(0.05)?;
    write_ply(dir.join("map.ply"), &map, PlyEncoding::BinaryLittleEndian)?;
    write_pcd(dir.join("map.pcd"), &map, PcdEncoding::Binary)?;
    write_tum(dir.join("trajectory.tum"), &mapping.estimate)?;
    write_g2o(dir.join("graph.g2o"), &G2oGraph::Se3(slam.graph().clone()))?;
    let scans: Vec<_> = slam.keyframe_scans().collect();
    match NavigationMap::from_scans(&scans, lidar_height, &NavigationMapConfig::default()) {
        Ok(navigation) => {
            let grid = navigation.occupancy();
            let planning = grid.to_planning_grid(UnknownCells::Free);
            let inflated = inflate(&planning, INFLATION)?;
            let path: Vec<_> = mapping
                .estimate
                .iter()
                .filter_map(|p| {
                    let t = p.pose.translation.vector;
                    planning.cell_at(Vector2::new(t.x, t.y))
                })
                .collect();
            gridmap::write_png(dir.join("grid.png"), grid, Some(&inflated), &path, &[])?;
            gridmap::write_ros_map(grid, dir.join("map.yaml"))?;
            out!(
                "wrote       {}: map.ply, map.pcd, trajectory.tum, graph.g2o, grid.png, map.yaml + map.pgm, summary.json",
                dir.display()
            )?;
        }
        Err(e) => {
            eprintln!("note: no grid ({e:#}); is --lidar-height {lidar_height} m right?");
            out!(
                "wrote       {}: map.ply, map.pcd, trajectory.tum, graph.g2o, summary.json",
                dir.display()
            )?;
        }
    }
    Ok(())
}
