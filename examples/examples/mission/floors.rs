//! `mission --floors N`: a building of several floors mapped by a scripted tour of every floor
//! by the stairs, a grid per floor with the flights marked and linked, then goals each on
//! another floor than the one before, walked to by the stairs (`drive_across_floors`).

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use gridmap::{FloorLevels, FloorLevelsConfig};
use nalgebra::{Point3, Vector2};
use serde::Serialize;
use slam_core::{GraphSlamConfig, PointCloud, Pose3};
use spot_adapter::nav::{
    DriveOutcome, FloorCell, FloorGraph, FloorMaps, FloorPoint, NavigatorConfig, StairsClimbConfig,
    drive_across_floors,
};
use spot_adapter::pipelines::{point_to_plane_localiser, point_to_plane_slam, scan_context_places};
use spot_adapter::sim::{Building, CommandedSpot, SimRng, SimulatedSpot, SimulationConfig};
use spot_nav_examples::out;

use crate::legs::Frames;
use crate::mapping::map_walk;
use crate::report::MappingSummary;

/// A goal counts as reached within this distance of the true body (metres), on its floor.
const REACHED_WITHIN: f64 = 0.10;
/// Goals lie at least this far from every obstacle of their floor (metres).
const GOAL_CLEARANCE: f64 = 0.6;
/// Samples a leg may take (a leg crosses up to two floors of a 1,500 m2 office).
const MAX_CYCLES: usize = 6000;

/// One leg of the walk across floors, as `summary.json` gives it.
#[derive(Clone, Debug, Serialize)]
struct FloorLeg {
    /// The goal's floor and where it is (map frame, metres).
    floor: usize,
    goal: [f64; 2],
    outcome: &'static str,
    /// Arrived on the goal's floor within 0.10 m of the goal by the ground truth.
    reached: bool,
    final_error_m: f64,
    /// The floor the robot stands on at the end, by the simulator.
    true_floor: usize,
    flights: usize,
    collisions: usize,
    cycles: usize,
    /// The route's length over the floors' grids and the stairs (metres).
    route_m: Option<f64>,
    seconds: f64,
}

/// `summary.json` of a mission over several floors.
#[derive(Clone, Debug, Serialize)]
struct FloorsSummary {
    seed: u64,
    floors: usize,
    mapping: MappingSummary,
    /// Cells marked as stairs on each floor's grid.
    stairs_cells: Vec<usize>,
    flights_linked: usize,
    legs: Vec<FloorLeg>,
    goals_reached: usize,
}

/// The mission over `config.building.floors` floors: map by the floors tour, then `goals`
/// goals; results written to `out_dir`. Fails (the example exits 1) when a goal is missed.
pub(crate) fn floors_mission(
    config: &SimulationConfig,
    slam: GraphSlamConfig,
    nav_config: &NavigatorConfig,
    goals: usize,
    out_dir: &Path,
) -> Result<()> {
    let sim = SimulatedSpot::floors_tour(config)?;
    let building = sim.building().clone();
    let truth = sim.ground_truth();
    let body_t_lidar = sim.body_t_lidar();
    let frames = Frames {
        world_t_map: truth.first().context("empty tour")?.pose,
    };
    let tour_end = truth.last().context("empty tour")?.pose;
    out!(
        "building    seed {}: {:.1} x {:.1} m, {} floors, {} rooms a floor",
        config.seed,
        building.size().x,
        building.size().y,
        building.floors(),
        building.rooms().len()
    )?;
    let mut engine = point_to_plane_slam(slam)?.with_place_recognizer(scan_context_places());
    let mapping = map_walk(&mut engine, sim, "tour")?;
    let positions: Vec<Point3<f64>> = engine
        .scan_trajectory()
        .iter()
        .map(|p| Point3::from(p.pose.translation.vector))
        .collect();
    let floors = FloorLevels::split(&positions, &FloorLevelsConfig::default())?;
    if floors.levels().len() != building.floors() {
        bail!(
            "the walk split into {} floors by height, the building has {}",
            floors.levels().len(),
            building.floors()
        );
    }
    let loaded = engine.keyframe_scans().collect::<Result<Vec<_>, _>>()?;
    let keyframes: Vec<(Pose3, &PointCloud)> =
        loaded.iter().map(|(p, c)| (*p, c.as_ref())).collect();
    let lidar_height = config.spot.body_height + config.spot.body_t_lidar.translation.z;
    let maps = FloorMaps::build(
        &keyframes,
        &positions,
        &floors,
        lidar_height,
        &nav_config.map_config(),
        nav_config.planning.inflation,
    )
    .context("building a grid per floor and the stairs between them")?;
    let clouds = maps
        .clouds(&keyframes, 0.05)
        .context("each floor's localisation cloud")?;
    let stairs_cells = print_floors(&maps)?;
    let mut spot = CommandedSpot::new(
        building.clone(),
        tour_end.translation.vector.xy(),
        tour_end.rotation.euler_angles().2,
        config,
    )?;
    let map_t_body = engine
        .current_lidar_pose()
        .context("the tour gave the engine no scan")?
        * body_t_lidar.inverse();
    let goals = floor_goals(&building, &maps, &frames, goals, config.seed)?;
    write_grids(&maps, &clouds, &goals, out_dir)?;
    let legs = walk_goals(
        &mut spot, &maps, &clouds, nav_config, &frames, &goals, map_t_body,
    )?;
    finish(
        &FloorsSummary {
            seed: config.seed,
            floors: floors.levels().len(),
            mapping,
            stairs_cells,
            flights_linked: maps.links().len(),
            goals_reached: legs.iter().filter(|l| l.reached).count(),
            legs,
        },
        out_dir,
    )
}

/// Prints the goals' tally, writes `summary.json` to `out_dir`; fails when a goal was missed
/// or the robot collided.
fn finish(summary: &FloorsSummary, out_dir: &Path) -> Result<()> {
    let reached = summary.goals_reached;
    let collisions: usize = summary.legs.iter().map(|l| l.collisions).sum();
    out!(
        "goals       {reached} of {} reached within {REACHED_WITHIN} m on their floor, {collisions} collisions",
        summary.legs.len()
    )?;
    std::fs::create_dir_all(out_dir).with_context(|| format!("creating {}", out_dir.display()))?;
    let json = serde_json::to_string_pretty(summary)?;
    std::fs::write(out_dir.join("summary.json"), json)
        .with_context(|| format!("writing {}", out_dir.join("summary.json").display()))?;
    out!(
        "wrote       {}: grid_floor{{k}}.png, map_floor{{k}}.yaml + .pgm, map_floor{{k}}.ply, summary.json",
        out_dir.display()
    )?;
    if reached < summary.legs.len() || collisions > 0 {
        bail!(
            "{} of {} goals missed, {collisions} collisions",
            summary.legs.len() - reached,
            summary.legs.len()
        );
    }
    Ok(())
}

/// Walks `spot` from `map_t_body` on the ground floor to each of `goals` in turn across the
/// floors of `maps`; prints and returns each leg against the simulator's truth.
fn walk_goals(
    spot: &mut CommandedSpot,
    maps: &FloorMaps,
    clouds: &[PointCloud],
    nav_config: &NavigatorConfig,
    frames: &Frames,
    goals: &[FloorPoint],
    map_t_body: Pose3,
) -> Result<Vec<FloorLeg>> {
    let registrator = point_to_plane_localiser();
    let (mut floor, mut pose) = (0, map_t_body);
    let mut legs = Vec::new();
    for (k, goal) in goals.iter().enumerate() {
        let started = Instant::now();
        let before = spot.collisions();
        let report = drive_across_floors(
            spot,
            maps,
            clouds,
            &registrator,
            nav_config,
            StairsClimbConfig::default(),
            (floor, pose),
            *goal,
            MAX_CYCLES,
        )?;
        let truth = spot.body_pose().translation.vector.xy();
        let error = (frames.to_map(truth) - goal.at).norm();
        let reached = report.outcome == DriveOutcome::Arrived
            && error <= REACHED_WITHIN
            && spot.floor() == goal.floor;
        let leg = FloorLeg {
            floor: goal.floor,
            goal: [goal.at.x, goal.at.y],
            outcome: report.outcome.name(),
            reached,
            final_error_m: error,
            true_floor: spot.floor(),
            flights: report.flights,
            collisions: spot.collisions() - before,
            cycles: report.cycles,
            route_m: report.route.as_ref().map(|r| r.length),
            seconds: started.elapsed().as_secs_f64(),
        };
        out!(
            "leg {:<2}      floor {} -> {} ({:.1}, {:.1}): {}, {:.3} m off on floor {}, {} flight(s), {} collisions, {} cycles, route {:.1} m, {:.1} s",
            k + 1,
            floor,
            goal.floor,
            goal.at.x,
            goal.at.y,
            leg.outcome,
            error,
            leg.true_floor,
            leg.flights,
            leg.collisions,
            leg.cycles,
            leg.route_m.unwrap_or(f64::NAN),
            leg.seconds
        )?;
        legs.push(leg);
        (floor, pose) = (report.floor, report.pose);
    }
    Ok(legs)
}

/// Prints the floors' grids and stairs; returns the stairs cells on each floor's grid.
fn print_floors(maps: &FloorMaps) -> Result<Vec<usize>> {
    let floors = maps.floors().levels().len();
    let stairs_cells: Vec<usize> = (0..floors)
        .map(|k| match maps.map(k) {
            Some(Ok(map)) => map.occupancy().stairs().count_blocked(),
            _ => 0,
        })
        .collect();
    out!(
        "floors      {floors} grids; stairs cells per floor {stairs_cells:?}; {} flight(s) linked",
        maps.links().len()
    )?;
    Ok(stairs_cells)
}

/// A picture (`grid_floor{k}.png`: the stairs teal, the inflation orange, the stairs' ends and
/// the floor's goals red), a ROS map (`map_floor{k}.yaml` + `.pgm`) and the map cloud
/// (`map_floor{k}.ply`, from `clouds`) per floor in `dir`.
fn write_grids(
    maps: &FloorMaps,
    clouds: &[PointCloud],
    goals: &[FloorPoint],
    dir: &Path,
) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    for (k, cloud) in clouds.iter().enumerate() {
        let (Some(Ok(map)), Some(planning)) = (maps.map(k), maps.planning(k)) else {
            continue;
        };
        let mut marks: Vec<slam_core::Cell> = maps
            .links()
            .iter()
            .flat_map(|l| [l.foot, l.top])
            .filter(|end| end.floor == k)
            .map(|end| end.cell)
            .collect();
        marks.extend(
            goals
                .iter()
                .filter(|g| g.floor == k)
                .filter_map(|g| planning.cell_at(g.at)),
        );
        let occupancy = map.occupancy();
        gridmap::write_png(
            dir.join(format!("grid_floor{k}.png")),
            occupancy,
            Some(planning),
            &[],
            &marks,
        )?;
        gridmap::write_ros_map(occupancy, dir.join(format!("map_floor{k}.yaml")))?;
        slam_core::io::write_ply(
            dir.join(format!("map_floor{k}.ply")),
            cloud,
            slam_core::io::PlyEncoding::BinaryLittleEndian,
        )?;
    }
    Ok(())
}

/// `count` goals (map frame), each on another floor than the one before (the first off the
/// ground floor): random points of the building at least [`GOAL_CLEARANCE`] from the true
/// obstacles of their floor, free on that floor's planning grid and reachable over the
/// floors' grids and stairs from the goal before (the first from the tour's start).
fn floor_goals(
    building: &Building,
    maps: &FloorMaps,
    frames: &Frames,
    count: usize,
    seed: u64,
) -> Result<Vec<FloorPoint>> {
    let floors = maps.floors().levels().len();
    let grids: Vec<_> = (0..floors)
        .map(|k| maps.planning(k).context("a floor has no grid"))
        .collect::<Result<_>>()?;
    let graph = FloorGraph::new(grids.clone(), maps.links().to_vec())?;
    let mut rng = SimRng::new(seed, 0xf100_0125);
    let mut from = FloorCell {
        floor: 0,
        cell: grids[0]
            .cell_at(Vector2::zeros())
            .context("the tour's start is off the ground floor's grid")?,
    };
    let mut goals = Vec::new();
    for k in 0..count {
        let floor = (from.floor + 1 + rng.index(floors - 1)) % floors;
        let mut found = None;
        for _ in 0..5000 {
            let world = Vector2::new(
                rng.range(0.0, building.size().x),
                rng.range(0.0, building.size().y),
            );
            if building.clearance_on(floor, world, None) < GOAL_CLEARANCE {
                continue;
            }
            let at = frames.to_map(world);
            let Some(cell) = grids[floor].cell_at(at) else {
                continue;
            };
            if grids[floor].is_blocked(cell) {
                continue;
            }
            let to = FloorCell { floor, cell };
            if graph.route(from, to)?.is_some() {
                found = Some((to, at));
                break;
            }
        }
        let (to, at) =
            found.with_context(|| format!("no reachable goal {} on floor {floor}", k + 1))?;
        goals.push(FloorPoint { floor, at });
        from = to;
    }
    Ok(goals)
}
