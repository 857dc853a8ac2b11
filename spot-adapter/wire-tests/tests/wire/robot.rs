//! The robot's data and commands on the wire: frames, clouds, grids, commands and faults, and
//! the official SDK's own flow against the same fake.

use std::time::{Duration, Instant};

use nalgebra::{Vector2, Vector3};
use serde_json::Value;
use slam_core::{Pose2, Pose3};
use spot_adapter::grpc::{CloudProblem, FrameError, SpotClient, SpotError};
use spot_adapter::robot::{
    MobilityCommand, Robot, Se2Trajectory, Se2TrajectoryPoint, TrajectoryFrame, VelocityCommand,
};

use super::{connect, f, support};
use crate::fake_spot;

#[test]
fn the_frame_tree_gives_any_a_t_b_and_names_unknown_frames() {
    let fake = fake_spot!("frames");
    let spot = connect(&fake);
    let frames = spot.frame_tree().unwrap();
    // The fake's body stands at (1, 2) heading 0.3 rad in odom; vision is (0.5, -0.25, 0.1) in
    // odom; the LiDAR is 0.05 m behind and 0.30 m above the body origin.
    let pose = |x: f64, y: f64, z: f64, yaw: f64| {
        Pose3::new(Vector3::new(x, y, z), Vector3::new(0.0, 0.0, yaw))
    };
    let close = |a: Pose3, b: Pose3| (a.to_homogeneous() - b.to_homogeneous()).norm() < 1e-9;
    let odom_t_body = pose(1.0, 2.0, 0.0, 0.3);
    assert!(close(frames.a_t_b("odom", "body").unwrap(), odom_t_body));
    let vision_t_velodyne =
        pose(0.5, -0.25, 0.0, 0.1).inverse() * odom_t_body * pose(-0.05, 0.0, 0.30, 0.0);
    assert!(close(
        frames.a_t_b("vision", "velodyne").unwrap(),
        vision_t_velodyne
    ));
    assert!(close(
        frames.a_t_b("gpe", "odom").unwrap(),
        pose(0.0, 0.0, 0.5, 0.0)
    ));
    assert_eq!(
        frames.a_t_b("odom", "hand"),
        Err(FrameError::UnknownFrame {
            frame: "hand".to_owned()
        })
    );
}

#[test]
fn a_point_cloud_decodes_to_the_points_the_fake_sent_and_a_sample_carries_its_frames() {
    let mut fake = fake_spot!("cloud");
    let mut spot = connect(&fake);
    let scan = spot.point_cloud().unwrap();
    assert_eq!(scan.frame_name, "velodyne");
    let expected = support::known_points();
    assert_eq!(scan.cloud.len(), expected.len());
    for (p, e) in scan.cloud.points().iter().zip(&expected) {
        assert_eq!([p.x, p.y, p.z], *e);
    }
    let request = fake.requests_of("GetPointCloud").pop().unwrap();
    assert_eq!(request["authority"], "velodyne.spot.robot");
    assert_eq!(
        request["request"]["point_cloud_requests"][0]["point_cloud_source_name"],
        "velodyne-point-cloud"
    );

    let first = spot.next_sample().unwrap();
    let second = spot.next_sample().unwrap();
    assert!(second.stamp > first.stamp, "each sample is a new scan");
    assert!((first.odom_t_body.translation.vector - Vector3::new(1.0, 2.0, 0.0)).norm() < 1e-9);
    assert!((first.body_t_lidar.translation.vector - Vector3::new(-0.05, 0.0, 0.30)).norm() < 1e-9);

    fake.control("malformed-cloud");
    let error = spot.next_sample().unwrap_err();
    assert!(
        matches!(&error, SpotError::MalformedCloud { source_name, problem }
            if source_name == "velodyne-point-cloud"
                && *problem == CloudProblem::DataSize { bytes: 1440, points: 121, needed: 1452 }),
        "{error:?}"
    );
}

#[test]
fn local_grids_decode_raw_and_rle_cells_with_scale_and_offset() {
    let fake = fake_spot!("grids");
    let spot = connect(&fake);
    let grids = spot.local_grids(&["terrain", "no_step"]).unwrap();
    let (terrain, no_step) = (&grids[0], &grids[1]);
    for grid in &grids {
        assert_eq!((grid.num_cells_x, grid.num_cells_y), (16, 12));
        assert!((grid.cell_size - 0.03).abs() < 1e-12);
        assert_eq!(grid.frame_name, "odom");
    }
    for y in 0..12 {
        for x in 0..16 {
            let v = support::grid_value(x, y);
            assert!(
                (terrain.value(x, y).unwrap() - (v * 0.01 - 0.05)).abs() < 1e-12,
                "terrain ({x}, {y})"
            );
            assert_eq!(no_step.value(x, y).unwrap(), v, "no_step ({x}, {y})");
        }
    }
    let blocked = no_step.to_bit_grid(|v| v > 0.0).unwrap();
    let expected = (0..12)
        .flat_map(|y| (0..16).map(move |x| (x, y)))
        .filter(|&(x, y)| support::grid_value(x, y) > 0.0)
        .count();
    assert_eq!(blocked.count_blocked(), expected);
    let error = spot.local_grids(&["stairs"]).unwrap_err();
    assert!(
        matches!(
            error,
            SpotError::NoData {
                status: "STATUS_NO_SUCH_GRID",
                ..
            }
        ),
        "{error:?}"
    );
}

#[test]
fn commands_reach_the_robot_with_frames_end_times_limits_and_the_lease() {
    let fake = fake_spot!("commands", &["--clock-offset", "-3.25"]);
    let mut spot = connect(&fake);
    spot.send(
        &VelocityCommand {
            forward: 0.4,
            lateral: -0.1,
            yaw_rate: 0.2,
        }
        .into(),
    )
    .unwrap();
    // Beyond the limits: clamped to 1.6 m/s and 1.0 rad/s before sending.
    spot.send(&VelocityCommand::new(5.0, -3.0).into()).unwrap();
    let point = |time: f64, x: f64, y: f64, yaw: f64| Se2TrajectoryPoint {
        time,
        pose: Pose2::new(Vector2::new(x, y), yaw),
    };
    let trajectory = Se2Trajectory::new(
        TrajectoryFrame::Vision,
        vec![point(0.0, 1.0, 2.0, 0.3), point(2.5, 1.5, 2.2, 0.5)],
    )
    .unwrap();
    spot.send(&MobilityCommand::Trajectory(trajectory)).unwrap();
    // Up a flight: the stairs mode on.
    spot.send(&MobilityCommand::Stairs(VelocityCommand::new(0.3, 0.0)))
        .unwrap();
    spot.stop().unwrap();

    let commands = fake.requests_of("RobotCommand");
    assert_eq!(commands.len(), 5);
    let lease = &fake.requests_of("AcquireLease");
    assert_eq!(lease.len(), 1);
    let retained_lease = serde_json::json!({"resource": "body", "sequence": [1]});
    for c in &commands {
        assert_eq!(c["authority"], "command.spot.robot");
        assert_eq!(c["request"]["clock_identifier"], "fake-spot-clock");
        assert_eq!(
            c["request"]["lease"]["resource"],
            retained_lease["resource"]
        );
        assert_eq!(
            c["request"]["lease"]["sequence"],
            retained_lease["sequence"]
        );
        assert!(c["request"]["lease"]["epoch"].is_string());
    }
    let mobility =
        |c: &Value| c["request"]["command"]["synchronized_command"]["mobility_command"].clone();
    let velocity = mobility(&commands[0])["se2_velocity_request"].clone();
    assert_eq!(velocity["se2_frame_name"], "body");
    assert_eq!(f(&velocity["velocity"]["linear"]["x"]), 0.4);
    assert_eq!(f(&velocity["velocity"]["linear"]["y"]), -0.1);
    assert_eq!(f(&velocity["velocity"]["angular"]), 0.2);
    assert_eq!(f(&velocity["slew_rate_limit"]["angular"]), 2.0);
    assert_eq!(
        commands[0]["decoded"]["max_vel"],
        serde_json::json!([1.6, 0.5, 1.0])
    );
    let robot_time = f(&commands[0]["robot_time"]);
    assert!((f(&commands[0]["decoded"]["end_time"]) - robot_time - 0.6).abs() < 0.25);

    let clamped = mobility(&commands[1])["se2_velocity_request"]["velocity"].clone();
    assert_eq!(
        (f(&clamped["linear"]["x"]), f(&clamped["angular"])),
        (1.6, -1.0)
    );

    let trajectory = mobility(&commands[2])["se2_trajectory_request"].clone();
    assert_eq!(trajectory["se2_frame_name"], "vision");
    let points = trajectory["trajectory"]["points"].as_array().unwrap();
    assert_eq!(points.len(), 2);
    assert_eq!(f(&points[1]["pose"]["position"]["x"]), 1.5);
    assert_eq!(f(&points[1]["pose"]["angle"]), 0.5);
    let decoded = &commands[2]["decoded"];
    assert_eq!(decoded["point_times"], serde_json::json!([0.0, 2.5]));
    let reference = f(&decoded["reference_time"]);
    assert!(
        (reference - f(&commands[2]["robot_time"])).abs() < 0.1,
        "reference time in robot time"
    );
    assert!(
        (f(&decoded["end_time"]) - reference - 3.5).abs() < 1e-6,
        "2.5 s of points and 1 s slack"
    );

    // The official decoder reads the stairs mode: on for the flight, unset otherwise.
    assert_eq!(commands[0]["decoded"]["stairs_mode"], "STAIRS_MODE_UNKNOWN");
    assert_eq!(commands[3]["decoded"]["stairs_mode"], "STAIRS_MODE_ON");
    let stairs = mobility(&commands[3])["se2_velocity_request"]["velocity"].clone();
    assert_eq!(f(&stairs["linear"]["x"]), 0.3);

    assert!(commands[4]["request"]["command"]["full_body_command"]["stop_request"].is_object());
}

#[test]
fn a_stale_time_sync_stops_motion_but_not_a_stop() {
    let mut fake = fake_spot!("stale");
    let mut config = fake.config();
    config.time_sync.resync_interval = Duration::from_millis(200);
    config.time_sync.max_age = Duration::from_millis(1500);
    let mut spot = SpotClient::connect(config).unwrap();
    std::thread::sleep(Duration::from_secs(2));
    spot.send(&VelocityCommand::new(0.2, 0.0).into())
        .expect("background rounds keep the sync fresh");
    fake.control("stall-time-sync");
    std::thread::sleep(Duration::from_secs(2));
    let sent = fake.requests_of("RobotCommand").len();
    let error = spot
        .send(&VelocityCommand::new(0.2, 0.0).into())
        .unwrap_err();
    assert!(
        matches!(error, SpotError::TimeSyncStale { .. }),
        "{error:?}"
    );
    assert_eq!(
        fake.requests_of("RobotCommand").len(),
        sent,
        "no motion sent on a stale sync"
    );
    spot.stop().expect("a stop needs no time sync");
}

#[test]
fn a_connection_dropped_mid_walk_is_an_error_on_the_next_call() {
    let mut fake = fake_spot!("drop");
    let mut spot = connect(&fake);
    spot.next_sample().unwrap();
    spot.send(&VelocityCommand::new(0.3, 0.0).into()).unwrap();
    fake.control("drop");
    let start = Instant::now();
    let error = spot.next_sample().unwrap_err();
    assert!(
        matches!(
            error,
            SpotError::Unreachable { .. } | SpotError::Timeout { .. }
        ),
        "{error:?}"
    );
    assert!(matches!(
        spot.stop(),
        Err(SpotError::Unreachable { .. } | SpotError::Timeout { .. })
    ));
    assert!(
        start.elapsed() < Duration::from_secs(7),
        "{:?}",
        start.elapsed()
    );
}

#[test]
fn the_official_sdk_runs_the_same_flow_against_the_fake() {
    let fake = fake_spot!("sdk", &["--clock-offset", "7.0"]);
    let report: Value = serde_json::from_slice(&support::run_sdk_flow(&fake, &[])).unwrap();
    assert_eq!(report["serial"], "fake-0001");
    assert!((f(&report["clock_skew"]) - 7.0).abs() < 0.05, "{report}");
    assert_eq!(report["num_points"], 120);
    assert_eq!(report["grids"], serde_json::json!(["terrain", "no_step"]));
    let odom_t_body = report["odom_t_body"].as_array().unwrap();
    assert!((f(&odom_t_body[0]) - 1.0).abs() < 1e-9 && (f(&odom_t_body[1]) - 2.0).abs() < 1e-9);
    // The SDK's commands took the same paths through the fake as ours.
    let commands = fake.requests_of("RobotCommand");
    assert_eq!(commands.len(), 3);
    assert_eq!(commands[0]["decoded"]["kind"], "se2_velocity_request");
    assert_eq!(commands[1]["decoded"]["kind"], "se2_trajectory_request");
    assert_eq!(commands[2]["decoded"]["kind"], "full_body_command");
}
