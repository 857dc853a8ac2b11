//! The navigator drives a Spot over gRPC: a fake Spot on the official `bosdyn-api` servicers
//! serves the simulator's scans and odometry, and the simulated robot moves by the velocity
//! commands the fake decoded. A bridge thread keeps the two in lockstep: publish a scan, wait
//! for the command that answers it, step the simulator by it for one LiDAR turn.
#![allow(clippy::unwrap_used, clippy::panic)]

#[path = "../../tests/integration/common/mod.rs"]
mod common;
mod support;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use nalgebra::Vector2;
use serde_json::Value;
use slam_core::{PointCloud, Pose3};
use spot_adapter::DriveError;
use spot_adapter::grpc::{SpotClient, SpotError};
use spot_adapter::nav::{DriveOutcome, NavigationMap, Navigator, NavigatorConfig, drive};
use spot_adapter::pipelines::point_to_plane_localiser;
use spot_adapter::robot::{Robot, Sample, VelocityCommand};
use spot_adapter::sim::{Building, CommandedSpot, SimulationConfig};

/// The oldest time sync the client moves with in these tests (short, to test a stale one).
const MAX_SYNC_AGE: Duration = Duration::from_secs(1);

/// x y z qw qx qy qz of a pose.
fn words(pose: &Pose3) -> String {
    let t = pose.translation.vector;
    let q = pose.rotation.quaternion();
    format!("{} {} {} {} {} {} {}", t.x, t.y, t.z, q.w, q.i, q.j, q.k)
}

/// Publish the simulator's sample to the fake (the cloud through a file).
fn publish(fake: &mut support::FakeSpot, sample: &Sample, k: usize) {
    let path = fake.dir.join(format!("scan-{}.bin", k % 2));
    let bytes: Vec<u8> = sample
        .cloud
        .points()
        .iter()
        .flat_map(|p| [p.x, p.y, p.z])
        .flat_map(f32::to_le_bytes)
        .collect();
    std::fs::write(&path, bytes).unwrap();
    fake.query(&format!(
        "scan {} {} {}",
        path.display(),
        words(&sample.odom_t_body),
        words(&sample.body_t_lidar)
    ));
}

/// Commands the simulator took: the kind the fake decoded and the velocity.
type Commanded = Vec<(String, VelocityCommand)>;

/// The simulator behind the fake, stepped once per decoded command; `fault` sends a control
/// line to the fake after the given step (and ends the bridge after a `drop`).
struct Bridge {
    fake: Arc<Mutex<support::FakeSpot>>,
    done: Arc<AtomicBool>,
    thread: JoinHandle<(CommandedSpot, Commanded)>,
}

impl Bridge {
    fn start(
        fake: support::FakeSpot,
        mut sim: CommandedSpot,
        fault: Option<(usize, &'static str)>,
    ) -> Self {
        let fake = Arc::new(Mutex::new(fake));
        let done = Arc::new(AtomicBool::new(false));
        let (bridge_fake, bridge_done) = (Arc::clone(&fake), Arc::clone(&done));
        let thread = std::thread::spawn(move || {
            let mut commanded = Vec::new();
            let mut k = 0;
            let mut last_scan = Instant::now();
            let period =
                Duration::from_secs_f64(1.0 / SimulationConfig::default().lidar.rotation_rate);
            while !bridge_done.load(Ordering::Relaxed) {
                let answer = bridge_fake.lock().unwrap().query("wait-command 0.5");
                let fields: Vec<&str> = answer.split_whitespace().collect();
                if fields[0] == "none" {
                    continue;
                }
                let number = |i: usize| fields[i].parse::<f64>().unwrap();
                let command = VelocityCommand {
                    forward: number(1),
                    lateral: number(2),
                    yaw_rate: number(3),
                };
                commanded.push((fields[0].to_owned(), command));
                k += 1;
                let sample = sim.step(command);
                // Scans come at the simulated LiDAR's rate, not as fast as the loop can go.
                std::thread::sleep(period.saturating_sub(last_scan.elapsed()));
                last_scan = Instant::now();
                publish(&mut bridge_fake.lock().unwrap(), &sample, k);
                if let Some((at, line)) = fault
                    && at == k
                {
                    bridge_fake.lock().unwrap().control(line);
                    if line == "drop" {
                        break;
                    }
                }
            }
            (sim, commanded)
        });
        Self { fake, done, thread }
    }

    fn finish(self) -> (CommandedSpot, Commanded, Vec<Value>) {
        self.done.store(true, Ordering::Relaxed);
        let (sim, commanded) = self.thread.join().unwrap();
        let requests = self.fake.lock().unwrap().requests();
        (sim, commanded, requests)
    }
}

/// A fake fed by a commanded Spot standing at `start`, the client connected to it, and a
/// navigator on the map that knows where the robot stands.
fn setup(
    building: &Building,
    map: &PointCloud,
    navigation: &NavigationMap,
    start: Vector2<f64>,
    name: &str,
    fault: Option<(usize, &'static str)>,
) -> (SpotClient, Navigator<registration::PointToPlaneIcp>, Bridge) {
    let mut sim =
        CommandedSpot::new(building.clone(), start, 0.0, &SimulationConfig::default()).unwrap();
    let mut fake = support::start(name, &["--clock-offset", "4.5"]);
    publish(&mut fake, &sim.sense(), 0);
    let mut config = fake.config();
    config.description = sim.description().clone();
    config.lease_retain_interval = Duration::from_millis(200);
    config.time_sync.resync_interval = Duration::from_millis(200);
    config.time_sync.max_age = MAX_SYNC_AGE;
    let spot = SpotClient::connect(config).unwrap();
    let navigator = Navigator::new(
        point_to_plane_localiser(),
        map,
        navigation,
        sim.body_pose(),
        spot.description(),
        NavigatorConfig::default(),
    )
    .unwrap();
    (spot, navigator, Bridge::start(fake, sim, fault))
}

/// A goal 4 m down the corridor from its first corner.
fn corridor_goal(building: &Building) -> (Vector2<f64>, Vector2<f64>) {
    let corners = building.corridor_loop();
    let along = corners[1] - corners[0];
    (
        corners[0],
        corners[0] + along.normalize() * (0.8 * along.norm()).min(4.0),
    )
}

#[test]
fn the_navigator_walks_the_simulated_spot_to_a_goal_and_back_over_grpc() {
    let (building, map, navigation) = common::building_and_map(3);
    let (start, goal) = corridor_goal(&building);
    let (mut spot, mut navigator, bridge) =
        setup(&building, &map, &navigation, start, "navigation", None);
    let there = drive(&mut spot, &mut navigator, goal, 300, |_| {}).unwrap();
    let back = drive(&mut spot, &mut navigator, start, 300, |_| {}).unwrap();
    drop(spot);
    let (sim, commanded, requests) = bridge.finish();
    eprintln!(
        "over gRPC: {:?} in {} cycles, {:?} in {} cycles, ended {:.3} m from the start, {} collisions",
        there.outcome,
        there.cycles,
        back.outcome,
        back.cycles,
        (sim.position() - start).norm(),
        sim.collisions()
    );
    assert_eq!(there.outcome, DriveOutcome::Arrived);
    assert_eq!(back.outcome, DriveOutcome::Arrived);
    assert!(
        there.cycles + back.cycles >= 50,
        "{} cycles",
        there.cycles + back.cycles
    );
    assert!(
        (sim.position() - start).norm() < 0.2,
        "ended at {:?}",
        sim.position()
    );
    assert_eq!(sim.collisions(), 0);
    // The robot moved only by commands the official side decoded; each drive ended with a stop.
    let walked = commanded
        .iter()
        .filter(|(kind, _)| kind == "se2_velocity_request")
        .count();
    assert!(walked >= 40, "{walked} velocity commands");
    let stops = commanded
        .iter()
        .filter(|(kind, _)| kind == "full_body_command")
        .count();
    assert_eq!(stops, 2, "a stop after each arrival");
    let decoded: Vec<&Value> = requests
        .iter()
        .filter(|r| r["method"] == "RobotCommand")
        .collect();
    assert!(
        decoded
            .iter()
            .all(|c| c["request"]["lease"]["sequence"] == serde_json::json!([1]))
    );
    assert_eq!(requests.last().unwrap()["method"], "ReturnLease");
}

/// Each fault mid-walk ends the drive with a clear error; no motion command is sent after it,
/// and the stop goes out whenever the robot can still take one.
#[test]
fn faults_mid_walk_stop_the_drive_and_no_motion_follows_them() {
    let (building, map, navigation) = common::building_and_map(3);
    let (start, goal) = corridor_goal(&building);
    for (fault, stop_sent) in [
        ("malformed-cloud", true),
        ("stall-time-sync", true),
        ("take-lease", false),
        ("drop", false),
    ] {
        let (mut spot, mut navigator, bridge) = setup(
            &building,
            &map,
            &navigation,
            start,
            fault,
            Some((10, fault)),
        );
        let began = Instant::now();
        let error = drive(&mut spot, &mut navigator, goal, 300, |_| {}).unwrap_err();
        let took = began.elapsed();
        drop(spot);
        let (_, _, requests) = bridge.finish();
        let DriveError::Robot(error) = error else {
            panic!("{fault}: {error:?}")
        };
        match fault {
            "malformed-cloud" => assert!(
                matches!(error, SpotError::MalformedCloud { .. }),
                "{error:?}"
            ),
            "stall-time-sync" => assert!(
                matches!(error, SpotError::TimeSyncStale { .. }),
                "{error:?}"
            ),
            "take-lease" => assert!(
                matches!(
                    error,
                    SpotError::LeaseLost {
                        status: "STATUS_OLDER",
                        ..
                    }
                ),
                "{error:?}"
            ),
            _ => assert!(
                matches!(
                    error,
                    SpotError::Unreachable { .. } | SpotError::Timeout { .. }
                ),
                "{error:?}"
            ),
        }
        assert!(took < Duration::from_secs(20), "{fault}: {took:?}");
        let at = requests
            .iter()
            .position(|r| r["method"] == "control" && r["line"] == fault)
            .unwrap();
        let after: Vec<&Value> = requests[at..]
            .iter()
            .filter(|r| r["method"] == "RobotCommand")
            .collect();
        let motion = after
            .iter()
            .filter(|c| c["decoded"]["kind"] != "full_body_command")
            .count();
        let stops = after.len() - motion;
        // One cycle may already have been under way when the fault struck, and a stalled time
        // sync stays usable until it is `MAX_SYNC_AGE` old; nothing after that.
        if fault == "stall-time-sync" {
            let struck = requests[at]["robot_time"].as_f64().unwrap();
            for c in after
                .iter()
                .filter(|c| c["decoded"]["kind"] != "full_body_command")
            {
                let sent = c["robot_time"].as_f64().unwrap();
                assert!(
                    sent - struck < MAX_SYNC_AGE.as_secs_f64() + 0.3,
                    "{fault}: motion {:.2} s after the stall",
                    sent - struck
                );
            }
        } else {
            assert!(
                motion <= 1,
                "{fault}: {motion} motion commands after the fault"
            );
        }
        if stop_sent {
            // The drive's stop must reach the robot, and the client's own when dropped may.
            assert!((1..=2).contains(&stops), "{fault}: {stops} stops");
            assert_eq!(
                after.last().unwrap()["decoded"]["kind"],
                "full_body_command",
                "{fault}"
            );
        } else {
            assert_eq!(stops, 0, "{fault}");
        }
        eprintln!("{fault}: {error} after {took:.1?}");
    }
}
