//! The navigator in closed loop with the commanded simulated Spot: a map of the seed-3 building
//! (scans cast along its corridor loop, placed at their true poses), then walks to goals with
//! drifting odometry, localising against the map every scan. Checked against the simulator's
//! ground truth.
#![allow(clippy::unwrap_used)]

use nalgebra::Vector2;
use slam_core::PointCloud;
use spot_adapter::{
    Building, CommandedSpot, NavigationStep, Navigator, NavigatorConfig, SimulatedSpot,
    SimulationConfig, VelocityCommand, point_to_plane_tracker,
};

/// The building of seed 3 and a map of it: every 4th scan of one lap, at its true pose, thinned
/// to 5 cm.
fn building_and_map() -> (Building, PointCloud) {
    let sim = SimulatedSpot::corridor_loop(3, &SimulationConfig::default()).unwrap();
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

/// Runs the navigator from `start` (facing `yaw`) to `goal` for at most `cycles` scans; returns
/// the final step, the robot, the largest localisation error seen and the distance walked
/// (metres), and the cycles run.
fn run(
    building: &Building,
    map: &PointCloud,
    start: Vector2<f64>,
    yaw: f64,
    goal: Vector2<f64>,
    cycles: usize,
) -> (NavigationStep, CommandedSpot, f64, f64, usize) {
    let config = SimulationConfig::default();
    let mut spot = CommandedSpot::new(building.clone(), start, yaw, &config).unwrap();
    let lidar_height = config.spot.body_height + config.spot.body_t_lidar.translation.z;
    let mut nav = Navigator::new(
        point_to_plane_tracker(),
        map,
        lidar_height,
        spot.body_pose(),
        NavigatorConfig::default(),
    )
    .unwrap();
    let mut sample = spot.sense();
    let (mut worst, mut walked): (f64, f64) = (0.0, 0.0);
    for cycle in 0..cycles {
        let step = nav.step(&sample, goal);
        let truth = sample.ground_truth.unwrap();
        worst = worst.max(
            (nav.pose().translation.vector - truth.translation.vector)
                .xy()
                .norm(),
        );
        match step {
            NavigationStep::Walk(command) => {
                let before = spot.position();
                sample = spot.step(command);
                walked += (spot.position() - before).norm();
            }
            done => return (done, spot, worst, walked, cycle),
        }
    }
    (
        NavigationStep::Walk(VelocityCommand::default()),
        spot,
        worst,
        walked,
        cycles,
    )
}

/// From the corridor into the farthest room and back out to another: arrives within the
/// tolerance (measured on the ground truth), never bumps into anything, and stays localised.
#[test]
fn walks_into_rooms_without_touching_anything() {
    let (building, map) = building_and_map();
    let start = building.corridor_loop()[0];
    // The room whose door is farthest from the start, then one near the start.
    let far = building
        .rooms()
        .iter()
        .max_by(|a, b| (a.door - start).norm().total_cmp(&(b.door - start).norm()))
        .unwrap();
    let goal = far.entry_point();
    let (step, spot, worst, walked, cycles) = run(&building, &map, start, 0.0, goal, 1500);
    eprintln!(
        "({:.2}, {:.2}) to ({:.2}, {:.2}), {:.1} m apart: {step:?} after {cycles} scans and {walked:.1} m, ended {:.3} m from the goal, {} collisions, localisation error up to {:.3} m",
        start.x,
        start.y,
        goal.x,
        goal.y,
        (goal - start).norm(),
        (spot.position() - goal).norm(),
        spot.collisions(),
        worst
    );
    assert_eq!(step, NavigationStep::Arrived);
    assert!(
        (spot.position() - goal).norm() < 0.3,
        "ended at {}",
        spot.position()
    );
    assert_eq!(spot.collisions(), 0);
    assert!(worst < 0.1, "localisation error {worst} m");
}

/// A goal off the map is answered with `NoPath` on the first cycle, without a step.
#[test]
fn unreachable_goals_are_answered() {
    let (building, map) = building_and_map();
    let start = building.corridor_loop()[0];
    let outside = Vector2::new(-5.0, -5.0);
    let (step, spot, ..) = run(&building, &map, start, 0.0, outside, 5);
    assert_eq!(step, NavigationStep::NoPath);
    assert_eq!(spot.position(), start);
}
