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

use std::time::Instant;

use anyhow::{Context, Result, bail};
use nalgebra::{Point3, Vector2};
use registration::PointToPlaneIcp;
use slam_core::io::{PlyEncoding, write_ply};
use slam_core::{Cell, GraphSlam, MapRegistrator, Optimizer, PointCloud, Pose3};
use spot_adapter::eval::{
    DEFAULT_MAX_STAMP_DIFFERENCE, INDOOR_SEGMENT_LENGTHS, TrajectoryEvaluation, body_trajectory,
};
use spot_adapter::nav::{NavigationStep, Navigator, NavigatorConfig, navigation_grid};
use spot_adapter::pipelines::{
    loam_slam, point_to_plane_slam, point_to_plane_tracker, slam_config,
};
use spot_adapter::robot::Robot;
use spot_adapter::sim::{CommandedSpot, SimulatedSpot, SimulationConfig};

const USAGE: &str =
    "usage: mission [--seed N] [--registration p2plane|loam] [--goal X,Y] [--out DIR]";

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
    let started = Instant::now();
    for (n, sample) in sim.enumerate() {
        slam.process(&sample.scan_input());
        if (n + 1).is_multiple_of(50) {
            eprint!(
                "\rmapping: {} scans, {} keyframes, {} loops",
                n + 1,
                slam.keyframe_count(),
                slam.report().loops_closed
            );
        }
    }
    eprintln!();
    let report = slam.report();
    let estimate = body_trajectory(slam.scan_trajectory(), &body_t_lidar);
    let e = TrajectoryEvaluation::compute(
        &estimate,
        &truth,
        DEFAULT_MAX_STAMP_DIFFERENCE,
        &INDOOR_SEGMENT_LENGTHS,
    )?;
    println!(
        "mapping     {} scans, {} keyframes, {} loops closed; {:.1} m lap; ATE {:.3} m, loop end-point error {:.3} m; {:.2} ms mean per scan; {:.1} s",
        report.scans,
        report.keyframes,
        report.loops_closed,
        e.end_point.path_length,
        e.ate.rmse,
        e.loop_end_point_error,
        report.mean_scan_ms(),
        started.elapsed().as_secs_f64()
    );
    let map_t_lidar = slam
        .current_lidar_pose()
        .context("the lap gave the engine no scan")?;
    Ok(Mapped {
        map: slam.map(0.05)?,
        map_t_body: map_t_lidar * body_t_lidar.inverse(),
    })
}

fn parse_goal(text: &str) -> Result<Vector2<f64>> {
    let v: Vec<f64> = text
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()
        .context("--goal X,Y")?;
    let [x, y] = v[..] else {
        bail!("--goal needs two numbers");
    };
    Ok(Vector2::new(x, y))
}

/// What the navigation did.
struct Walk {
    result: &'static str,
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
    let result = loop {
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
        match step {
            NavigationStep::Walk(command) if cycles < MAX_CYCLES => {
                let before = spot.position();
                sample = spot.step(command);
                walked += (spot.position() - before).norm();
                cycles += 1;
                if cycles.is_multiple_of(25) {
                    eprint!(
                        "\rnavigating: {cycles} scans, {walked:.1} m walked, {:.1} m to go",
                        (goal_world - spot.position()).norm()
                    );
                }
            }
            NavigationStep::Walk(_) => break "gave up (scan limit)",
            NavigationStep::Arrived => break "arrived",
            NavigationStep::NoPath => break "no path on the map",
        }
    };
    eprintln!();
    Ok(Walk {
        result,
        cycles,
        walked,
        worst,
        trail,
        cycle_ms,
    })
}

/// Command-line settings.
struct Args {
    seed: u64,
    method: String,
    goal: Option<Vector2<f64>>,
    out: Option<std::path::PathBuf>,
}

fn parse_args() -> Result<Args> {
    let mut parsed = Args {
        seed: 3,
        method: "p2plane".into(),
        goal: None,
        out: None,
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--seed" => parsed.seed = args.next().context(USAGE)?.parse()?,
            "--registration" => parsed.method = args.next().context(USAGE)?,
            "--goal" => parsed.goal = Some(parse_goal(&args.next().context(USAGE)?)?),
            "--out" => parsed.out = Some(args.next().context(USAGE)?.into()),
            _ => bail!("unknown argument {a}\n{USAGE}"),
        }
    }
    Ok(parsed)
}

/// The map (PLY) and its grid with the inflated obstacles and the walked cells (PNG) in `dir`.
fn write_outputs(
    dir: &std::path::Path,
    map: &PointCloud,
    lidar_height: f64,
    inflated: &slam_core::BitGrid,
    trail: &[Cell],
) -> Result<()> {
    std::fs::create_dir_all(dir)?;
    write_ply(dir.join("map.ply"), map, PlyEncoding::BinaryLittleEndian)?;
    let occupancy = gridmap::OccupancyGridBuilder::new(NavigatorConfig::default().grid)?
        .build(map, lidar_height)?;
    gridmap::write_png(dir.join("grid.png"), &occupancy, Some(inflated), trail, &[])?;
    println!("wrote       {0}/map.ply, {0}/grid.png", dir.display());
    Ok(())
}

fn main() -> Result<()> {
    let Args {
        seed,
        method,
        goal,
        out,
    } = parse_args()?;
    let mut config = SimulationConfig::default();
    config.seed = seed;
    let sim = SimulatedSpot::corridor_loop(&config)?;
    let building = sim.building().clone();
    let truth = sim.ground_truth();
    // The map frame is the odometry frame, which starts at the first body pose.
    let world_t_map = truth.first().context("empty lap")?.pose;
    let lap_end = truth.last().context("empty lap")?.pose;
    println!(
        "building    seed {seed}: {:.1} x {:.1} m, {} rooms",
        building.size().x,
        building.size().y,
        building.rooms().len()
    );
    let mapped = match method.as_str() {
        "p2plane" => map_building(point_to_plane_slam(slam_config()), sim)?,
        "loam" => map_building(loam_slam(slam_config()), sim)?,
        other => bail!("unknown registration {other} (p2plane, loam)"),
    };

    // Navigation, from where the lap ended.
    let start = lap_end.translation.vector.xy();
    let goal_world = match goal {
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
    println!(
        "grid        {} x {} cells of {:.2} m, obstacles inflated by {:.2} m ({:.1} s)",
        nav.grid().width(),
        nav.grid().height(),
        nav.grid().geometry().resolution,
        NavigatorConfig::default().clearance,
        started.elapsed().as_secs_f64()
    );
    println!(
        "goal        ({:.2}, {:.2}) m in the map frame, {:.1} m from the start as the crow flies",
        goal_map.x,
        goal_map.y,
        (goal_world - start).norm()
    );
    let walk = walk(&mut nav, &mut spot, goal_map, goal_world, &world_t_map)?;
    let mean_ms = walk.cycle_ms.iter().sum::<f64>() / walk.cycle_ms.len().max(1) as f64;
    let max_ms = walk.cycle_ms.iter().copied().fold(0.0, f64::max);
    println!(
        "navigation  {} after {} scans ({:.1} s walking), {:.1} m walked; ends {:.3} m from the goal (ground truth)",
        walk.result,
        walk.cycles,
        walk.cycles as f64 / config.lidar.rotation_rate,
        walk.walked,
        (goal_world - spot.position()).norm()
    );
    println!(
        "            collisions {}, localisation error up to {:.3} m, {} registrations fell back to odometry; {mean_ms:.1} ms mean, {max_ms:.1} ms max per cycle",
        spot.collisions(),
        walk.worst,
        nav.localisation_failures()
    );
    if let Some(dir) = out {
        write_outputs(&dir, &mapped.map, lidar_height, nav.grid(), &walk.trail)?;
    }
    Ok(())
}
