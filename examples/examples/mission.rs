//! The main job, on a simulated Spot: map an unknown building, then walk from A to B in it with no
//! recorded route.
//!
//! 1. Mapping: Spot walks one lap of the generated building's corridor loop while the Graph-SLAM
//!    engine maps it (point-to-plane ICP or LOAM odometry, loop closure, Levenberg-Marquardt).
//! 2. Navigation: from where the lap ended, the `Navigator` walks the robot (a `CommandedSpot`
//!    that moves only as commanded, with drifting odometry) to a goal on the map: each scan it
//!    localises against the map, replans with Jump Point Search on the map's inflated occupancy
//!    grid and follows the filtered waypoints.
//!
//! Prints the mapping accuracy and the navigation result against the simulator's ground truth.
//! With no goal it walks into the room whose door is farthest from the start.
//!
//! `cargo run --release --example mission -- [--seed N] [--registration p2plane|loam]
//! [--goal X,Y] [--out DIR]` (the goal in metres in the map frame, which is where the lap
//! started, x ahead; `--out` writes the map (PLY) and the grid with the walked path (PNG)).
//! Exits with status 1 when the robot does not arrive (no path, or the scan limit) or collides.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::Parser;
use nalgebra::{Point3, Vector2};
use registration::PointToPlaneIcp;
use slam_core::io::{PlyEncoding, write_ply};
use slam_core::{BitGrid, Cell, GraphSlam, MapRegistrator, Optimizer, PointCloud, Pose3};
use spot_adapter::nav::{NavigationStep, Navigator, NavigatorConfig, navigation_grid};
use spot_adapter::pipelines::{
    loam_slam, point_to_plane_slam, point_to_plane_tracker, slam_config,
};
use spot_adapter::robot::{Robot, VelocityCommand};
use spot_adapter::sim::{CommandedSpot, SimulatedSpot, SimulationConfig};
use spot_nav_examples::{Progress, Registration, Timings, map_and_evaluate, out, parse_goal};

/// The main job on a simulated Spot: map an unknown building, then walk to a goal in it.
///
/// Maps the generated building with Graph-SLAM in one lap of its corridor loop, then walks from
/// where the lap ended to a goal on that map with no recorded route (localising against the map
/// each scan, replanning with Jump Point Search on its inflated occupancy grid). Prints the mapping accuracy and the navigation result against the simulator's ground truth.
/// Without `--goal` the robot walks into the room whose door is farthest from the start. Fails
/// when the robot does not arrive (no path on the map, or the scan limit) or collides.
#[derive(Debug, Parser)]
#[command(name = "mission")]
struct Args {
    /// Seed of the building, the sensor noise and the odometry drift.
    #[arg(
        long,
        value_name = "N",
        allow_negative_numbers = true,
        default_value_t = 3
    )]
    seed: u64,
    /// Odometry and loop refinement backend of the mapping lap.
    #[arg(long, value_enum, default_value_t = Registration::PointToPlane)]
    registration: Registration,
    /// The goal in metres in the map frame (where the lap started, x ahead) [default: the
    /// entry of the room farthest from the start].
    #[arg(long, value_name = "X,Y", allow_hyphen_values = true, value_parser = parse_goal)]
    goal: Option<Vector2<f64>>,
    /// Write the map (`map.ply`) and the grid with the walked cells (`grid.png`) to this folder.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

/// Scans the navigation may take before it gives up (5 minutes at 5 Hz).
const MAX_CYCLES: usize = 1500;

/// The map and where the robot ended, from one mapped lap.
struct Mapped {
    map: PointCloud,
    /// The engine's estimate of the body at the last scan (map frame).
    map_t_body: Pose3,
}

/// Walks one lap of `sim` through `slam`, prints the mapping figures, returns the map.
fn map_building<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    mut slam: GraphSlam<R, C, O>,
    sim: SimulatedSpot,
) -> Result<Mapped> {
    let body_t_lidar = sim.body_t_lidar();
    let truth = sim.ground_truth();
    let samples = sim.map(Ok::<_, std::convert::Infallible>);
    let mapping = map_and_evaluate(&mut slam, samples, &body_t_lidar, Some(&truth), "mapping")?;
    let e = mapping.evaluation.context("the lap has a ground truth")?;
    let report = slam.report();
    out!(
        "mapping     {} scans, {} keyframes, {} loops closed; {:.1} m lap; ATE {:.3} m, loop end-point error {:.3} m; {:.2} ms mean per scan; {:.1} s",
        report.scans,
        report.keyframes,
        report.loops_closed,
        e.end_point.path_length,
        e.ate.rmse,
        e.loop_end_point_error,
        report.mean_scan_ms(),
        mapping.seconds
    )?;
    let map_t_lidar = slam
        .current_lidar_pose()
        .context("the lap gave the engine no scan")?;
    Ok(Mapped {
        map: slam.map(0.05)?,
        map_t_body: map_t_lidar * body_t_lidar.inverse(),
    })
}

/// How the navigation ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Outcome {
    Arrived,
    GaveUp,
    NoPath,
    Blocked,
    Lost,
}

impl Outcome {
    fn describe(self) -> &'static str {
        match self {
            Self::Arrived => "arrived",
            Self::GaveUp => "gave up (scan limit)",
            Self::NoPath => "no path on the map",
            Self::Blocked => "blocked (no progress after backing off and retrying)",
            Self::Lost => "lost (the robot could not be found on the map)",
        }
    }
}

/// What the navigation did.
struct Walk {
    outcome: Outcome,
    cycles: usize,
    /// Metres walked (ground truth).
    walked: f64,
    /// Largest localisation error (metres, ground truth).
    worst: f64,
    /// Grid cells the robot stood in (ground truth).
    trail: Vec<Cell>,
    cycle_ms: Vec<f64>,
}

/// Runs `nav` on `spot` to `goal_map` (map frame; `goal_world` the same in the world, for the
/// progress line) until it arrives, finds no path or reaches the scan limit.
fn walk(
    nav: &mut Navigator<'_, PointToPlaneIcp>,
    spot: &mut CommandedSpot,
    goal_map: Vector2<f64>,
    goal_world: Vector2<f64>,
    world_t_map: &Pose3,
) -> Result<Walk> {
    let mut sample = spot.sense();
    let (mut walked, mut worst, mut cycles) = (0.0f64, 0.0f64, 0usize);
    let mut trail: Vec<Cell> = Vec::new();
    let mut cycle_ms = Vec::new();
    let mut progress = Progress::new("navigating", "scans", None);
    let outcome = loop {
        let t = Instant::now();
        let step = nav.step(&sample, goal_map)?;
        cycle_ms.push(t.elapsed().as_secs_f64() * 1e3);
        let truth_map = world_t_map.inverse() * sample.ground_truth.context("simulated")?;
        worst = worst.max(
            (nav.pose().translation.vector - truth_map.translation.vector)
                .xy()
                .norm(),
        );
        if let Some(c) = nav.grid().cell_at(truth_map.translation.vector.xy()) {
            trail.push(c);
        }
        let command = match step {
            NavigationStep::Walk(command) => Some(command),
            NavigationStep::Hold => Some(VelocityCommand::default()),
            _ => None,
        };
        match (step, command) {
            (_, Some(command)) if cycles < MAX_CYCLES => {
                let before = spot.position();
                sample = spot.step(command);
                walked += (spot.position() - before).norm();
                cycles += 1;
                progress.update(
                    cycles as u64,
                    format!(
                        "{walked:.1} m walked, {:.1} m to go",
                        (goal_world - spot.position()).norm()
                    ),
                );
            }
            (_, Some(_)) => break Outcome::GaveUp,
            (NavigationStep::Arrived, _) => break Outcome::Arrived,
            (NavigationStep::Blocked, _) => break Outcome::Blocked,
            (NavigationStep::Lost, _) => break Outcome::Lost,
            _ => break Outcome::NoPath,
        }
    };
    progress.finish();
    Ok(Walk {
        outcome,
        cycles,
        walked,
        worst,
        trail,
        cycle_ms,
    })
}

/// The map (PLY) and its grid with the inflated obstacles and the walked cells (PNG) in `dir`.
fn write_outputs(
    dir: &Path,
    map: &PointCloud,
    lidar_height: f64,
    inflated: &BitGrid,
    trail: &[Cell],
) -> Result<()> {
    std::fs::create_dir_all(dir)?;
    write_ply(dir.join("map.ply"), map, PlyEncoding::BinaryLittleEndian)?;
    let occupancy = gridmap::OccupancyGridBuilder::new(NavigatorConfig::default().grid)?
        .build(map, lidar_height)?;
    gridmap::write_png(dir.join("grid.png"), &occupancy, Some(inflated), trail, &[])?;
    out!("wrote       {0}/map.ply, {0}/grid.png", dir.display())?;
    Ok(())
}

fn main() -> ExitCode {
    spot_nav_examples::run(|| mission(&Args::parse()))
}

fn mission(args: &Args) -> Result<()> {
    let seed = args.seed;
    let config = SimulationConfig::with_seed(seed);
    let sim = SimulatedSpot::corridor_loop(&config)?;
    let building = sim.building().clone();
    let truth = sim.ground_truth();
    // The map frame is the odometry frame, which starts at the first body pose.
    let world_t_map = truth.first().context("empty lap")?.pose;
    let lap_end = truth.last().context("empty lap")?.pose;
    out!(
        "building    seed {seed}: {:.1} x {:.1} m, {} rooms",
        building.size().x,
        building.size().y,
        building.rooms().len()
    )?;
    let mapped = match args.registration {
        Registration::PointToPlane => map_building(point_to_plane_slam(slam_config()), sim)?,
        Registration::Loam => map_building(loam_slam(slam_config()), sim)?,
    };

    // Navigation, from where the lap ended.
    let start = lap_end.translation.vector.xy();
    let goal_world = match args.goal {
        Some(g) => (world_t_map * Point3::new(g.x, g.y, 0.0)).coords.xy(),
        None => building
            .rooms()
            .iter()
            .max_by(|a, b| (a.door - start).norm().total_cmp(&(b.door - start).norm()))
            .context("the building has no room")?
            .entry_point(),
    };
    let goal_map = (world_t_map.inverse() * Point3::new(goal_world.x, goal_world.y, 0.0))
        .coords
        .xy();
    let mut spot = CommandedSpot::new(building, start, lap_end.rotation.euler_angles().2, &config)?;
    // The map frame's origin is the body at the lap's start: the LiDAR sits its mounting height
    // above it.
    let lidar_height = config.spot.body_t_lidar.translation.z;
    let started = Instant::now();
    let grid = navigation_grid(&mapped.map, lidar_height, &NavigatorConfig::default())?;
    let mut nav = Navigator::new(
        point_to_plane_tracker(),
        &mapped.map,
        &grid,
        mapped.map_t_body,
        spot.description(),
        NavigatorConfig::default(),
    )?;
    out!(
        "grid        {} x {} cells of {:.2} m, obstacles inflated by {:.2} m ({:.1} s)",
        nav.grid().width(),
        nav.grid().height(),
        nav.grid().geometry().resolution,
        NavigatorConfig::default().clearance,
        started.elapsed().as_secs_f64()
    )?;
    out!(
        "goal        ({:.2}, {:.2}) m in the map frame, {:.1} m from the start as the crow flies",
        goal_map.x,
        goal_map.y,
        (goal_world - start).norm()
    )?;
    let walk = walk(&mut nav, &mut spot, goal_map, goal_world, &world_t_map)?;
    let cycles = Timings::new(walk.cycle_ms.iter().copied()).context("no navigation cycle")?;
    let to_goal = (goal_world - spot.position()).norm();
    out!(
        "navigation  {} after {} scans ({:.1} s walking), {:.1} m walked; ends {to_goal:.3} m from the goal (ground truth)",
        walk.outcome.describe(),
        walk.cycles,
        walk.cycles as f64 / config.lidar.rotation_rate,
        walk.walked,
    )?;
    out!(
        "            collisions {}, localisation error up to {:.3} m, {} registrations fell back to odometry; {:.1} ms mean, {:.1} ms max per cycle",
        spot.collisions(),
        walk.worst,
        nav.localisation_failures(),
        cycles.mean(),
        cycles.max()
    )?;
    if let Some(dir) = &args.out {
        write_outputs(dir, &mapped.map, lidar_height, nav.grid(), &walk.trail)?;
    }
    if walk.outcome != Outcome::Arrived {
        bail!(
            "the robot did not reach the goal: {} after {} scans, {to_goal:.2} m from it",
            walk.outcome.describe(),
            walk.cycles
        );
    }
    if spot.collisions() > 0 {
        bail!(
            "the robot arrived but collided {} times on the way",
            spot.collisions()
        );
    }
    Ok(())
}
