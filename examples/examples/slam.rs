//! Graph-SLAM on a simulated Spot or on any recording: a ROS 1 bag (`.bag`), a ROS 2 bag
//! (`.mcap`, or its folder), a KITTI sequence, a folder of PCD/PLY scans or a spot-nav
//! recording, detected from PATH. Point-to-plane ICP (or LOAM) odometry against the local map,
//! loop closure (point-to-point check, point-to-plane or LOAM refinement), Levenberg-Marquardt.
//! Prints what the recording holds, then scans, keyframes, loop closures, per-scan times and,
//! with ground truth, ATE, drift and loop end-point error; writes the map (PLY, PCD), the
//! trajectory (TUM), the pose graph (g2o) and the occupancy grid (PNG, ROS map) with `--out`.
//!
//! `cargo run --release --example slam -- [PATH] [--cloud-topic T] [--odom-topic T | --odom-frame F | --no-odometry] [--base-frame F] [--lidar-frame F] [--calibration tx,ty,tz,qx,qy,qz,qw] [--odometry FILE] [--blank-corridor] [--lidar-range M] [--out DIR]`

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
use spot_adapter::nav::{NavigationMap, NavigatorConfig};
use spot_adapter::pipelines::{loam_slam, point_to_plane_slam, scan_context_places, slam_config};
use spot_adapter::record::{
    BagConfig, ImuSource, OdometrySource, PointCloud2Config, ReadAhead, ReturnFilter,
    SampleSource, SourceConfig, TimeUnit, open_recording,
};
use spot_adapter::robot::Sample;
use spot_adapter::sim::{SimulatedSpot, SimulationConfig};
use spot_nav_examples::{Motion, Registration, Sensor, map_and_evaluate, out, parse_numbers};

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
/// times and, when the ground truth is known, ATE, drift and loop end-point error. With `--out`
/// it writes the map (`map.ply`, `map.pcd`), the body trajectory (`trajectory.tum`), the pose
/// graph (`graph.g2o`) and the occupancy grid (`grid.png`, `map.yaml` + `map.pgm`), all after
/// the run: a failed run leaves nothing. Fails when the recording cannot be read or the engine
/// accepts no scan.
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
    /// Seek loops by position only: no Scan Context place recognition (on by default, so that
    /// loops are found however far the estimate drifted).
    #[arg(long)]
    no_place_recognition: bool,
    /// Write the map, trajectory, pose graph and grid to this folder.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
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
        let source = open_recording(path, &source_config(args))?;
        out!("{}", source.description)?;
        let lidar_only = !source.has_odometry || args.no_odometry;
        if lidar_only {
            out!("odometry    none: LiDAR-only, every scan registered against the local map")?;
        }
        let samples = source.samples;
        // Reading runs on a thread of its own, a few scans ahead of the engine.
        let mut samples = ReadAhead::new(samples, READ_AHEAD);
        backend(
            args,
            config,
            &mut samples,
            source.body_t_lidar,
            source.ground_truth.as_deref(),
            lidar_only,
        )?;
        let dropped = samples.dropped_points();
        out!(
            "points      {} no-return and {} non-finite points removed",
            dropped.no_return,
            dropped.non_finite
        )?;
        Ok(())
    } else {
        let mut sim_config = SimulationConfig::with_seed(args.seed);
        sim_config.lidar = args.sensor.lidar();
        sim_config.motion = args.motion.profile();
        sim_config.motion_distortion = args.skewed;
        sim_config.building.blank_corridor = args.blank_corridor;
        if let Some(range) = args.lidar_range {
            sim_config.lidar.max_range = range;
        }
        let sim = SimulatedSpot::corridor_loop(&sim_config)?;
        let body_t_lidar = sim.body_t_lidar();
        let truth = sim.ground_truth();
        if args.no_odometry {
            out!("odometry    none: LiDAR-only, every scan registered against the local map")?;
        }
        let samples = sim.map(Ok::<Sample, Infallible>);
        backend(
            args,
            config,
            samples,
            body_t_lidar,
            Some(&truth),
            args.no_odometry,
        )
    }
}

/// The engine `--registration` chooses, run on `samples`.
fn backend<I, E>(
    args: &Args,
    config: GraphSlamConfig,
    samples: I,
    body_t_lidar: Pose3,
    truth: Option<&[StampedPose]>,
    lidar_only: bool,
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
            if !args.no_place_recognition {
                slam = slam.with_place_recognizer(scan_context_places());
            }
            let mapping =
                map_and_evaluate(&mut slam, samples, &body_t_lidar, truth, label, lidar_only)?;
            report(&slam, &mapping, args)
        }
        Registration::Loam => {
            let mut slam = loam_slam(config)?;
            if !args.no_place_recognition {
                slam = slam.with_place_recognizer(scan_context_places());
            }
            let mapping =
                map_and_evaluate(&mut slam, samples, &body_t_lidar, truth, label, lidar_only)?;
            report(&slam, &mapping, args)
        }
    }
}

/// Print the run's figures and write the outputs to `out`.
fn report<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    slam: &GraphSlam<R, C, O>,
    mapping: &spot_nav_examples::Mapping,
    args: &Args,
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
        "loops       {} closed of {} tried ({} by appearance; {} refused beyond the drift, {} weighted out by the back end); {} odometry fallbacks, {} odometry faults",
        report.loops_closed,
        report.loops_attempted,
        report.place_loops_closed,
        report.loops_beyond_drift,
        report.loops_weighted_out,
        report.fallbacks(),
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
    if let Some(dir) = &args.out {
        write_outputs(slam, mapping, dir, args.lidar_height)?;
    }
    Ok(())
}

/// The map, trajectory, graph and grid in `dir` (made here, after the run).
fn write_outputs<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    slam: &GraphSlam<R, C, O>,
    mapping: &spot_nav_examples::Mapping,
    dir: &Path,
    lidar_height: f64,
) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let map = slam.map(0.05)?;
    write_ply(dir.join("map.ply"), &map, PlyEncoding::BinaryLittleEndian)?;
    write_pcd(dir.join("map.pcd"), &map, PcdEncoding::Binary)?;
    write_tum(dir.join("trajectory.tum"), &mapping.estimate)?;
    write_g2o(dir.join("graph.g2o"), &G2oGraph::Se3(slam.graph().clone()))?;
    let scans: Vec<_> = slam.keyframe_scans().collect();
    match NavigationMap::from_scans(&scans, lidar_height, &NavigatorConfig::default()) {
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
                "wrote       {}: map.ply, map.pcd, trajectory.tum, graph.g2o, grid.png, map.yaml + map.pgm",
                dir.display()
            )?;
        }
        Err(e) => {
            eprintln!("note: no grid ({e:#}); is --lidar-height {lidar_height} m right?");
            out!(
                "wrote       {}: map.ply, map.pcd, trajectory.tum, graph.g2o",
                dir.display()
            )?;
        }
    }
    Ok(())
}
