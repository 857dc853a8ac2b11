//! The navigator in closed loop with the commanded simulated Spot: a map of the seed-3 building
//! (scans cast along its corridor loop, placed at their true poses), then walks to goals with
//! drifting odometry, localising against the map every scan. Checked against the simulator's
//! ground truth.
#![allow(clippy::unwrap_used)]

use nalgebra::Vector2;
use registration::{IcpConfig, PointToPlaneIcp};
use slam_core::PointCloud;
use spot_adapter::AdapterError;
use spot_adapter::nav::{
    DriveOutcome, LocaliserConfig, Navigator, NavigatorConfig, drive, navigation_grid,
};
use spot_adapter::pipelines::point_to_plane_tracker;
use spot_adapter::robot::Robot;
use spot_adapter::sim::{
    Building, BuildingConfig, CommandedSpot, Route, SimulatedSpot, SimulationConfig,
};

/// The building of seed 3 and a map of it: every 4th scan of one lap, at its true pose, thinned
/// to 5 cm.
fn building_and_map() -> (Building, PointCloud) {
    // Building 3 with the noise and drift of seed 0.
    let building = Building::generate(3, &BuildingConfig::default()).unwrap();
    let lap = Route::corridor_loop(&building);
    let sim = SimulatedSpot::new(building, &lap, &SimulationConfig::default()).unwrap();
    let building = sim.building().clone();
    let body_t_lidar = sim.body_t_lidar();
    let mut points = Vec::new();
    for sample in sim.step_by(4) {
        let world_t_lidar = sample.ground_truth.unwrap() * body_t_lidar;
        points.extend_from_slice(sample.cloud.transformed(&world_t_lidar).points());
    }
    let map = PointCloud::from_points(points)
        .voxel_downsample(0.05)
        .unwrap();
    (building, map)
}

/// What a run did, measured on the ground truth.
struct Run {
    outcome: DriveOutcome,
    spot: CommandedSpot,
    /// Largest localisation error (metres).
    worst: f64,
    /// Metres walked.
    walked: f64,
    cycles: usize,
    /// Scans taken standing in a blocked cell of the building's true 0.10 m occupancy grid.
    in_obstacle_cells: usize,
}

/// Drives the robot from `start` (facing `yaw`) to `goal` for at most `cycles` scans, through
/// the `Robot` interface as any robot is driven.
fn run(
    building: &Building,
    map: &PointCloud,
    start: Vector2<f64>,
    yaw: f64,
    goal: Vector2<f64>,
    cycles: usize,
) -> Run {
    let config = SimulationConfig::default();
    let mut spot = CommandedSpot::new(building.clone(), start, yaw, &config).unwrap();
    let truth_grid = building.occupancy_grid(0.1).unwrap();
    let lidar_height = config.spot.body_height + config.spot.body_t_lidar.translation.z;
    let grid = navigation_grid(map, lidar_height, &NavigatorConfig::default()).unwrap();
    let mut nav = Navigator::new(
        point_to_plane_tracker(),
        map,
        &grid,
        spot.body_pose(),
        spot.description(),
        NavigatorConfig::default(),
    )
    .unwrap();
    let (mut worst, mut walked, mut in_obstacle_cells) = (0.0f64, 0.0, 0);
    let mut last: Option<Vector2<f64>> = None;
    let report = drive(&mut spot, &mut nav, goal, cycles, |cycle| {
        let truth = cycle.sample.ground_truth.unwrap().translation.vector.xy();
        worst = worst.max((cycle.estimate.translation.vector.xy() - truth).norm());
        walked += last.map_or(0.0, |p| (truth - p).norm());
        last = Some(truth);
        if truth_grid
            .cell_at(truth)
            .is_none_or(|c| truth_grid.is_blocked(c))
        {
            in_obstacle_cells += 1;
        }
    })
    .unwrap();
    Run {
        outcome: report.outcome,
        spot,
        worst,
        walked,
        cycles: report.cycles,
        in_obstacle_cells,
    }
}

/// From the corridor into the room whose door is farthest away: arrives within the tolerance
/// (measured on the ground truth), never bumps into anything or stands in an obstacle cell, and
/// stays localised.
#[test]
fn walks_into_rooms_without_touching_anything() {
    let (building, map) = building_and_map();
    let start = building.corridor_loop()[0];
    let far = building
        .rooms()
        .iter()
        .max_by(|a, b| (a.door - start).norm().total_cmp(&(b.door - start).norm()))
        .unwrap();
    let goal = far.entry_point();
    let o = run(&building, &map, start, 0.0, goal, 1500);
    let end = (o.spot.position() - goal).norm();
    eprintln!(
        "({:.2}, {:.2}) to ({:.2}, {:.2}), {:.1} m apart: {:?} after {} scans and {:.1} m, ended {end:.3} m from the goal, {} collisions, {} scans in obstacle cells, localisation error up to {:.3} m",
        start.x,
        start.y,
        goal.x,
        goal.y,
        (goal - start).norm(),
        o.outcome,
        o.cycles,
        o.walked,
        o.spot.collisions(),
        o.in_obstacle_cells,
        o.worst
    );
    assert_eq!(o.outcome, DriveOutcome::Arrived);
    assert!(end < 0.3, "ended at {}", o.spot.position());
    assert_eq!(o.spot.collisions(), 0);
    assert_eq!(o.in_obstacle_cells, 0);
    assert!(o.worst < 0.1, "localisation error {} m", o.worst);
}

/// A goal off the map is answered with `NoPath` on the first cycle, without a step.
#[test]
fn unreachable_goals_are_answered() {
    let (building, map) = building_and_map();
    let start = building.corridor_loop()[0];
    let outside = Vector2::new(-5.0, -5.0);
    let o = run(&building, &map, start, 0.0, outside, 5);
    assert_eq!(o.outcome, DriveOutcome::NoPath);
    assert_eq!(o.cycles, 1, "answered on the first cycle");
    assert_eq!(o.spot.position(), start);
}

/// A goal that is not a finite point is an error before anything moves.
#[test]
fn a_non_finite_goal_is_an_error_before_any_step() {
    let (building, map) = building_and_map();
    let config = SimulationConfig::default();
    let start = building.corridor_loop()[0];
    let mut spot = CommandedSpot::new(building, start, 0.0, &config).unwrap();
    let lidar_height = config.spot.body_height + config.spot.body_t_lidar.translation.z;
    let grid = navigation_grid(&map, lidar_height, &NavigatorConfig::default()).unwrap();
    let mut nav = Navigator::new(
        point_to_plane_tracker(),
        &map,
        &grid,
        spot.body_pose(),
        spot.description(),
        NavigatorConfig::default(),
    )
    .unwrap();
    let goal = Vector2::new(f64::NAN, f64::NAN);
    let result = drive(&mut spot, &mut nav, goal, 10, |_| {});
    assert!(
        matches!(
            result,
            Err(spot_adapter::DriveError::Navigation(
                AdapterError::NonFiniteGoal { .. }
            ))
        ),
        "{result:?}"
    );
    assert_eq!(spot.position(), start);
}

/// A scan that does not belong where the odometry says the robot is (taken 0.5 m away) cannot
/// drag the estimate away: a wide registration (point-to-plane with Huber weights, pairs within
/// 1.5 m) would move it there, as a navigator that allows 1 m corrections shows, but with the
/// default limit the correction is rejected and the prediction stands, until further scans
/// confirm it.
#[test]
fn a_jump_is_rejected_until_confirmed() {
    let (building, map) = building_and_map();
    let config = SimulationConfig::default();
    let start = building.corridor_loop()[0];
    let ahead = (building.corridor_loop()[1] - start).normalize();
    let mut here = CommandedSpot::new(building.clone(), start, 0.0, &config).unwrap();
    let side = Vector2::new(-ahead.y, ahead.x);
    let offset = 0.4 * ahead + 0.3 * side;
    let mut there = CommandedSpot::new(building, start + offset, 0.0, &config).unwrap();
    let lidar_height = config.spot.body_height + config.spot.body_t_lidar.translation.z;
    let goal = start + 5.0 * ahead;
    let grid = navigation_grid(&map, lidar_height, &NavigatorConfig::default()).unwrap();
    let mut moved_by = |max_correction: f64| {
        let wide = PointToPlaneIcp {
            config: IcpConfig {
                max_correspondence_distance: 1.5,
                ..IcpConfig::default()
            },
        };
        let mut nav = Navigator::new(
            wide,
            &map,
            &grid,
            here.body_pose(),
            here.description(),
            NavigatorConfig {
                localiser: LocaliserConfig {
                    max_correction,
                    ..LocaliserConfig::default()
                },
                ..NavigatorConfig::default()
            },
        )
        .unwrap();
        nav.step(&here.sense(), goal).unwrap();
        assert_eq!(nav.localisation_failures(), 0);
        let mut moved = Vec::new();
        // The same scan taken there, three times while the odometry says the robot stands here.
        for _ in 0..3 {
            let mut wrong = there.sense();
            wrong.odom_t_body = here.sense().odom_t_body;
            nav.step(&wrong, goal).unwrap();
            moved
                .push((nav.pose().translation.vector - here.body_pose().translation.vector).norm());
        }
        (moved, nav.localisation_failures())
    };
    let (free, _) = moved_by(1.0);
    assert!(
        (free[0] - 0.5).abs() < 0.05,
        "registration alone moves it {} m",
        free[0]
    );
    let (gated, failures) = moved_by(LocaliserConfig::default().max_correction);
    assert!(
        gated[0] < 0.02 && gated[1] < 0.02,
        "the estimate moved {gated:?} m"
    );
    assert_eq!(failures, 2);
    // A third scan that agrees confirms the correction: a genuine recovery is not blocked.
    assert!((gated[2] - 0.5).abs() < 0.05, "{gated:?}");
}
