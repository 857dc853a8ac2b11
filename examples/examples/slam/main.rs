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
//! `cargo run --release --example slam -- [PATH] [--cloud-topic T] [--odom-topic T | --odom-frame F | --no-odometry] [--base-frame F] [--lidar-frame F] [--calibration tx,ty,tz,qx,qy,qz,qw] [--odometry FILE] [--blank-corridor] [--lidar-range M] [--out DIR] [--ground-truth FILE] [--summary FILE] [--config FILE] [--print-config]`

mod args;
mod floor_grids;
mod report;

use std::convert::Infallible;
use std::path::Path;
use std::process::ExitCode;

use anyhow::Result;
use clap::Parser;
use slam_core::io::StampedPose;
use slam_core::{EdgeInformation, GraphSlamConfig, Pose3};
use spot_adapter::pipelines::{loam_slam, point_to_plane_slam_with, scan_context_places};
use spot_adapter::record::{DroppedPoints, ReadAhead, SampleSource, open_recording};
use spot_adapter::robot::Sample;
use spot_adapter::sim::{SimulatedSpot, SimulationConfig};
use spot_nav_examples::summary::Input;
use spot_nav_examples::{GroundTruthFile, Registration, map_samples, out, print_settings};

use args::{Args, OdometryInformation, Settings, source_config};
use report::finish;

fn main() -> ExitCode {
    spot_nav_examples::run(|| slam(&Args::parse()))
}

/// Scans read ahead of the engine (each a few hundred kB to a few MB).
const READ_AHEAD: usize = 4;

fn slam(args: &Args) -> Result<()> {
    let mut config = args.settings.load(Settings::default())?.slam;
    if args.no_deskew {
        config.deskew = false;
    }
    if args.no_sweep_motion {
        config.sweep_motion = false;
    }
    if let Some(rate) = args.loop_drift_rate {
        config.loop_max_drift_rate = rate;
    }
    config.odometry_information = match (args.odometry_information, config.odometry_information) {
        // The settings' fixed sigmas, with the registration's covariance added to them ...
        (
            Some(OdometryInformation::Registration),
            EdgeInformation::Fixed {
                translation_sigma,
                rotation_sigma,
            },
        ) => EdgeInformation::FixedAndRegistration {
            translation_sigma,
            rotation_sigma,
            scale: 1.0,
        },
        // ... or without it.
        (
            Some(OdometryInformation::Fixed),
            EdgeInformation::FixedAndRegistration {
                translation_sigma,
                rotation_sigma,
                ..
            },
        ) => EdgeInformation::Fixed {
            translation_sigma,
            rotation_sigma,
        },
        (_, information) => information,
    };
    if let Some(format) = args.settings.print_config {
        return print_settings(&Settings { slam: config }, format);
    }
    // A bad tracker setting fails before the recording is read or the building made.
    args.tracker()?;
    if let Some(path) = &args.recording {
        replay(args, config, path)
    } else {
        let mut sim_config = SimulationConfig::with_seed(args.seed);
        sim_config.lidar = args.sensor.lidar();
        sim_config.motion = args.motion.profile();
        sim_config.motion_distortion = args.skewed;
        sim_config.building.blank_corridor = args.blank_corridor;
        sim_config.building.floors = args.floors;
        sim_config.building.repeat_floor_plan = args.repeat_floor_plan;
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
        let sim = SimulatedSpot::floors_tour(&sim_config)?;
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
    let walk = if args.floors > 1 {
        format!("tour of {} floors by the stairs", args.floors)
    } else {
        "corridor lap".to_owned()
    };
    format!(
        "simulated {walk}, seed {}{}{}{range}{gyro}",
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
            let mut slam = point_to_plane_slam_with(config, args.tracker()?)?;
            if !args.no_place_recognition {
                slam = slam.with_place_recognizer(scan_context_places());
            }
            if let Some(n) = args.keyframes_in_memory {
                slam = slam.with_keyframe_store(&std::env::temp_dir(), n)?;
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
            if let Some(n) = args.keyframes_in_memory {
                slam = slam.with_keyframe_store(&std::env::temp_dir(), n)?;
            }
            let run = map_samples(&mut slam, &mut *samples, label, context.lidar_only)?;
            let points = dropped(samples);
            finish(&slam, &run, &body_t_lidar, points, args, context)
        }
    }
}
