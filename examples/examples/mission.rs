//! The main job, on a simulated Spot: map an unknown building, then walk to goals in it with no
//! recorded route, around obstacles dropped after mapping.
//!
//! 1. Mapping: Spot walks one lap of the generated building's corridor loop while the Graph-SLAM
//!    engine maps it (point-to-plane ICP or LOAM odometry, loop closure, Levenberg-Marquardt).
//! 2. Navigation: from where the lap ended, the `Navigator` walks the robot (a `CommandedSpot`
//!    that moves only as commanded, with drifting odometry) to each goal in turn: each scan it
//!    localises against the map, replans on the map's inflated occupancy grid and follows the
//!    filtered waypoints. Boxes are dropped on the routes of some legs after mapping.
//!
//! Prints the mapping accuracy and each leg's result against the simulator's ground truth and
//! writes them to `--out` (default `mission-out/`): `map.ply`, `grid.png`, `map.yaml` +
//! `map.pgm` (ROS `map_server`), `estimate.tum` and `ground_truth.tum` (body poses in the map
//! frame), `summary.json`. Exits with status 1 when a goal was not reached.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::{Parser, ValueEnum};
use nalgebra::{Point3, Translation3, UnitQuaternion, Vector2};
use serde::Serialize;
use slam_core::io::{PlyEncoding, StampedPose, write_ply, write_tum};
use slam_core::{GraphSlam, MapRegistrator, Optimizer, PointCloud, Pose3, Registrator};
use spot_adapter::nav::{
    DriveOutcome, Goal, NavigationMap, NavigationMapConfig, Navigator, NavigatorConfig,
    PlannerKind, drive,
};
use spot_adapter::pipelines::{
    loam_slam, point_to_plane_localiser, point_to_plane_slam, scan_context_places, slam_config,
};
use spot_adapter::robot::Robot;
use spot_adapter::sim::{
    Building, CommandedSpot, Route, RouteConfig, SimRng, SimulatedSpot, SimulationConfig,
    shortest_length,
};
use spot_nav_examples::picture::{self, Overlay};
use spot_nav_examples::{
    Progress, Registration, Timings, map_and_evaluate, out, parse_goal, parse_numbers, value_name,
};

/// The main job on a simulated Spot: map an unknown building, then walk to goals in it.
///
/// Maps the generated building with Graph-SLAM in one lap of its corridor loop, then walks from
/// where the lap ended to each goal in turn on that map with no recorded route (localising
/// against the map each scan, replanning on its inflated occupancy grid), around boxes dropped
/// on the routes after mapping. Prints the mapping accuracy and every leg's result against the
/// simulator's ground truth, and writes the map, the grid picture, the ROS map, the
/// trajectories and `summary.json` to `--out`. Fails when a goal is not reached within 0.10 m
/// (by the ground truth) or the robot collides.
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
    /// Random reachable goals to visit (from a fixed generator seeded by `--seed`), when no
    /// `--goal` is given.
    #[arg(
        long,
        value_name = "K",
        allow_negative_numbers = true,
        default_value_t = 5
    )]
    goals: usize,
    /// A goal in metres in the map frame (where the lap started, x ahead); repeat for several,
    /// visited in order. Replaces the random goals.
    #[arg(long, value_name = "X,Y", allow_hyphen_values = true, value_parser = parse_goal)]
    goal: Vec<Vector2<f64>>,
    /// Boxes dropped on the routes of as many legs after mapping (never on the first).
    #[arg(
        long,
        value_name = "M",
        allow_negative_numbers = true,
        default_value_t = 1
    )]
    obstacles: usize,
    /// Start navigating with the estimate this far off the truth: metres, degrees.
    #[arg(long, value_name = "METRES,DEGREES", allow_hyphen_values = true, value_parser = parse_numbers::<2>)]
    kidnap: Option<[f64; 2]>,
    /// Odometry and loop refinement backend of the mapping lap.
    #[arg(long, value_enum, default_value_t = Registration::PointToPlane)]
    registration: Registration,
    /// The navigator's planner.
    #[arg(long, value_enum, default_value_t = PlannerChoice::CostAware)]
    planner: PlannerChoice,
    /// Where the outputs go.
    #[arg(long, value_name = "DIR", default_value = "mission-out")]
    out: PathBuf,
}

/// `--planner`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum PlannerChoice {
    /// A* under the clearance cost (least cost: keeps to the middle of corridors).
    CostAware,
    /// Jump Point Search.
    Jps,
    /// A* with the octile heuristic.
    Astar,
}

/// Scans a leg may take before the robot gives up (5 minutes at 5 Hz).
const MAX_CYCLES: usize = 1500;

/// A goal counts as reached within this distance of the true body (metres).
const REACHED_WITHIN: f64 = 0.10;

/// The map and where the robot ended, from one mapped lap.
struct Mapped {
    map: PointCloud,
    /// The occupancy (obstacles from the floor up, free from the beams, unknown elsewhere).
    navigation: NavigationMap,
    /// The engine's estimate of the body at the last scan (map frame).
    map_t_body: Pose3,
    summary: MappingSummary,
}

/// The mapping lap's figures (`summary.json`'s `mapping`).
#[derive(Clone, Debug, Serialize)]
struct MappingSummary {
    scans: usize,
    keyframes: usize,
    loops_closed: usize,
    lap_length_m: f64,
    ate_m: f64,
    loop_end_point_error_m: f64,
    segment_drift_percent: Option<f64>,
    mean_ms_per_scan: f64,
    seconds: f64,
}

/// Walks one lap of `sim` through `slam`, prints the mapping figures, returns the map.
fn map_building<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    mut slam: GraphSlam<R, C, O>,
    sim: SimulatedSpot,
) -> Result<Mapped> {
    let body_t_lidar = sim.body_t_lidar();
    let truth = sim.ground_truth();
    let samples = sim.map(Ok::<_, std::convert::Infallible>);
    let mapping = map_and_evaluate(
        &mut slam,
        samples,
        &body_t_lidar,
        Some(&truth),
        "mapping",
        false,
    )?;
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
    let scans: Vec<(Pose3, &PointCloud)> = slam.keyframe_scans().collect();
    let sim_config = SimulationConfig::default();
    let lidar_height = sim_config.spot.body_height + sim_config.spot.body_t_lidar.translation.z;
    let navigation =
        NavigationMap::from_scans(&scans, lidar_height, &NavigationMapConfig::default())?;
    Ok(Mapped {
        map: slam.map(0.05)?,
        navigation,
        map_t_body: map_t_lidar * body_t_lidar.inverse(),
        summary: MappingSummary {
            scans: report.scans,
            keyframes: report.keyframes,
            loops_closed: report.loops_closed,
            lap_length_m: e.end_point.path_length,
            ate_m: e.ate.rmse,
            loop_end_point_error_m: e.loop_end_point_error,
            segment_drift_percent: e.segments.as_ref().map(|s| 100.0 * s.translation),
            mean_ms_per_scan: report.mean_scan_ms(),
            seconds: mapping.seconds,
        },
    })
}

/// One leg's figures (`summary.json`'s `goals`).
#[derive(Clone, Debug, Serialize)]
struct LegSummary {
    /// The goal in the map frame (metres).
    goal: [f64; 2],
    /// `arrived`, `no_path`, `blocked`, `lost` or `gave_up`.
    outcome: &'static str,
    /// Arrived and within 0.10 m of the goal by the ground truth.
    reached: bool,
    final_error_m: f64,
    collisions: usize,
    cycles: usize,
    walked_m: f64,
    /// Length of the shortest way on the building's true floor plan at the navigator's
    /// inflation and cells (`spot_adapter::sim::shortest_length`); `None` when there is none.
    shortest_m: Option<f64>,
    localisation_error_max_m: f64,
    /// Plans made on the leg (the first, blocked paths, the periodic ones).
    plans: usize,
    /// Times the robot was stuck and backed off.
    recoveries: usize,
    cycle_ms_mean: f64,
    cycle_ms_p99: f64,
    cycle_ms_max: f64,
}

/// `summary.json`.
#[derive(Clone, Debug, Serialize)]
struct Summary {
    seed: u64,
    registration: String,
    planner: String,
    kidnap: Option<[f64; 2]>,
    mapping: MappingSummary,
    /// Plan-view footprints of the dropped boxes in the map frame: min and max corners.
    obstacles: Vec<[[f64; 2]; 2]>,
    goals: Vec<LegSummary>,
    reached: usize,
    collisions: usize,
}

/// The world and map frames of the run: the map frame is the odometry frame of the lap, which
/// starts at the first body pose.
struct Frames {
    world_t_map: Pose3,
}

impl Frames {
    fn to_world(&self, p: Vector2<f64>) -> Vector2<f64> {
        (self.world_t_map * Point3::new(p.x, p.y, 0.0)).coords.xy()
    }

    fn to_map(&self, p: Vector2<f64>) -> Vector2<f64> {
        (self.world_t_map.inverse() * Point3::new(p.x, p.y, 0.0))
            .coords
            .xy()
    }
}

/// `count` goals in the building (world frame): at least 0.6 m from every obstacle, in space
/// the lap saw (a floor point of the map within 0.25 m, free on the planning `grid`), at least
/// 5 m from the one before and reachable from it with Spot's clearance.
fn random_goals(
    building: &Building,
    map: &PointCloud,
    grid: &slam_core::BitGrid,
    frames: &Frames,
    start: Vector2<f64>,
    count: usize,
    seed: u64,
) -> Result<Vec<Vector2<f64>>> {
    let cell = 0.25;
    let key = |p: Vector2<f64>| ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64);
    let floor_z = -frames.world_t_map.translation.z;
    let seen: std::collections::HashSet<(i64, i64)> = map
        .points()
        .iter()
        .filter(|p| f64::from(p.z) < floor_z + 0.1)
        .map(|p| key(frames.to_world(Vector2::new(f64::from(p.x), f64::from(p.y)))))
        .collect();
    let mut rng = SimRng::new(seed, 0x6041);
    let mut goals: Vec<Vector2<f64>> = Vec::with_capacity(count);
    let size = building.size();
    for _ in 0..200_000 {
        if goals.len() == count {
            return Ok(goals);
        }
        let from = goals.last().copied().unwrap_or(start);
        let p = Vector2::new(rng.range(0.0, size.x), rng.range(0.0, size.y));
        let free_on_map = grid
            .cell_at(frames.to_map(p))
            .is_some_and(|c| !grid.is_blocked(c));
        if seen.contains(&key(p))
            && free_on_map
            && building.clearance(p) >= 0.6
            && (p - from).norm() >= 5.0
            && Route::between(building, from, p, &RouteConfig::default()).is_ok()
        {
            goals.push(p);
        }
    }
    bail!("found only {} of {count} reachable goals", goals.len())
}

/// What one leg did, measured on the ground truth.
struct Leg {
    outcome: DriveOutcome,
    cycles: usize,
    walked: f64,
    worst: f64,
    cycle_ms: Vec<f64>,
    planned: Vec<Vector2<f64>>,
}

/// Runs `nav` on `spot` to `goal` (map frame) through `nav::drive` until it arrives, stops or
/// reaches the scan limit; appends the estimate and the truth (map frame).
fn leg<R: Registrator>(
    nav: &mut Navigator<R>,
    spot: &mut CommandedSpot,
    goal: Vector2<f64>,
    frames: &Frames,
    trajectories: &mut (Vec<StampedPose>, Vec<StampedPose>),
    label: &str,
) -> Result<Leg> {
    let (mut walked, mut worst) = (0.0f64, 0.0f64);
    let mut last: Option<Vector2<f64>> = None;
    let mut cycle_ms = Vec::new();
    let mut planned = Vec::new();
    let mut progress = Progress::new(label, "scans", None);
    let goal_world = frames.to_world(goal);
    let mut truth_missing = false;
    let report = drive(spot, nav, Goal::from(goal), MAX_CYCLES, |cycle| {
        cycle_ms.push(cycle.navigator_ms);
        let Some(world_t_body) = cycle.sample.ground_truth else {
            truth_missing = true;
            return;
        };
        let truth = frames.world_t_map.inverse() * world_t_body;
        let estimate = cycle.estimate;
        worst = worst.max(
            (estimate.translation.vector - truth.translation.vector)
                .xy()
                .norm(),
        );
        walked += last.map_or(0.0, |p| (truth.translation.vector.xy() - p).norm());
        last = Some(truth.translation.vector.xy());
        trajectories.0.push(StampedPose {
            stamp: cycle.sample.stamp,
            pose: estimate,
        });
        trajectories.1.push(StampedPose {
            stamp: cycle.sample.stamp,
            pose: truth,
        });
        if planned.is_empty() && !cycle.waypoints.is_empty() {
            planned.push(estimate.translation.vector.xy());
            planned.extend_from_slice(cycle.waypoints);
        }
        progress.update(
            cycle_ms.len() as u64,
            format!(
                "{walked:.1} m walked, {:.1} m to go",
                (goal_world - world_t_body.translation.vector.xy()).norm()
            ),
        );
    })?;
    progress.finish();
    if truth_missing {
        bail!("the simulated Spot gave a sample without its ground truth");
    }
    Ok(Leg {
        outcome: report.outcome,
        cycles: report.cycles,
        walked,
        worst,
        cycle_ms,
        planned,
    })
}

fn main() -> ExitCode {
    spot_nav_examples::run(|| mission(&Args::parse()))
}

#[allow(clippy::too_many_lines)] // The mission reads top to bottom: map, goals, legs, outputs.
fn mission(args: &Args) -> Result<()> {
    let seed = args.seed;
    if args.goal.is_empty() && args.goals == 0 {
        bail!("--goals 0 and no --goal: nothing to visit");
    }
    let config = SimulationConfig::with_seed(seed);
    let sim = SimulatedSpot::corridor_loop(&config)?;
    let mut building = sim.building().clone();
    let truth = sim.ground_truth();
    let frames = Frames {
        world_t_map: truth.first().context("empty lap")?.pose,
    };
    let lap_end = truth.last().context("empty lap")?.pose;
    out!(
        "building    seed {seed}: {:.1} x {:.1} m, {} rooms",
        building.size().x,
        building.size().y,
        building.rooms().len()
    )?;
    let mapped = match args.registration {
        // Loops by position and by appearance, as the slam example seeks them.
        Registration::PointToPlane => map_building(
            point_to_plane_slam(slam_config())?.with_place_recognizer(scan_context_places()),
            sim,
        )?,
        Registration::Loam => map_building(
            loam_slam(slam_config())?.with_place_recognizer(scan_context_places()),
            sim,
        )?,
    };

    let start = lap_end.translation.vector.xy();
    let mut spot = CommandedSpot::new(
        building.clone(),
        start,
        lap_end.rotation.euler_angles().2,
        &config,
    )?;
    // The map frame's origin is the body at the lap's start: the LiDAR sits its mounting height
    // above it.
    let nav_config = NavigatorConfig {
        planner: match args.planner {
            PlannerChoice::CostAware => PlannerKind::CellCostAStar,
            PlannerChoice::Jps => PlannerKind::JumpPointSearch,
            PlannerChoice::Astar => PlannerKind::AStar,
        },
        ..NavigatorConfig::default()
    };
    // What the legs' shortest ways are measured at: the navigator's inflation and cells.
    let (inflation, resolution) = (nav_config.planning.inflation, nav_config.grid.resolution);
    let started = Instant::now();
    let kidnap = args
        .kidnap
        .map_or_else(Pose3::identity, |[metres, degrees]| {
            let d = 30f64.to_radians();
            Pose3::from_parts(
                Translation3::new(metres * d.cos(), metres * d.sin(), 0.0),
                UnitQuaternion::from_euler_angles(0.0, 0.0, degrees.to_radians()),
            )
        });
    let mut nav = Navigator::new(
        point_to_plane_localiser(),
        &mapped.map,
        &mapped.navigation,
        mapped.map_t_body * kidnap,
        spot.description(),
        nav_config,
    )?;
    out!(
        "grid        {} x {} cells of {:.2} m, obstacles from the floor up, inflated by {:.2} m plus a clearance cost ({:.1} s)",
        nav.grid().width(),
        nav.grid().height(),
        nav.grid().geometry().resolution,
        inflation,
        started.elapsed().as_secs_f64()
    )?;

    // Goals (world frame) from where the lap ended.
    let goals_world: Vec<Vector2<f64>> = if args.goal.is_empty() {
        random_goals(
            &building,
            &mapped.map,
            nav.grid(),
            &frames,
            start,
            args.goals,
            seed,
        )?
    } else {
        args.goal.iter().map(|&g| frames.to_world(g)).collect()
    };
    let goals: Vec<Vector2<f64>> = goals_world.iter().map(|&g| frames.to_map(g)).collect();
    // Legs that get a box on their route: spread over the legs after the first.
    let boxed: Vec<usize> = (0..args.obstacles.min(goals.len().saturating_sub(1)))
        .map(|k| 1 + k * (goals.len() - 1) / args.obstacles.max(1))
        .collect();

    let mut trajectories = (Vec::new(), Vec::new());
    let mut overlay = Overlay {
        start: Some(frames.to_map(start)),
        goals: goals.clone(),
        ..Overlay::default()
    };
    let mut legs = Vec::new();
    let mut obstacles = Vec::new();
    for (k, (&goal, &goal_world)) in goals.iter().zip(&goals_world).enumerate() {
        let from = spot.position();
        if boxed.contains(&k)
            && let Some(solid) =
                spot.building()
                    .obstacle_on_route(from, goal_world, 0.6, &RouteConfig::default())
        {
            spot.building_mut().add_box(solid)?;
            building.add_box(solid)?;
            let (lo, hi) = (
                frames.to_map(solid.min.coords.xy()),
                frames.to_map(solid.max.coords.xy()),
            );
            let footprint = (lo.inf(&hi), lo.sup(&hi));
            overlay.obstacles.push(footprint);
            obstacles.push([footprint.0.into(), footprint.1.into()]);
            out!(
                "obstacle    0.6 m box dropped on leg {}'s route at ({:.1}, {:.1}) m (map frame)",
                k + 1,
                0.5 * (footprint.0.x + footprint.1.x),
                0.5 * (footprint.0.y + footprint.1.y)
            )?;
        }
        // The shortest way on the true floor plan at the navigator's own inflation (boxes
        // dropped on this leg included): the figure the walk is measured against.
        let shortest = shortest_length(&building, from, goal_world, inflation, resolution)?;
        let collisions_before = spot.collisions();
        let (plans_before, recoveries_before) = (nav.replans(), nav.recoveries());
        let label = format!("goal {}/{}", k + 1, goals.len());
        let walk = leg(
            &mut nav,
            &mut spot,
            goal,
            &frames,
            &mut trajectories,
            &label,
        )?;
        let error = (spot.position() - goal_world).norm();
        let collisions = spot.collisions() - collisions_before;
        let times = Timings::new(walk.cycle_ms.iter().copied());
        let summary = LegSummary {
            goal: [goal.x, goal.y],
            outcome: walk.outcome.name(),
            reached: walk.outcome == DriveOutcome::Arrived && error <= REACHED_WITHIN,
            final_error_m: error,
            collisions,
            cycles: walk.cycles,
            walked_m: walk.walked,
            shortest_m: shortest,
            localisation_error_max_m: walk.worst,
            plans: nav.replans() - plans_before,
            recoveries: nav.recoveries() - recoveries_before,
            cycle_ms_mean: times.as_ref().map_or(0.0, Timings::mean),
            cycle_ms_p99: times.as_ref().map_or(0.0, |t| t.quantile(0.99)),
            cycle_ms_max: times.as_ref().map_or(0.0, Timings::max),
        };
        out!(
            "goal {:>2}     ({:6.2}, {:6.2}): {} after {} scans, {:.1} m walked (shortest {}), {:.3} m from the goal, {} collisions, localisation error up to {:.3} m, {} plans, {} recoveries, {:.1} ms mean per cycle",
            k + 1,
            goal.x,
            goal.y,
            summary.outcome,
            summary.cycles,
            summary.walked_m,
            shortest.map_or_else(|| "-".to_owned(), |s| format!("{s:.1} m")),
            error,
            collisions,
            summary.localisation_error_max_m,
            summary.plans,
            summary.recoveries,
            summary.cycle_ms_mean
        )?;
        overlay.planned.push(walk.planned);
        legs.push(summary);
    }
    overlay.walked = trajectories
        .1
        .iter()
        .map(|p| p.pose.translation.vector.xy())
        .collect();

    let reached = legs.iter().filter(|l| l.reached).count();
    let collisions = legs.iter().map(|l| l.collisions).sum();
    let summary = Summary {
        seed,
        registration: value_name(&args.registration),
        planner: value_name(&args.planner),
        kidnap: args.kidnap,
        mapping: mapped.summary.clone(),
        obstacles,
        goals: legs,
        reached,
        collisions,
    };
    write_outputs(
        &args.out,
        &mapped.map,
        mapped.navigation.occupancy(),
        nav.grid(),
        &overlay,
        &trajectories,
        &summary,
    )?;
    out!(
        "result      {reached} of {} goals reached within {REACHED_WITHIN} m, {collisions} collisions",
        summary.goals.len()
    )?;
    if reached < summary.goals.len() || collisions > 0 {
        bail!(
            "{} of {} goals not reached, {collisions} collisions",
            summary.goals.len() - reached,
            summary.goals.len()
        );
    }
    Ok(())
}

/// Every output file in `dir`.
fn write_outputs(
    dir: &Path,
    map: &PointCloud,
    occupancy: &gridmap::OccupancyGrid,
    inflated: &slam_core::BitGrid,
    overlay: &Overlay,
    trajectories: &(Vec<StampedPose>, Vec<StampedPose>),
    summary: &Summary,
) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    write_ply(dir.join("map.ply"), map, PlyEncoding::BinaryLittleEndian)?;
    picture::write_png(&dir.join("grid.png"), occupancy, inflated, overlay)?;
    gridmap::write_ros_map(occupancy, dir.join("map.yaml"))?;
    write_tum(dir.join("estimate.tum"), &trajectories.0)?;
    write_tum(dir.join("ground_truth.tum"), &trajectories.1)?;
    let json = serde_json::to_string_pretty(summary)?;
    std::fs::write(dir.join("summary.json"), json + "\n")
        .with_context(|| format!("writing {}/summary.json", dir.display()))?;
    out!(
        "wrote       {0}/map.ply, grid.png, map.yaml + map.pgm, estimate.tum, ground_truth.tum, summary.json",
        dir.display()
    )?;
    Ok(())
}
