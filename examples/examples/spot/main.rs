//! Walk a real Spot to a goal over gRPC (needs `--features grpc`).
//!
//! ```text
//! SPOT_PASSWORD=... cargo run --release --features grpc --example spot -- \
//!     --host 192.168.80.3 --ca robot-ca.pem --user admin --password-env SPOT_PASSWORD --goal 3,0
//! ```
//!
//! Connects (login, directory, time sync, body lease) and checks the robot state: it refuses to
//! start while an E-stop is asserted, when no E-stop endpoint is registered, or with a system
//! or behaviour fault, naming what to do. It powers the motors on if they are off and stands
//! Spot up (each step with a timeout), and only then walks. It then either loads `--map` (a PCD cloud
//! in the map frame, with the robot's pose in it given by `--start X,Y,YAW`) or maps where it
//! stands: Spot turns once in place at 0.3 rad/s and the scans at their odometry poses make the
//! map (the map frame is then the odometry frame). The goal is in the frame of the body where
//! the run started (x forward, y left, metres) without `--map`, in the map frame with it. The
//! navigator then walks Spot there; it stops on arrival and on every fault. With `--sit` Spot
//! sits and powers off at the end. The password is read from the environment variable named
//! by `--password-env`, never from the command line.
//!
//! On Ctrl-C, on every error and on a panic Spot is sent a stop and the lease is returned
//! (Ctrl-C exits 130; a second Ctrl-C exits at once). A robot whose odometry does not change
//! for 3 s while commanded to move, or that refuses a command, stops the run with the reason.
//!
//! Keep the e-stop in hand. Speeds are capped by `--max-speed` (default 0.5 m/s).

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use anyhow::{Context, Result, bail};
use clap::Parser;
use nalgebra::{Point3, Vector2, Vector3};
use slam_core::{PointCloud, Pose3};
use spot_adapter::grpc::{Credentials, MotorPower, SpotClient, SpotConfig, SpotError};
use spot_adapter::nav::{DriveOutcome, NavigationMap, Navigator, NavigatorConfig, drive};
use spot_adapter::pipelines::point_to_plane_localiser;
use spot_adapter::robot::{MobilityCommand, Robot, VelocityCommand};
use spot_nav_examples::{parse_goal, parse_numbers};

/// Walk a real Spot to a goal.
#[derive(Debug, Parser)]
struct Args {
    /// The robot's address.
    #[arg(long)]
    host: String,
    /// The robot's TLS port.
    #[arg(long, default_value_t = 443)]
    port: u16,
    /// The CA certificate (PEM) the robot's certificate chains to.
    #[arg(long)]
    ca: PathBuf,
    /// The user to log in as.
    #[arg(long)]
    user: String,
    /// The environment variable that holds the password.
    #[arg(long, default_value = "SPOT_PASSWORD")]
    password_env: String,
    /// The goal X,Y (metres): in the start body frame, or in the map frame with --map.
    #[arg(long, value_parser = parse_goal)]
    goal: Vector2<f64>,
    /// A map cloud (PCD) to navigate on instead of mapping in place.
    #[arg(long)]
    map: Option<PathBuf>,
    /// The robot's pose X,Y,YAW (metres, radians) in the --map frame.
    #[arg(long, value_parser = parse_numbers::<3>, default_value = "0,0,0")]
    start: [f64; 3],
    /// The largest forward speed, m/s.
    #[arg(long, default_value_t = 0.5)]
    max_speed: f64,
    /// The most navigator cycles (scans) before giving up.
    #[arg(long, default_value_t = 3000)]
    cycles: usize,
    /// At the end, sit and power the motors off.
    #[arg(long)]
    sit: bool,
}

/// The exit status after Ctrl-C (128 + SIGINT), as a shell reports it.
const INTERRUPTED: u8 = 130;

/// A flag raised by the first Ctrl-C (the run then stops the robot, returns the lease and
/// exits); a second Ctrl-C exits at once.
fn interrupt_flag() -> Result<Arc<AtomicBool>> {
    let flag = Arc::new(AtomicBool::new(false));
    let raised = Arc::clone(&flag);
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .context("starting the Ctrl-C handler")?;
    // Polled once here, so the handler is registered before any step that moves the robot:
    // no later Ctrl-C kills the process unhandled.
    let mut first = runtime
        .block_on(async {
            let mut first = Box::pin(tokio::signal::ctrl_c());
            if let Ok(Err(error)) = tokio::time::timeout(Duration::ZERO, &mut first).await {
                return Err(error);
            }
            Ok(first)
        })
        .context("installing the Ctrl-C handler")?;
    std::thread::spawn(move || {
        runtime.block_on(async {
            while (&mut first).await.is_ok() {
                if raised.swap(true, Ordering::Relaxed) {
                    eprintln!("interrupted twice: exiting without stopping the robot");
                    std::process::exit(i32::from(INTERRUPTED));
                }
                eprintln!("interrupted: stopping the robot and returning the lease");
                first = Box::pin(tokio::signal::ctrl_c());
            }
        });
    });
    Ok(flag)
}

/// From the robot state: refuse to start while E-stopped or faulted, power the motors on if
/// they are off, and stand.
fn bring_up(spot: &SpotClient, interrupt: &AtomicBool) -> Result<()> {
    let status = spot.status().context("reading the robot state")?;
    status
        .check_ready()
        .context("the robot is not ready to move")?;
    if status.motor_power == MotorPower::On {
        println!("motors already on");
    } else {
        println!("powering the motors on (motors {:?})", status.motor_power);
        spot.power_on()?;
    }
    if interrupt.load(Ordering::Relaxed) {
        return Err(SpotError::Interrupted.into());
    }
    println!("standing up");
    spot.stand()?;
    if interrupt.load(Ordering::Relaxed) {
        return Err(SpotError::Interrupted.into());
    }
    Ok(())
}

/// Turn once in place, keeping every scan at its odometry pose: `(odom_T_lidar, cloud)`.
fn map_in_place(spot: &mut SpotClient) -> Result<Vec<(Pose3, PointCloud)>> {
    let mut scans = Vec::new();
    let (mut turned, mut last_yaw) = (0.0, None::<f64>);
    while turned < std::f64::consts::TAU {
        let sample = spot.next_sample()?;
        let yaw = sample.odom_t_body.rotation.euler_angles().2;
        if let Some(last) = last_yaw {
            turned += (yaw - last + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
        }
        last_yaw = Some(yaw);
        scans.push((sample.odom_t_lidar(), sample.cloud.voxel_downsample(0.05)?));
        spot.send(&MobilityCommand::Velocity(VelocityCommand::new(0.0, 0.3)))?;
        if scans.len() > 2000 {
            bail!("the robot did not turn a full circle in 2000 scans");
        }
    }
    spot.stop()?;
    Ok(scans)
}

fn run(args: &Args, interrupt: &Arc<AtomicBool>) -> Result<DriveOutcome> {
    let password = std::env::var(&args.password_env).with_context(|| {
        format!(
            "set the environment variable {} to the password",
            args.password_env
        )
    })?;
    let ca = std::fs::read(&args.ca).with_context(|| format!("{}", args.ca.display()))?;
    let mut config = SpotConfig::new(&args.host, ca, Credentials::new(&args.user, password));
    config.port = args.port;
    config.description.limits.max_forward_speed = args.max_speed;
    let mut spot = SpotClient::connect(config).context("connecting to the robot")?;
    spot.set_interrupt(Arc::clone(interrupt));
    println!(
        "connected to {} ({})",
        spot.identity().nickname,
        spot.identity().serial_number
    );
    bring_up(&spot, interrupt)?;
    let nav_config = NavigatorConfig::default();
    let geometry = &spot.description().geometry;
    let lidar_height = geometry.body_height + geometry.body_t_lidar.translation.z;
    let (map, navigation, map_t_body, goal) = if let Some(path) = &args.map {
        let map = slam_core::io::read_pcd(path)?;
        let [x, y, yaw] = args.start;
        let map_t_body = Pose3::new(Vector3::new(x, y, 0.0), Vector3::new(0.0, 0.0, yaw));
        let lidar = map_t_body * geometry.body_t_lidar;
        let navigation =
            NavigationMap::from_cloud(&map, &[lidar], lidar_height, &nav_config.map_config())?;
        (map, navigation, map_t_body, args.goal)
    } else {
        let odom_t_start = spot.frame_tree()?.a_t_b("odom", "body")?;
        println!("mapping: turning once in place");
        let scans = map_in_place(&mut spot)?;
        let refs: Vec<(Pose3, &PointCloud)> = scans.iter().map(|(p, c)| (*p, c)).collect();
        let navigation = NavigationMap::from_scans(&refs, lidar_height, &nav_config.map_config())?;
        let points: Vec<Point3<f32>> = scans
            .iter()
            .flat_map(|(pose, cloud)| cloud.transformed(pose).points().to_vec())
            .collect();
        let map = PointCloud::from_points(points).voxel_downsample(0.05)?;
        let goal = odom_t_start * Point3::new(args.goal.x, args.goal.y, 0.0);
        let odom_t_body = spot.frame_tree()?.a_t_b("odom", "body")?;
        (map, navigation, odom_t_body, goal.coords.xy())
    };
    let mut navigator = Navigator::new(
        point_to_plane_localiser(),
        &map,
        &navigation,
        map_t_body,
        spot.description(),
        nav_config,
    )?;
    println!("walking to ({:.2}, {:.2})", goal.x, goal.y);
    let report = drive(&mut spot, &mut navigator, goal, args.cycles, |_| {})?;
    println!("{:?} after {} scans", report.outcome, report.cycles);
    if args.sit {
        println!("sitting down and powering the motors off");
        spot.sit()?;
        spot.power_off()?;
    }
    Ok(report.outcome)
}

/// Whether `error` comes from Ctrl-C.
fn interrupted(error: &anyhow::Error) -> bool {
    error
        .chain()
        .any(|e| matches!(e.downcast_ref::<SpotError>(), Some(SpotError::Interrupted)))
}

fn main() -> ExitCode {
    let args = Args::parse();
    // The client, dropped when `run` returns, errs or panics, stops the robot and returns
    // the lease.
    let result = interrupt_flag().and_then(|flag| run(&args, &flag));
    match result {
        Ok(DriveOutcome::Arrived) => ExitCode::SUCCESS,
        Ok(_) => ExitCode::FAILURE,
        Err(error) if interrupted(&error) => {
            eprintln!("interrupted: the robot was sent a stop and the lease returned");
            ExitCode::from(INTERRUPTED)
        }
        Err(error) => {
            eprintln!("error: {error:#}");
            ExitCode::FAILURE
        }
    }
}
