//! The main job, on a simulated Spot: map an unknown building, then walk to goals in it with no
//! recorded route, around obstacles dropped after mapping.
//!
//! 1. Mapping, by default by exploring: Spot starts at a random reachable spot (seeded by
//!    `--seed`) with no map and no route; the Graph-SLAM engine maps live while the explorer
//!    sends the navigator from frontier to frontier (`--frontier`: the nearest one that would
//!    reveal at least 1 m², the default; information gain, greedy or tour) until no reachable
//!    frontier worth a walk is left. With `--lap`, Spot walks one scripted lap of the
//!    building's corridor loop instead (a route from the true floor plan) while the engine
//!    maps it (point-to-plane ICP or LOAM odometry, loop closure, Levenberg-Marquardt).
//! 2. Navigation: from where the mapping ended, the `Navigator` walks the robot (a
//!    `CommandedSpot` that moves only as commanded, with drifting odometry) to each goal in
//!    turn: each scan it localises against the map, replans on the map's inflated occupancy
//!    grid and follows the filtered waypoints. Random goals lie where the mapping saw free floor
//!    the robot can reach (after an exploration: rooms included). Boxes are dropped on the
//!    routes of some legs after mapping.
//!
//! With `--floors N` (2 or 3) the office has N floors joined by stairs: Spot maps it by a
//! scripted tour of every floor (a lap of each, up the stairs and back down), the map splits
//! into a grid per floor with the flights marked as stairs on both floors they join, and each
//! goal lies on another floor than the one before: the navigator walks to the flight, a stairs
//! controller climbs or descends it (Spot's stairs mode), and the next floor's navigator
//! localises against that floor's map and walks on.
//!
//! Prints the mapping's figures (coverage of the reachable floor, distance, loops, ATE) and
//! each leg's result against the simulator's ground truth and writes them to `--out` (default
//! `mission-out/`): `map.ply`, `grid.png`, `map.yaml` + `map.pgm` (ROS `map_server`),
//! `estimate.tum` and `ground_truth.tum` (body poses in the map frame), `summary.json`. Exits
//! with status 1 when the exploration fell short of `--min-coverage` or collided, or a goal was
//! not reached.

mod args;
mod exploring;
mod floors;
mod legs;
mod mapped;
mod mapping;
mod reachable;
mod report;

use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Result, bail};
use clap::Parser;
use gridmap::CellState;
use nalgebra::{Translation3, UnitQuaternion, Vector2};
use slam_core::{Cell, Pose3};
use spot_adapter::nav::{DriveOutcome, Navigator, PlannerKind};
use spot_adapter::pipelines::point_to_plane_localiser;
use spot_adapter::robot::Robot;
use spot_adapter::sim::{RouteConfig, SimulationConfig, shortest_length};
use spot_nav_examples::picture::Overlay;
use spot_nav_examples::{Timings, out, print_settings, value_name};

use args::{Args, BuildingSize, PlannerChoice, Settings};
use legs::{leg, random_goals};
use mapped::{Mapped, MappingSettings, by_exploring, by_lap};
use reachable::ReachableCells;
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
    if let Some(rule) = args.frontier {
        settings.explorer.choice = rule.apply(settings.explorer.choice);
    }
    if let Some(format) = args.settings.print_config {
        return print_settings(&settings, format);
    }
    let Settings {
        slam: slam_settings,
        navigator: nav_config,
        explorer: explorer_config,
        lidar,
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
    // Before anything is simulated: bad explorer settings are refused by name.
    if !args.lap {
        explorer_config.validate()?;
    }
    let config = SimulationConfig {
        building: spot_adapter::sim::BuildingConfig {
            floors: args.floors,
            ..BuildingSize::chosen(args).config()
        },
        lidar,
        ..SimulationConfig::with_seed(seed)
    };
    if args.floors > 1 {
        if !args.goal.is_empty()
            || args.kidnap.is_some()
            || args.frontier.is_some()
            || args.obstacles != 1
            || args.registration != spot_nav_examples::Registration::PointToPlane
        {
            bail!(
                "--floors {} maps by the floors tour with point-to-plane ICP and walks random goals \
                 across floors with no boxes dropped: --goal, --kidnap, --frontier, --obstacles \
                 and --registration loam are for one floor",
                args.floors
            );
        }
        return floors::floors_mission(&config, slam_settings, &nav_config, args.goals, &args.out);
    }
    let mapping = MappingSettings {
        registration: args.registration,
        slam: slam_settings,
        navigator: &nav_config,
        explorer: &explorer_config,
        max_scans: args.max_scans,
        start: args.start,
    };
    let Mapped {
        mut spot,
        frames,
        map,
        navigation,
        map_t_body,
        start,
        mut trajectories,
        frontiers_left,
        lap,
        exploration,
    } = if args.lap {
        by_lap(&config, mapping)?
    } else {
        by_exploring(&config, mapping)?
    };
    let mut building = spot.building().clone();
    let exploration_failure = exploration
        .as_ref()
        .and_then(|e| e.failure(args.min_coverage / 100.0));

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
        &map,
        &navigation,
        map_t_body * kidnap,
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

    // Goals (world frame) from where the mapping ended; none when the exploration failed.
    let here = spot.position();
    let goals_world: Vec<Vector2<f64>> = if exploration_failure.is_some() {
        Vec::new()
    } else if args.goal.is_empty() {
        // After an exploration: only where it mapped free floor that the robot can reach on
        // the map, never in unknown space (the lap's goals keep today's draws).
        let reachable = ReachableCells::from(nav.grid(), map_t_body.translation.vector.xy());
        let occupancy = navigation.occupancy();
        let explored = |p: Vector2<f64>| {
            args.lap
                || (reachable.contains(p) && {
                    let (x, y) = occupancy.geometry().cell_coords(p);
                    matches!((u32::try_from(x), u32::try_from(y)), (Ok(x), Ok(y))
                        if occupancy.state(Cell::new(x, y)) == CellState::Free)
                })
        };
        random_goals(
            &building,
            &map,
            nav.grid(),
            explored,
            &frames,
            here,
            if args.lap { here } else { start },
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

    let mut overlay = Overlay {
        start: Some(frames.to_map(start)),
        explored: trajectories
            .1
            .iter()
            .map(|p| p.pose.translation.vector.xy())
            .collect(),
        frontiers: frontiers_left,
        goals: goals.clone(),
        ..Overlay::default()
    };
    let explored_scans = trajectories.1.len();
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
    overlay.walked = trajectories.1[explored_scans.saturating_sub(1)..]
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
        mode: if args.lap { "lap" } else { "explore" },
        building: value_name(&BuildingSize::chosen(args)),
        mapping: lap,
        exploration,
        obstacles,
        goals: legs,
        reached,
        collisions,
    };
    write_outputs(
        &args.out,
        &map,
        navigation.occupancy(),
        nav.grid(),
        &overlay,
        &trajectories,
        &summary,
    )?;
    if let Some(failure) = exploration_failure {
        bail!("{failure}");
    }
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
