//! The commanded simulated Spot as a `Robot`: velocity and trajectory commands, the motion
//! limits, obstacles dropped in its way, and turning in place where it cannot walk.

#![allow(clippy::unwrap_used, clippy::float_cmp)] // Exact stamps and positions are the point.

use nalgebra::{Point3, Vector2};
use slam_core::Pose2;
use spot_adapter::robot::{
    MobilityCommand, Robot, Se2Trajectory, Se2TrajectoryPoint, TrajectoryFrame, VelocityCommand,
};
use spot_adapter::sim::SimError;
use spot_adapter::sim::{
    BoxKind, Building, BuildingConfig, CommandedSpot, SimulationConfig, SolidBox,
};

/// Seed 3's building and a Spot at the corridor loop's first corner, facing along it.
fn spot() -> (CommandedSpot, Vector2<f64>, Vector2<f64>) {
    let building = Building::generate(3, &BuildingConfig::default()).unwrap();
    let start = building.corridor_loop()[0];
    let ahead = (building.corridor_loop()[1] - start).normalize();
    let yaw = ahead.y.atan2(ahead.x);
    let spot = CommandedSpot::new(building, start, yaw, &SimulationConfig::default()).unwrap();
    (spot, start, ahead)
}

#[test]
fn velocity_commands_move_the_body_along_the_exact_arc_within_the_limits() {
    let (mut spot, start, ahead) = spot();
    let first = spot.next_sample().unwrap();
    assert_eq!(first.stamp, 0.0);
    assert_eq!(spot.position(), start, "the first sample is taken standing");
    // 5 m/s is clamped to the 1.6 m/s limit: 0.32 m per 0.2 s turn, straight ahead.
    spot.send(&VelocityCommand::new(5.0, 0.0).into()).unwrap();
    let sample = spot.next_sample().unwrap();
    assert!((sample.stamp - 0.2).abs() < 1e-12);
    let moved = spot.position() - start;
    assert!((moved.norm() - 0.32).abs() < 1e-9, "{}", moved.norm());
    assert!((moved.normalize() - ahead).norm() < 1e-9);
    // A sideways command walks left of the heading.
    let here = spot.position();
    spot.send(&MobilityCommand::Velocity(VelocityCommand {
        forward: 0.0,
        lateral: 0.25,
        yaw_rate: 0.0,
    }))
    .unwrap();
    spot.next_sample().unwrap();
    let left = Vector2::new(-ahead.y, ahead.x);
    assert!((spot.position() - here - 0.05 * left).norm() < 1e-9);
    // Stop holds the robot still.
    spot.stop().unwrap();
    let here = spot.position();
    spot.next_sample().unwrap();
    assert_eq!(spot.position(), here);
    assert_eq!(spot.collisions(), 0);
}

#[test]
fn an_odometry_frame_trajectory_is_tracked_by_the_robots_own_odometry() {
    let (mut spot, start, ahead) = spot();
    let first = spot.next_sample().unwrap();
    // 1.5 m ahead in 4 s, turning 0.5 rad, in the odometry frame (identity at the start).
    let odom_yaw = first.odom_t_body.rotation.euler_angles().2;
    let goal = Pose2::new(Vector2::new(1.5, 0.0), 0.5);
    let trajectory = Se2Trajectory::new(
        TrajectoryFrame::Odom,
        vec![
            Se2TrajectoryPoint {
                time: 0.0,
                pose: Pose2::new(Vector2::zeros(), odom_yaw),
            },
            Se2TrajectoryPoint {
                time: 4.0,
                pose: goal,
            },
        ],
    )
    .unwrap();
    spot.send(&trajectory.clone().into()).unwrap();
    let mut last = first;
    for _ in 0..25 {
        last = spot.next_sample().unwrap();
    }
    // The odometry ends on the trajectory's last pose; the true body near it (the odometry
    // drifts 1.9 % of 1.5 m, under 3 cm).
    let odom = last.odom_t_body.translation.vector.xy();
    assert!((odom - goal.translation.vector).norm() < 1e-4, "{odom}");
    let yaw = last.odom_t_body.rotation.euler_angles().2;
    assert!((yaw - 0.5).abs() < 1e-4, "{yaw}");
    let truth = spot.position() - start;
    assert!((truth - 1.5 * ahead).norm() < 0.05, "{truth}");
    // A frame this robot does not have is refused, naming it.
    let vision = Se2Trajectory::new(TrajectoryFrame::Vision, trajectory.points().to_vec()).unwrap();
    assert!(matches!(
        spot.send(&vision.into()),
        Err(SimError::UnsupportedFrame { frame: "vision" })
    ));
}

#[test]
fn a_box_dropped_ahead_blocks_the_walk_but_not_the_turn() {
    let (mut spot, start, ahead) = spot();
    let wall = start + 0.6 * ahead;
    let half = Vector2::new(0.3, 0.3);
    spot.building_mut()
        .add_box(SolidBox {
            min: Point3::new(wall.x - half.x, wall.y - half.y, 0.0),
            max: Point3::new(wall.x + half.x, wall.y + half.y, 0.6),
            kind: BoxKind::Obstacle,
        })
        .unwrap();
    // The LiDAR sees it: the lowest ring meets the box's top (0.1 m above the body origin)
    // 0.75-0.9 m ahead, where it would meet the floor (0.5 m below) farther out.
    let sample = spot.next_sample().unwrap();
    let lidar = sample.body_t_lidar;
    let close_ahead = sample
        .cloud
        .points()
        .iter()
        .map(|p| lidar * p.cast::<f64>())
        .filter(|p| p.x > 0.25 && p.x < 0.95 && p.y.abs() < 0.3 && (p.z - 0.1).abs() < 0.05)
        .count();
    assert!(close_ahead > 20, "{close_ahead} points on the box");
    spot.send(&VelocityCommand::new(0.6, 0.5).into()).unwrap();
    let yaw_before = spot.body_pose().rotation.euler_angles().2;
    let mut blocked = 0;
    for _ in 0..5 {
        let before = spot.position();
        spot.next_sample().unwrap();
        blocked += usize::from(spot.position() == before);
    }
    assert!(blocked > 0 && spot.collisions() == blocked);
    let turned = spot.body_pose().rotation.euler_angles().2 - yaw_before;
    assert!(
        (turned - 0.5).abs() < 1e-9,
        "turned {turned} rad in 1 s at 0.5 rad/s"
    );
}

#[test]
fn a_walker_crosses_the_corridor_to_and_fro_and_counts_when_it_walks_into_the_robot() {
    let (mut spot, start, ahead) = spot();
    let left = Vector2::new(-ahead.y, ahead.x);
    // A person 2 m ahead, walking 1.2 m sideways and back at 1 m/s.
    let from = start + 2.0 * ahead - 0.6 * left;
    let to = start + 2.0 * ahead + 0.6 * left;
    let half = Vector2::new(0.25, 0.25);
    spot.add_walker(from, to, 1.0, half, 1.7).unwrap();
    let mut seen = Vec::new();
    for _ in 0..13 {
        spot.next_sample().unwrap();
        let b = spot.building().boxes().last().copied().unwrap();
        seen.push(Vector2::new(
            0.5 * (b.min.x + b.max.x),
            0.5 * (b.min.y + b.max.y),
        ));
    }
    // The first sample is taken standing; then 0.2 m per turn: at the far end after 6 turns,
    // back at the start after 12.
    assert!((seen[0] - from).norm() < 1e-9, "{}", seen[0]);
    assert!((seen[6] - to).norm() < 1e-9, "{}", seen[6]);
    assert!((seen[12] - from).norm() < 1e-9, "{}", seen[12]);
    assert_eq!(spot.collisions(), 0, "it never came near the robot");
    // One that walks across the robot's own position collides with it.
    let (mut crossed, start, _) = self::spot();
    crossed
        .add_walker(start - 0.8 * left, start + 0.8 * left, 1.0, half, 1.7)
        .unwrap();
    for _ in 0..10 {
        crossed.next_sample().unwrap();
    }
    assert!(crossed.collisions() > 0);
    assert!(crossed.add_walker(start, start, 1.0, half, 1.7).is_err());
    assert!(crossed.add_walker(from, to, f64::NAN, half, 1.7).is_err());
}
