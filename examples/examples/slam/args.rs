//! The command line: `Args`, its value types, and the recording's source settings from it.

use std::path::PathBuf;

use anyhow::Result;
use clap::{Parser, ValueEnum};
use nalgebra::Translation3;
use serde::{Deserialize, Serialize};
use slam_core::GraphSlamConfig;
use slam_core::{Pose3, quaternion_from_xyzw};
use spot_adapter::pipelines::{point_to_plane_tracker, slam_config};
use spot_adapter::record::{
    BagConfig, ImuSource, OdometrySource, PointCloud2Config, ReturnFilter, SourceConfig, TimeUnit,
};
use spot_adapter::registration::PointToPlaneIcp;
use spot_nav_examples::{Motion, Registration, Sensor, SettingsArgs, parse_numbers};

/// A per-point time unit, as `--time-unit` gives it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum TimeUnitArg {
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
pub(crate) enum OdometryInformation {
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
pub(crate) struct Args {
    /// A recording to replay instead of simulating (bag, KITTI, PCD/PLY folder, spot-nav).
    #[arg(value_name = "PATH")]
    pub(crate) recording: Option<PathBuf>,
    /// Bags: the `sensor_msgs/PointCloud2` topic (default: the only one).
    #[arg(long, value_name = "TOPIC")]
    pub(crate) cloud_topic: Option<String>,
    /// Bags: the `nav_msgs/Odometry` topic (default: the only one, else `/tf` from `odom`).
    #[arg(long, value_name = "TOPIC", conflicts_with_all = ["odom_frame", "no_odometry"])]
    pub(crate) odom_topic: Option<String>,
    /// Bags: take the odometry from /tf, from this frame to the body frame.
    #[arg(long, value_name = "FRAME", conflicts_with = "no_odometry")]
    pub(crate) odom_frame: Option<String>,
    /// Ignore the odometry (the recording's, or the simulated legs'): LiDAR-only, every scan
    /// registered against the local map from a constant-velocity guess.
    #[arg(long)]
    pub(crate) no_odometry: bool,
    /// Bags: the body frame (default: the odometry's child frame).
    #[arg(long, value_name = "FRAME")]
    pub(crate) base_frame: Option<String>,
    /// Bags: the LiDAR frame (default: the clouds' `frame_id`).
    #[arg(long, value_name = "FRAME")]
    pub(crate) lidar_frame: Option<String>,
    /// Bags: the `sensor_msgs/Imu` topic whose gyro gives each scan the body's orientation
    /// (default: the only one, when its frame is joined to the body frame).
    #[arg(long, value_name = "TOPIC", conflicts_with = "no_imu")]
    pub(crate) imu_topic: Option<String>,
    /// Bags: read no IMU.
    #[arg(long)]
    pub(crate) no_imu: bool,
    /// Scan folders: the LiDAR pose in the body frame, `tx,ty,tz,qx,qy,qz,qw` (default
    /// identity).
    #[arg(long, value_name = "POSE", value_parser = parse_pose, allow_negative_numbers = true)]
    pub(crate) calibration: Option<Pose3>,
    /// Scan folders: a TUM file of the body's odometry (default: none, LiDAR-only).
    #[arg(long, value_name = "FILE")]
    pub(crate) odometry: Option<PathBuf>,
    /// Points closer than this to the sensor (metres) are no-returns and removed.
    #[arg(long, value_name = "M", default_value_t = 0.1)]
    pub(crate) min_range: f32,
    /// Bags: the longest sweep (seconds) per-point times may span.
    #[arg(long, value_name = "S", default_value_t = 0.25)]
    pub(crate) max_scan_period: f64,
    /// Bags: the per-point time unit (default: decided from the first cloud).
    #[arg(long, value_enum, value_name = "UNIT")]
    pub(crate) time_unit: Option<TimeUnitArg>,
    /// Height of the LiDAR above the floor (metres), where the grid looks for the floor.
    #[arg(long, value_name = "H", default_value_t = 0.8)]
    pub(crate) lidar_height: f64,
    /// Seed of the simulated building, sensor noise and odometry drift (without a recording).
    #[arg(
        long,
        value_name = "N",
        allow_negative_numbers = true,
        default_value_t = 1
    )]
    pub(crate) seed: u64,
    /// Odometry and loop refinement backend.
    #[arg(long, value_enum, default_value_t = Registration::PointToPlane)]
    pub(crate) registration: Registration,
    /// Simulate scans cast while walking (motion distortion, 12 cm per sweep).
    #[arg(long, conflicts_with = "recording")]
    pub(crate) skewed: bool,
    /// The simulated LiDAR: a VLP-16 (5 Hz) or an Ouster OS1-128 (10 Hz).
    #[arg(long, value_enum, value_name = "SENSOR", default_value_t = Sensor::Vlp16, conflicts_with = "recording")]
    pub(crate) sensor: Sensor,
    /// How the simulated LiDAR moves: Spot's walk, Spot turning corners in place at 1 rad/s,
    /// or a person carrying it (1.2 m/s, shaking, quick turns, a sample every 0.5 s).
    #[arg(long, value_enum, value_name = "MOTION", default_value_t = Motion::Walk, conflicts_with = "recording")]
    pub(crate) motion: Motion,
    /// Floors of the simulated building (1 to 3). Above one, Spot walks a lap of the ground
    /// floor, climbs the stairs, walks a lap of each floor above and comes back down; the
    /// report adds the height error on each floor.
    #[arg(
        long,
        value_name = "N",
        default_value_t = 1,
        conflicts_with = "recording"
    )]
    pub(crate) floors: usize,
    /// With `--floors`: every floor a copy of the ground floor's plan (the same rooms and
    /// furniture), the hard case for place recognition; by default each floor above has rooms
    /// of its own round the same corridor and core.
    #[arg(long, requires = "floors", conflicts_with = "recording")]
    pub(crate) repeat_floor_plan: bool,
    /// Simulate a blank north corridor: plain walls and shut doors, where LiDAR odometry has
    /// little to hold on to along the corridor.
    #[arg(long, conflicts_with = "recording")]
    pub(crate) blank_corridor: bool,
    /// The simulated LiDAR's largest range (metres; default the sensor's: 100 for the VLP-16,
    /// 120 for the OS1-128).
    #[arg(
        long,
        value_name = "M",
        conflicts_with = "recording",
        allow_negative_numbers = true
    )]
    pub(crate) lidar_range: Option<f64>,
    /// Simulate a gyro on the body drifting this many degrees a second: each sample carries
    /// the orientation integrated from it, and without odometry the engine predicts the turn
    /// between two scans from it.
    #[arg(
        long,
        value_name = "DEG_PER_S",
        conflicts_with = "recording",
        allow_negative_numbers = true
    )]
    pub(crate) gyro_drift: Option<f64>,
    /// How stiff the odometry edges are: fixed sigmas, or fixed sigmas softened where the
    /// registration was weak (see `EdgeInformation::FixedAndRegistration`) [default: the
    /// settings' `slam.odometry_information`, fixed].
    #[arg(long, value_enum, value_name = "KIND")]
    pub(crate) odometry_information: Option<OdometryInformation>,
    /// The drift a loop may correct, as a fraction of the distance walked between its two
    /// keyframes (default 0.02; raise it for a front end that drifts more).
    #[arg(long, value_name = "RATE", allow_negative_numbers = true)]
    pub(crate) loop_drift_rate: Option<f64>,
    /// Turn off the engine's deskewing of scans with per-point times.
    #[arg(long)]
    pub(crate) no_deskew: bool,
    /// LiDAR-only: deskew each scan with the constant velocity of the last two scans only,
    /// without estimating the sweep's own motion (`GraphSlamConfig::sweep_motion`).
    #[arg(long)]
    pub(crate) no_sweep_motion: bool,
    /// Seek loops by position only: no Scan Context place recognition (on by default, so that
    /// loops are found however far the estimate drifted).
    #[arg(long)]
    pub(crate) no_place_recognition: bool,
    /// Point-to-plane: the voxel (metres) the tracker's local map is thinned to, whatever the
    /// sensor (by default 0.15 for scans of at most 60,000 points, such as a VLP-16's, and 0.2
    /// for denser ones). Finer holds the height over stairs (0.1: the upper floor of `--floors
    /// 2` seeds 1-6 within 1.6 cm, where 0.2 leaves seed 3's 5.9 cm low on the mean) at up to
    /// twice the time a scan; 0 keeps every point (the map then rebuilt whole at each keyframe).
    #[arg(long, value_name = "M", allow_hyphen_values = true)]
    pub(crate) tracker_map_voxel: Option<f32>,
    /// Keep only the newest N keyframes' scans and registration points in memory and the older
    /// ones in a file in the system's temporary folder (removed at the end), for long
    /// recordings; by default every keyframe stays in memory.
    #[arg(long, value_name = "N")]
    pub(crate) keyframes_in_memory: Option<usize>,
    /// Write the map, trajectory, pose graph, grid and summary.json to this folder.
    #[arg(long, value_name = "DIR")]
    pub(crate) out: Option<PathBuf>,
    /// Recordings: the body's ground truth (`world_T_body`; a scan folder without
    /// `--calibration` has body = LiDAR). A TUM file (8 numbers a line: stamp tx ty tz qx qy qz
    /// qw, matched to the scans by stamp within 0.01 s) or KITTI poses (12 numbers a line, a
    /// row-major [R|t], one line per scan in the recording's order, stamped with the scans'
    /// stamps), told apart by the count of numbers on the first line whatever the file's
    /// extension. Replaces the recording's own ground truth (KITTI poses.txt, a spot-nav
    /// recording's) when it has one.
    #[arg(long, value_name = "FILE", requires = "recording")]
    pub(crate) ground_truth: Option<PathBuf>,
    /// Write summary.json (what `--out` writes) to this file too, or alone.
    #[arg(long, value_name = "FILE")]
    pub(crate) summary: Option<PathBuf>,
    /// The engine's settings (`[slam]`, a `GraphSlamConfig`): `--config FILE`, `--print-config`.
    #[command(flatten)]
    pub(crate) settings: SettingsArgs,
}

impl Args {
    /// The point-to-plane tracker with `--tracker-map-voxel` applied.
    ///
    /// # Errors
    /// The option given with LOAM, or a voxel the tracker refuses (named by its setting).
    pub(crate) fn tracker(&self) -> Result<PointToPlaneIcp> {
        let mut tracker = point_to_plane_tracker();
        let Some(voxel) = self.tracker_map_voxel else {
            return Ok(tracker);
        };
        anyhow::ensure!(
            matches!(self.registration, Registration::PointToPlane),
            "--tracker-map-voxel is a point-to-plane setting (LOAM keeps its own feature maps)"
        );
        tracker.config.target_voxel = voxel;
        // The voxel asked for, whatever the sensor.
        tracker.config.sparse_scan_points = 0;
        tracker
            .config
            .validate()
            .map_err(|e| anyhow::anyhow!("--tracker-map-voxel {voxel}: {e}"))?;
        Ok(tracker)
    }
}

/// The settings file of `slam` (`--config`, `--print-config`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub(crate) struct Settings {
    /// The engine's settings; by default spot-adapter's `slam_config()`.
    pub(crate) slam: GraphSlamConfig,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            slam: slam_config(),
        }
    }
}

/// `tx,ty,tz,qx,qy,qz,qw` as a pose.
pub(crate) fn parse_pose(text: &str) -> Result<Pose3, String> {
    let v = parse_numbers::<7>(text)?;
    let q = quaternion_from_xyzw([v[3], v[4], v[5], v[6]])
        .ok_or_else(|| "the quaternion is not of unit length".to_owned())?;
    Ok(Pose3::from_parts(Translation3::new(v[0], v[1], v[2]), q))
}

/// How to open the recording, from the options.
pub(crate) fn source_config(args: &Args) -> SourceConfig {
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
