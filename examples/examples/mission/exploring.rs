//! The exploration: Spot from a random reachable spot, the Graph-SLAM engine mapping live, the
//! explorer sending it from frontier to frontier until no reachable one is left; measured
//! against the simulator's floor plan and ground truth.

use anyhow::{Context, Result};
use nalgebra::Vector2;
use slam_core::io::StampedPose;
use slam_core::{GraphSlam, MapRegistrator, Optimizer, PointCloud, Pose3};
use spot_adapter::nav::{
    ExplorationOutcome, ExplorerConfig, NavigationMap, NavigatorConfig, explore, find_frontiers,
};
use spot_adapter::pipelines::point_to_plane_tracker;
use spot_adapter::sim::{Building, CommandedSpot, Route, RouteConfig, SimRng, floor_coverage};
use spot_nav_examples::{Progress, evaluate, out};

use crate::args::StartArea;
use crate::legs::Frames;
use crate::report::ExplorationSummary;

/// What the exploration left the legs: the map, where the robot is, and its figures.
pub(crate) struct Explored {
    pub(crate) map: PointCloud,
    /// The occupancy of the last decision (every keyframe square at its optimised pose).
    pub(crate) navigation: NavigationMap,
    /// The engine's estimate of the body at the end (map frame).
    pub(crate) map_t_body: Pose3,
    pub(crate) summary: ExplorationSummary,
    /// The body's estimate (optimised, per scan) and its ground truth, both in the map frame.
    pub(crate) trajectories: (Vec<StampedPose>, Vec<StampedPose>),
    /// Cell centres of the frontiers left on the final map (map frame).
    pub(crate) frontiers_left: Vec<Vector2<f64>>,
}

impl ExplorationSummary {
    /// Why the exploration failed, if it did: below `min_coverage` (a share), or a collision.
    pub(crate) fn failure(&self, min_coverage: f64) -> Option<String> {
        let s = self;
        let stopped = match s.outcome {
            "complete" => "no reachable frontier left",
            _ => "stopped by the scan budget",
        };
        if s.coverage < min_coverage {
            Some(format!(
                "exploration failed: {stopped} with {:.1} % of the reachable floor known free, below --min-coverage {:.1} %",
                100.0 * s.coverage,
                100.0 * min_coverage
            ))
        } else if s.collisions > 0 {
            Some(format!("exploration failed: {} collisions", s.collisions))
        } else {
            None
        }
    }
}

/// A random spot (world frame) and heading drawn from a generator seeded by `seed`: on the
/// corridor loop's centre line (`StartArea::Corridor`), or anywhere in `building` at least 0.6 m
/// from every obstacle and reachable from the corridor loop's first corner
/// (`StartArea::Anywhere`: rooms included, not a room shut off).
pub(crate) fn random_start(
    building: &Building,
    area: StartArea,
    seed: u64,
) -> Result<(Vector2<f64>, f64)> {
    let mut rng = SimRng::new(seed, 0x57a7);
    let size = building.size();
    let corridor = Route::corridor_loop(building);
    let corner = building.corridor_loop()[0];
    for _ in 0..100_000 {
        let p = match area {
            StartArea::Corridor => corridor.point_at(rng.range(0.0, corridor.length())),
            StartArea::Anywhere => Vector2::new(rng.range(0.0, size.x), rng.range(0.0, size.y)),
        };
        if building.clearance(p) >= 0.6
            && Route::between(building, corner, p, &RouteConfig::default()).is_ok()
        {
            return Ok((p, rng.range(-std::f64::consts::PI, std::f64::consts::PI)));
        }
    }
    anyhow::bail!("no reachable start found in the building")
}

/// Explores with `spot` from where it stands through `slam` (a fresh engine: its map frame is
/// the body's start pose, `frames`), at most `max_scans` scans; prints the figures.
pub(crate) fn explore_building<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    mut slam: GraphSlam<R, C, O>,
    spot: &mut CommandedSpot,
    frames: &Frames,
    navigator: &NavigatorConfig,
    explorer: &ExplorerConfig,
    max_scans: usize,
) -> Result<Explored> {
    let start = spot.position();
    let map_t_world = frames.world_t_map.inverse();
    let mut truth_world: Vec<StampedPose> = Vec::new();
    let mut truth_map: Vec<StampedPose> = Vec::new();
    let (mut walked, mut last) = (0.0f64, None::<Vector2<f64>>);
    let mut compute_ms = Vec::new();
    let mut progress = Progress::new("exploring", "scans", None);
    let started = std::time::Instant::now();
    // The tracker's settings (a 0.2 m map, normals when first needed) to localise on each
    // decision's map: the navigator is made afresh on every decision, and the localiser's
    // normals up front on a 0.1 m map took as long as the rest of the decision.
    let report = explore(
        spot,
        &mut slam,
        &point_to_plane_tracker(),
        navigator,
        explorer,
        max_scans,
        |cycle| {
            compute_ms.push(cycle.compute_ms);
            let Some(world_t_body) = cycle.sample.ground_truth else {
                return;
            };
            let here = world_t_body.translation.vector.xy();
            walked += last.map_or(0.0, |p| (here - p).norm());
            last = Some(here);
            truth_world.push(StampedPose {
                stamp: cycle.sample.stamp,
                pose: world_t_body,
            });
            truth_map.push(StampedPose {
                stamp: cycle.sample.stamp,
                pose: map_t_world * world_t_body,
            });
            progress.update(
                truth_map.len() as u64,
                format!(
                    "{walked:.1} m walked, to the frontier at ({:.1}, {:.1}) m",
                    cycle.goal.x, cycle.goal.y
                ),
            );
        },
    )
    .context("exploring")?;
    progress.finish();
    let seconds = started.elapsed().as_secs_f64();
    let body_t_lidar = spot.body_t_lidar();
    let (evaluation, estimate) = evaluate(&slam, &body_t_lidar, Some(&truth_world))?;
    let evaluation = evaluation.context("the exploration has a ground truth")?;
    let occupancy = report.navigation.occupancy();
    let coverage = floor_coverage(
        spot.building(),
        start,
        &frames.world_t_map,
        occupancy,
        navigator.planning.inflation,
    );
    let frontiers_left: Vec<Vector2<f64>> = find_frontiers(occupancy, explorer.min_frontier_cells)
        .iter()
        .flat_map(|f| f.cells.iter())
        .map(|&c| occupancy.geometry().cell_center(c))
        .collect();
    let slam_report = slam.report();
    let summary = ExplorationSummary {
        outcome: match report.outcome {
            ExplorationOutcome::Complete => "complete",
            _ => "gave_up",
        },
        frontier_rule: crate::args::FrontierRule::of(explorer.choice).map_or_else(
            || format!("{:?}", explorer.choice),
            |r| spot_nav_examples::value_name(&r),
        ),
        start: [start.x, start.y],
        coverage: coverage.share(),
        reachable_floor_m2: coverage.reachable_area(),
        walked_m: walked,
        estimated_walked_m: report.walked,
        scans: report.cycles,
        keyframes: slam.keyframe_count(),
        loops_closed: slam_report.loops_closed,
        ate_m: evaluation.ate.rmse,
        decisions: report.decisions,
        decision_ms_mean: mean(&report.decision_ms),
        decision_ms_max: report.decision_ms.iter().copied().fold(0.0, f64::max),
        full_renders: report.full_renders,
        cycle_ms_mean: mean(&compute_ms),
        frontiers_given_up: report.given_up.iter().map(|g| g.reason.name()).collect(),
        frontiers_unreachable: report.last_decision.unreachable.len(),
        frontier_cells_left: frontiers_left.len(),
        collisions: spot.collisions(),
        seconds,
    };
    print_exploration(&summary)?;
    Ok(Explored {
        map: slam.map(0.05)?,
        navigation: report.navigation,
        map_t_body: report.map_t_body,
        summary,
        trajectories: (estimate, truth_map),
        frontiers_left,
    })
}

/// The exploration's line of figures.
fn print_exploration(s: &ExplorationSummary) -> Result<()> {
    out!(
        "exploration {}: {:.1} % of {:.0} m² of reachable floor known free; {:.1} m walked in {} scans, {} keyframes, {} loops closed; ATE {:.3} m; {} decisions ({:.0} ms mean, {:.0} ms max, {} maps rendered afresh), {:.1} ms mean per scan; {} frontiers given up, {} unreachable left; {} collisions; {:.1} s",
        s.outcome,
        100.0 * s.coverage,
        s.reachable_floor_m2,
        s.walked_m,
        s.scans,
        s.keyframes,
        s.loops_closed,
        s.ate_m,
        s.decisions,
        s.decision_ms_mean,
        s.decision_ms_max,
        s.full_renders,
        s.cycle_ms_mean,
        s.frontiers_given_up.len(),
        s.frontiers_unreachable,
        s.collisions,
        s.seconds
    )
}

fn mean(values: &[f64]) -> f64 {
    if values.is_empty() {
        0.0
    } else {
        values.iter().sum::<f64>() / values.len() as f64
    }
}
