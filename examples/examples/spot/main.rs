//! Walk a real Spot to a goal over gRPC (needs `--features grpc`).
//!
//! ```text
//! SPOT_PASSWORD=... cargo run --release --features grpc --example spot -- \
//!     --host 192.168.80.3 --ca robot-ca.pem --user admin --password-env SPOT_PASSWORD \
//!     --route route.txt --save-map office --goal 3,0
//! ```
//!
//! Connects (login, directory, time sync, body lease: a lease the tablet holds is refused,
//! naming `--take-lease`, which takes it instead) and checks the robot state: it refuses to
//! start while an E-stop is asserted, when no E-stop endpoint is registered, or with a system
//! or behaviour fault, naming what to do. It powers the motors on if they are off and stands
//! Spot up (each step with a timeout), and only then walks.
//!
//! Without `--map` it maps with the Graph-SLAM engine, live: each new scan of the point-cloud
//! service goes to the engine with the body odometry of the robot state as its prior, while
//! Spot walks the waypoints of `--route FILE` (one `x y` a line, metres in the start frame:
//! the body's frame where the run started, x forward, y left; `#` comments) or, without a
//! route, turns once in place at `--turn-rate` (0.3 rad/s). The occupancy grid is then built
//! from the optimised keyframes, and `--save-map DIR` saves the map cloud (`map.pcd`,
//! `map.ply`), the pose graph (`graph.g2o`) and the grid (`grid.yaml` + `grid.pgm`), all in the
//! start frame.
//! A later run navigates on it with `--map DIR` (no mapping), its pose in the map given by
//! `--start X,Y,YAW` (`0,0,0` when it starts where the mapping run did); `--map` also takes a
//! PCD file alone.
//!
//! The goal is in the start frame without `--map`, in the map frame with it. The navigator
//! then walks Spot there; it stops on arrival and on every fault, and the run exits 0 only
//! when Spot arrived (or, without `--goal`, once the map is saved). With `--sit` Spot sits and
//! powers off at the end. The password is read from the environment variable named by
//! `--password-env`, never from the command line.
//!
//! On a bench without an E-stop controller, `--software-estop` registers the example's own
//! software E-stop endpoint and keeps it alive (as the SDK's `EstopEndpoint` and
//! `EstopKeepAlive`); on exit it is set to settle-then-cut, so Spot sits and cuts power.
//!
//! On Ctrl-C, on every error and on a panic Spot is sent a stop and the lease is returned
//! (Ctrl-C exits 130; a second Ctrl-C exits at once). A robot whose odometry does not change
//! for 3 s while commanded to move, or that refuses a command, stops the run with the reason.
//!
//! Keep the e-stop in hand. Speeds are capped by `--max-speed` (default 0.5 m/s).

mod mapping;

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use anyhow::{Context, Result};
use clap::Parser;
use nalgebra::{Vector2, Vector3};
use slam_core::Pose3;
use spot_adapter::grpc::{Credentials, MotorPower, SpotClient, SpotConfig, SpotError};
use spot_adapter::nav::{DriveOutcome, NavigationMap, Navigator, NavigatorConfig, drive};
use spot_adapter::pipelines::point_to_plane_localiser;
use spot_adapter::robot::{Robot, SpotGeometry};
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
    /// Without it the run ends once the map is made (and saved with --save-map).
    #[arg(long, value_parser = parse_goal, required_unless_present = "save_map")]
    goal: Option<Vector2<f64>>,
    /// A map to navigate on instead of mapping: a folder written by --save-map, or a PCD file.
    #[arg(long, conflicts_with_all = ["route", "save_map"])]
    map: Option<PathBuf>,
    /// Map while walking these waypoints (one `x y` a line, metres in the start frame; `#`
    /// comments) instead of turning once in place.
    #[arg(long, value_name = "FILE")]
    route: Option<PathBuf>,
    /// Without --route: the rate of the turn in place that maps, rad/s.
    #[arg(long, default_value_t = 0.3, value_parser = positive)]
    turn_rate: f64,
    /// Save the map made here (map.pcd, map.ply, graph.g2o, grid.yaml + grid.pgm) for --map.
    #[arg(long, value_name = "DIR")]
    save_map: Option<PathBuf>,
    /// The robot's pose X,Y,YAW (metres, radians) in the --map frame.
    #[arg(long, value_parser = parse_numbers::<3>, default_value = "0,0,0")]
    start: [f64; 3],
    /// The largest forward speed, m/s.
    #[arg(long, default_value_t = 0.5)]
    max_speed: f64,
    /// The most navigator cycles (scans) before giving up.
    #[arg(long, default_value_t = 3000)]
    cycles: usize,
    /// Take the body lease from whoever holds it (the tablet) instead of asking for it.
    #[arg(long)]
    take_lease: bool,
    /// Bench setups without an E-stop controller: register our own software E-stop endpoint
    /// with this timeout in seconds (9 when given alone), keep it alive while running, and on
    /// exit set it to settle-then-cut (Spot sits and cuts power). Stop it with Ctrl-C.
    #[arg(long, value_name = "SECONDS", num_args = 0..=1, default_missing_value = "9")]
    software_estop: Option<f64>,
    /// At the end, sit and power the motors off.
    #[arg(long)]
    sit: bool,
}

/// A finite number above zero.
fn positive(text: &str) -> Result<f64, String> {
    text.parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v > 0.0)
        .ok_or_else(|| format!("{text:?} is not a number above zero"))
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

/// Run as `args` ask; whether it did all it was asked (arrived, or mapped without a goal).
fn run(args: &Args, interrupt: &Arc<AtomicBool>) -> Result<bool> {
    // The files first: a bad route or map stops the run before it connects.
    let geometry = SpotGeometry::default();
    let lidar_height = geometry.body_height + geometry.body_t_lidar.translation.z;
    let route = args.route.as_deref().map(mapping::read_route).transpose()?;
    let [x, y, yaw] = args.start;
    let map_t_start = Pose3::new(Vector3::new(x, y, 0.0), Vector3::new(0.0, 0.0, yaw));
    let loaded = args
        .map
        .as_deref()
        .map(|path| mapping::load(path, map_t_start * geometry.body_t_lidar))
        .transpose()?;
    let password = std::env::var(&args.password_env).with_context(|| {
        format!(
            "set the environment variable {} to the password",
            args.password_env
        )
    })?;
    let ca = std::fs::read(&args.ca).with_context(|| format!("{}", args.ca.display()))?;
    let mut config = SpotConfig::new(&args.host, ca, Credentials::new(&args.user, password));
    config.port = args.port;
    config.description.geometry = geometry;
    config.description.limits.max_forward_speed = args.max_speed;
    config.take_lease = args.take_lease;
    config.software_estop = args
        .software_estop
        .map(Duration::try_from_secs_f64)
        .transpose()
        .context("--software-estop takes a timeout in seconds")?;
    let mut spot = SpotClient::connect(config).map_err(|error| {
        let hint = match &error {
            SpotError::LeaseRefused { owner, .. } if !args.take_lease => format!(
                "the body lease is held by {owner:?} (the tablet?): release it there, or run \
                 with --take-lease to take it"
            ),
            _ => "connecting to the robot".to_owned(),
        };
        anyhow::Error::new(error).context(hint)
    })?;
    spot.set_interrupt(Arc::clone(interrupt));
    println!(
        "connected to {} ({})",
        spot.identity().nickname,
        spot.identity().serial_number
    );
    bring_up(&spot, interrupt)?;
    let nav_config = NavigatorConfig::default();
    let (map, navigation, map_t_body) = if let Some(loaded) = loaded {
        let navigation = NavigationMap::from_cloud(
            &loaded.map,
            &loaded.viewpoints,
            lidar_height,
            &nav_config.map_config(),
        )?;
        (loaded.map, navigation, map_t_start)
    } else {
        match &route {
            Some(route) => println!("mapping: walking a route of {} waypoints", route.len()),
            None => println!("mapping: turning once in place"),
        }
        let mapped = mapping::map_live(
            &mut spot,
            route.as_deref(),
            args.turn_rate,
            args.max_speed,
            args.cycles,
            lidar_height,
        )?;
        let [x, y, yaw] = xy_yaw(&mapped.start_t_body);
        println!("mapping ended at ({x:.3}, {y:.3}, {yaw:.3}) in the start frame");
        if let Some(dir) = &args.save_map {
            mapping::save(dir, &mapped)?;
        }
        (mapped.map, mapped.navigation, mapped.start_t_body)
    };
    let Some(goal) = args.goal else {
        finish(&spot, args.sit)?;
        return Ok(true);
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
    finish(&spot, args.sit)?;
    Ok(report.outcome == DriveOutcome::Arrived)
}

/// A planar pose's x, y and yaw.
fn xy_yaw(pose: &Pose3) -> [f64; 3] {
    let t = pose.translation.vector;
    [t.x, t.y, pose.rotation.euler_angles().2]
}

/// With `sit`, sit down and power the motors off.
fn finish(spot: &SpotClient, sit: bool) -> Result<()> {
    if sit {
        println!("sitting down and powering the motors off");
        spot.sit()?;
        spot.power_off()?;
    }
    Ok(())
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
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
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
