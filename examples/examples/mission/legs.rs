//! The legs of the navigation: the frames, random goals, and one leg driven to its goal.

use anyhow::{Result, bail};
use nalgebra::{Point3, Vector2};
use slam_core::io::StampedPose;
use slam_core::{PointCloud, Pose3, Registrator};
use spot_adapter::nav::{DriveOutcome, Goal, Navigator, drive};
use spot_adapter::sim::{Building, CommandedSpot, Route, RouteConfig, SimRng};
use spot_nav_examples::Progress;

/// Scans a leg may take before the robot gives up (5 minutes at 5 Hz).
pub(crate) const MAX_CYCLES: usize = 1500;

/// The world and map frames of the run: the map frame is the odometry frame of the mapping
/// (lap or exploration), which starts at the first body pose.
pub(crate) struct Frames {
    pub(crate) world_t_map: Pose3,
}

impl Frames {
    pub(crate) fn to_world(&self, p: Vector2<f64>) -> Vector2<f64> {
        (self.world_t_map * Point3::new(p.x, p.y, 0.0)).coords.xy()
    }

    pub(crate) fn to_map(&self, p: Vector2<f64>) -> Vector2<f64> {
        (self.world_t_map.inverse() * Point3::new(p.x, p.y, 0.0))
            .coords
            .xy()
    }
}

/// `count` goals in the building (world frame): at least 0.6 m from every obstacle, in space
/// the mapping saw (a floor point of the map within 0.25 m, free on the planning `grid`, and
/// `on_map` at its map-frame position), at least 5 m from the one before (the first from
/// `start`) and reachable from it with Spot's clearance on the true floor plan (the first from
/// `route_start`: where the robot stands may lie closer to a wall than that clearance, after an
/// exploration, and any place the robot reached is connected to where it started).
#[allow(clippy::too_many_arguments)] // Each is one thing a goal is checked against.
pub(crate) fn random_goals(
    building: &Building,
    map: &PointCloud,
    grid: &slam_core::BitGrid,
    on_map: impl Fn(Vector2<f64>) -> bool,
    frames: &Frames,
    start: Vector2<f64>,
    route_start: Vector2<f64>,
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
        let (from, route_from) = goals.last().map_or((start, route_start), |&g| (g, g));
        let p = Vector2::new(rng.range(0.0, size.x), rng.range(0.0, size.y));
        let on_grid = frames.to_map(p);
        let free_on_map = grid.cell_at(on_grid).is_some_and(|c| !grid.is_blocked(c));
        if seen.contains(&key(p))
            && free_on_map
            && on_map(on_grid)
            && building.clearance(p) >= 0.6
            && (p - from).norm() >= 5.0
            && Route::between(building, route_from, p, &RouteConfig::default()).is_ok()
        {
            goals.push(p);
        }
    }
    bail!("found only {} of {count} reachable goals", goals.len())
}

/// What one leg did, measured on the ground truth.
pub(crate) struct Leg {
    pub(crate) outcome: DriveOutcome,
    pub(crate) cycles: usize,
    pub(crate) walked: f64,
    pub(crate) worst: f64,
    pub(crate) cycle_ms: Vec<f64>,
    pub(crate) planned: Vec<Vector2<f64>>,
}

/// Runs `nav` on `spot` to `goal` (map frame) through `nav::drive` until it arrives, stops or
/// reaches the scan limit; appends the estimate and the truth (map frame).
pub(crate) fn leg<R: Registrator>(
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
