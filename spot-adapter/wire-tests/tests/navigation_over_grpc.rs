//! The navigator drives a Spot over gRPC: a fake Spot on the official `bosdyn-api` servicers
//! serves the simulator's scans and odometry, and the simulated robot moves by the velocity
//! commands the fake decoded. A bridge thread keeps the two in lockstep: publish a scan, wait
//! for the command that answers it, step the simulator by it for one LiDAR turn.

#[path = "../../tests/common/mod.rs"]
mod common;
mod support;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use slam_core::Pose3;
use spot_adapter::grpc::SpotClient;
use spot_adapter::nav::{DriveOutcome, Navigator, NavigatorConfig, drive};
use spot_adapter::pipelines::point_to_plane_tracker;
use spot_adapter::robot::{Robot, VelocityCommand};
use spot_adapter::sim::{CommandedSpot, SimulationConfig};

/// x y z qw qx qy qz of a pose.
fn words(pose: &Pose3) -> String {
    let t = pose.translation.vector;
    let q = pose.rotation.quaternion();
    format!("{} {} {} {} {} {} {}", t.x, t.y, t.z, q.w, q.i, q.j, q.k)
}

/// Publish the simulator's sample to the fake (the cloud through a file).
fn publish(fake: &mut support::FakeSpot, sample: &spot_adapter::robot::Sample, k: usize) {
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

#[test]
fn the_navigator_walks_the_simulated_spot_to_its_goals_over_grpc() {
    let (building, map, navigation) = common::building_and_map(3);
    let corners = building.corridor_loop();
    let start = corners[0];
    let along = corners[1] - corners[0];
    let goal = start + along.normalize() * (0.8 * along.norm()).min(4.0);
    let mut sim = CommandedSpot::new(building, start, 0.0, &SimulationConfig::default()).unwrap();
    let world_t_body = sim.body_pose();

    let mut fake = fake_spot!("navigation", &["--clock-offset", "4.5"]);
    publish(&mut fake, &sim.sense(), 0);
    let mut config = fake.config();
    config.description = sim.description().clone();
    let mut spot = SpotClient::connect(config).unwrap();

    // The bridge: one simulator step per command the fake decoded, until told to stop.
    let fake = Arc::new(Mutex::new(fake));
    let done = Arc::new(AtomicBool::new(false));
    let (bridge_fake, bridge_done) = (Arc::clone(&fake), Arc::clone(&done));
    let bridge = std::thread::spawn(move || {
        let mut commanded = Vec::new();
        for k in 1.. {
            if bridge_done.load(Ordering::Relaxed) {
                break;
            }
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
            let sample = sim.step(command);
            publish(&mut bridge_fake.lock().unwrap(), &sample, k);
        }
        (sim, commanded)
    });

    let mut navigator = Navigator::new(
        point_to_plane_tracker(),
        &map,
        &navigation,
        world_t_body,
        spot.description(),
        NavigatorConfig::default(),
    )
    .unwrap();
    let there = drive(&mut spot, &mut navigator, goal, 300, |_| {}).unwrap();
    let back = drive(&mut spot, &mut navigator, start, 300, |_| {}).unwrap();
    done.store(true, Ordering::Relaxed);
    let (sim, commanded) = bridge.join().unwrap();
    drop(spot);

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
    assert!(stops >= 1, "a stop after arriving");
    let fake = fake.lock().unwrap();
    let decoded = fake.requests_of("RobotCommand");
    assert!(
        decoded
            .iter()
            .all(|c| c["request"]["lease"]["sequence"] == serde_json::json!([1]))
    );
}
