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

mod args;
mod legs;
mod mapping;
mod report;

use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::Parser;
use nalgebra::{Translation3, UnitQuaternion, Vector2};
use slam_core::Pose3;
use spot_adapter::nav::{DriveOutcome, Navigator, PlannerKind};
use spot_adapter::pipelines::{
    loam_slam, point_to_plane_localiser, point_to_plane_slam, scan_context_places,
};
use spot_adapter::robot::Robot;
use spot_adapter::sim::{
    CommandedSpot, RouteConfig, SimulatedSpot, SimulationConfig, shortest_length,
};
use spot_nav_examples::picture::Overlay;
use spot_nav_examples::{Registration, Timings, out, print_settings, value_name};

use args::{Args, PlannerChoice, Settings};
use legs::{Frames, leg, random_goals};
use mapping::map_building;
use report::{LegSummary, Summary, write_outputs};

/// A goal counts as reached within this distance of the true body (metres).
const REACHED_WITHIN: f64 = 0.10;

fn main() -> ExitCode {
    spot_nav_examples::run(|| mission(&Args::parse()))
}

#[allow(clippy::too_many_lines)] // The mission reads top to bottom: map, goals, legs, outputs.
fn mission(args: &Args) -> Result<()> {
    let seed = args.seed;
    let mut settings = args.settings.load(Settings::default())?;
    if let Some(planner) = args.planner {
        settings.navigator.planner = match planner {
            PlannerChoice::CostAware => PlannerKind::CellCostAStar,
            PlannerChoice::Jps => PlannerKind::JumpPointSearch,
            PlannerChoice::Astar => PlannerKind::AStar,
        };
    }
    if let Some(format) = args.settings.print_config {
        return print_settings(&settings, format);
    }
    let Settings {
        slam: slam_settings,
        navigator: nav_config,
    } = settings;
    let planner_name = match nav_config.planner {
        PlannerKind::CellCostAStar => value_name(&PlannerChoice::CostAware),
        PlannerKind::JumpPointSearch => value_name(&PlannerChoice::Jps),
        PlannerKind::AStar => value_name(&PlannerChoice::Astar),
        other => format!("{other:?}"),
    };
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
            point_to_plane_slam(slam_settings)?.with_place_recognizer(scan_context_places()),
            sim,
            &nav_config.map_config(),
        )?,
        Registration::Loam => map_building(
            loam_slam(slam_settings)?.with_place_recognizer(scan_context_places()),
            sim,
            &nav_config.map_config(),
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
        planner: planner_name,
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
