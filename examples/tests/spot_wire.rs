//! The `spot` example against a fake Spot built on the official `bosdyn-api` servicers
//! (spot-adapter/wire-tests/fake_spot): it powers a robot with its motors off on and stands
//! it before walking; it refuses to start while an E-stop is asserted or with a behaviour
//! fault; it stops a robot that does not move; Ctrl-C ends the run with a stop command and
//! the lease returned, also while the motors power on; it maps a room with the Graph-SLAM
//! engine while walking a route, saves the map, and a later run walks on the saved map to
//! its goal and sits. The fake's request log is the witness.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

#[path = "../../spot-adapter/wire-tests/tests/support/mod.rs"]
mod support;

mod common;

use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;
use support::FakeSpot;

/// Start the example against `fake`, walking to a goal 1 m ahead.
fn spawn_spot(fake: &FakeSpot, extra: &[&str]) -> Child {
    spawn_example(fake, &[&["--goal", "1,0"], extra].concat())
}

/// Start the example against `fake` with `args` besides the connection's.
fn spawn_example(fake: &FakeSpot, args: &[&str]) -> Child {
    Command::new(common::example("spot"))
        .args(["--host", "127.0.0.1", "--port", &fake.port.to_string()])
        .arg("--ca")
        .arg(fake.dir.join("ca.pem"))
        .args(["--user", support::USERNAME])
        .args(args)
        .env("SPOT_PASSWORD", support::PASSWORD)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the spot example starts")
}

/// Wait for `child` at most `limit`, killing it after.
fn finish(mut child: Child, limit: Duration) -> (Output, Duration) {
    let started = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if started.elapsed() > limit {
            let _ = child.kill();
            let output = child.wait_with_output().unwrap();
            panic!(
                "the example ran over {limit:?}: {}",
                String::from_utf8_lossy(&output.stderr)
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    (child.wait_with_output().unwrap(), started.elapsed())
}

/// The first request index matching `wanted`, panicking with the log when there is none.
fn position(requests: &[Value], wanted: impl Fn(&Value) -> bool, what: &str) -> usize {
    requests
        .iter()
        .position(wanted)
        .unwrap_or_else(|| panic!("no {what} in the fake's log: {requests:#?}"))
}

fn is_command(request: &Value, kind: &str) -> bool {
    request["method"] == "RobotCommand"
        && (request["decoded"]["kind"] == kind
            || request["request"]["command"]["synchronized_command"]["mobility_command"]
                .get(kind)
                .is_some())
}

fn is_stop(request: &Value) -> bool {
    request["method"] == "RobotCommand"
        && request["request"]["command"]["full_body_command"]
            .get("stop_request")
            .is_some()
}

/// The run ended with a stop command, then the lease returned; no motion after the stop.
fn assert_stopped_and_lease_returned(requests: &[Value]) {
    let returned = requests
        .iter()
        .rposition(|r| r["method"] == "ReturnLease")
        .unwrap_or_else(|| panic!("no ReturnLease: {requests:#?}"));
    let stop = requests[..returned]
        .iter()
        .rposition(is_stop)
        .unwrap_or_else(|| panic!("no stop before ReturnLease: {requests:#?}"));
    assert!(
        !requests[stop..]
            .iter()
            .any(|r| is_command(r, "se2_velocity_request")),
        "motion after the stop"
    );
}

/// Run until the fake has taken a velocity command, then send SIGINT; the run must end 130.
fn interrupt_while_walking(fake: &FakeSpot, extra: &[&str]) -> Vec<Value> {
    interrupt_after(
        fake,
        extra,
        |r| is_command(r, "se2_velocity_request"),
        "velocity command",
    )
}

/// Run until the fake has taken a request that is `wanted`, then send SIGINT; the run must
/// end 130 within 5 s with a stop and the lease returned.
fn interrupt_after(
    fake: &FakeSpot,
    extra: &[&str],
    wanted: impl Fn(&Value) -> bool,
    what: &str,
) -> Vec<Value> {
    let child = spawn_spot(fake, extra);
    let started = Instant::now();
    while !fake.requests().iter().any(&wanted) {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "no {what}: {:#?}",
            fake.requests()
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let (output, took) = finish(child, Duration::from_secs(10));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("interrupted"), "{stderr}");
    assert!(took < Duration::from_secs(5), "{took:?}");
    let requests = fake.requests();
    assert_stopped_and_lease_returned(&requests);
    requests
}

#[test]
fn motors_off_at_start_the_example_powers_on_and_stands_before_walking() {
    let fake = fake_spot!("example-motors-off", &["--motors", "off"]);
    let requests = interrupt_while_walking(&fake, &[]);
    let power = position(&requests, |r| r["method"] == "PowerCommand", "PowerCommand");
    let on = &requests[power]["request"]["request"];
    assert!(on == "REQUEST_ON_MOTORS" || on == "REQUEST_ON", "{on}");
    let stand = position(&requests, |r| is_command(r, "stand_request"), "stand");
    let walk = position(
        &requests,
        |r| is_command(r, "se2_velocity_request"),
        "velocity command",
    );
    assert!(power < stand && stand < walk, "{power} {stand} {walk}");
    // The stand was confirmed by its feedback before the first motion.
    let feedback = position(
        &requests,
        |r| r["method"] == "RobotCommandFeedback",
        "RobotCommandFeedback",
    );
    assert!(stand < feedback && feedback < walk);
}

#[test]
fn ctrl_c_sends_a_stop_and_returns_the_lease() {
    // No E-stop controller: the example's own software E-stop is the robot's E-stop.
    let fake = fake_spot!("example-ctrl-c", &["--estop", "none"]);
    let requests = interrupt_while_walking(&fake, &["--software-estop=0.9"]);
    // Motors on at start: no power command, still a stand.
    assert!(!requests.iter().any(|r| r["method"] == "PowerCommand"));
    let stand = position(&requests, |r| is_command(r, "stand_request"), "stand");
    // Registered and released before the stand, settled (sit, then cut) after the lease
    // was returned.
    let registered = position(
        &requests,
        |r| r["method"] == "RegisterEstopEndpoint",
        "RegisterEstopEndpoint",
    );
    assert!(registered < stand);
    let levels: Vec<&Value> = requests
        .iter()
        .filter(|r| r["method"] == "EstopCheckIn")
        .map(|r| &r["request"]["stop_level"])
        .collect();
    assert_eq!(levels[..2], ["ESTOP_LEVEL_CUT", "ESTOP_LEVEL_NONE"]);
    assert_eq!(levels[levels.len() - 1], "ESTOP_LEVEL_SETTLE_THEN_CUT");
    let returned = requests
        .iter()
        .rposition(|r| r["method"] == "ReturnLease")
        .unwrap();
    assert_eq!(requests[requests.len() - 1]["method"], "EstopCheckIn");
    assert!(returned < requests.len() - 1);
}

/// Run the example to its end against `fake`; it must fail within `limit` naming `cause`.
fn refused(fake: &FakeSpot, cause: &str, limit: Duration) -> (Vec<Value>, String) {
    let (output, took) = finish(spawn_spot(fake, &[]), Duration::from_secs(30));
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains(cause), "{stderr}");
    assert!(took < limit, "{took:?}: {stderr}");
    (fake.requests(), stderr)
}

#[test]
fn an_asserted_estop_stops_the_example_before_it_powers_on() {
    let fake = fake_spot!("example-estop", &["--motors", "off", "--estop", "asserted"]);
    let (requests, stderr) = refused(&fake, "E-stop asserted", Duration::from_secs(5));
    assert!(
        stderr.contains("hardware_estop") && stderr.contains("release"),
        "{stderr}"
    );
    assert!(!requests.iter().any(|r| r["method"] == "PowerCommand"));
    assert!(!requests.iter().any(|r| is_command(r, "stand_request")));
    assert_stopped_and_lease_returned(&requests);
}

#[test]
fn without_an_estop_endpoint_the_example_does_not_start() {
    let fake = fake_spot!("example-no-estop", &["--estop", "none"]);
    let (requests, _) = refused(&fake, "no E-stop endpoint", Duration::from_secs(5));
    assert!(!requests.iter().any(|r| is_command(r, "stand_request")));
    assert_stopped_and_lease_returned(&requests);
}

#[test]
fn a_behavior_fault_stops_the_example_with_its_name() {
    let fake = fake_spot!("example-fault", &["--behavior-fault"]);
    let (requests, _) = refused(&fake, "CAUSE_FALL", Duration::from_secs(5));
    assert!(!requests.iter().any(|r| is_command(r, "stand_request")));
    assert_stopped_and_lease_returned(&requests);
}

#[test]
fn a_robot_that_never_moves_is_stopped_within_5_s() {
    let fake = fake_spot!("example-frozen", &["--frozen"]);
    let (requests, stderr) = refused(&fake, "does not respond", Duration::from_secs(30));
    let first = position(
        &requests,
        |r| is_command(r, "se2_velocity_request"),
        "velocity command",
    );
    let returned = requests
        .iter()
        .rposition(|r| r["method"] == "ReturnLease")
        .unwrap();
    let seconds = requests[returned]["robot_time"].as_f64().unwrap()
        - requests[first]["robot_time"].as_f64().unwrap();
    assert!(
        seconds < 5.0,
        "{seconds} s from the first command: {stderr}"
    );
    assert_stopped_and_lease_returned(&requests);
    // Commands at the fixed 10 Hz rate, not as fast as the robot answers.
    let commands = requests[first..returned]
        .iter()
        .filter(|r| is_command(r, "se2_velocity_request"))
        .count();
    assert!(
        (15..=45).contains(&commands),
        "{commands} commands in {seconds:.1} s"
    );
}

#[test]
fn refused_commands_stop_the_example_at_once() {
    let fake = fake_spot!("example-refused", &["--refuse-motion"]);
    let (requests, stderr) = refused(&fake, "STATUS_BEHAVIOR_FAULT", Duration::from_secs(30));
    assert!(stderr.contains("refused"), "{stderr}");
    let first = position(
        &requests,
        |r| is_command(r, "se2_velocity_request"),
        "velocity command",
    );
    let motion = requests
        .iter()
        .filter(|r| is_command(r, "se2_velocity_request"))
        .count();
    assert_eq!(motion, 1, "a refused command is not retried");
    assert!(
        requests[..first]
            .iter()
            .any(|r| is_command(r, "stand_request"))
    );
    assert_stopped_and_lease_returned(&requests);
}

#[test]
fn ctrl_c_while_the_motors_power_on_sends_a_stop_and_returns_the_lease() {
    let fake = fake_spot!(
        "example-ctrl-c-power",
        &["--motors", "off", "--power-on-seconds", "30"]
    );
    let requests = interrupt_after(
        &fake,
        &[],
        |r| r["method"] == "PowerCommand",
        "PowerCommand",
    );
    // Interrupted while waiting for the motors: never stood nor walked.
    assert!(!requests.iter().any(|r| is_command(r, "stand_request")));
    assert!(
        !requests
            .iter()
            .any(|r| is_command(r, "se2_velocity_request"))
    );
}

#[test]
fn ctrl_c_while_standing_up_sends_a_stop_and_returns_the_lease() {
    let fake = fake_spot!("example-ctrl-c-stand", &["--posture-seconds", "30"]);
    let requests = interrupt_after(
        &fake,
        &[],
        |r| is_command(r, "stand_request"),
        "stand command",
    );
    // Interrupted while waiting for the stand: never walked.
    assert!(
        !requests
            .iter()
            .any(|r| is_command(r, "se2_velocity_request"))
    );
}

/// The fake's true body pose in odom, `[x, y, yaw]`.
fn true_pose(fake: &mut FakeSpot) -> [f64; 3] {
    poses(fake)[0]
}

/// The fake's true body pose in odom and the one its odometry reports, each `[x, y, yaw]`.
fn poses(fake: &mut FakeSpot) -> [[f64; 3]; 2] {
    let answer = fake.query("pose");
    let n: Vec<f64> = answer
        .split_whitespace()
        .map(|w| w.parse().unwrap())
        .collect();
    [[n[0], n[1], n[2]], [n[3], n[4], n[5]]]
}

/// `pose` in the frame of `origin` (both `[x, y, yaw]` in odom).
fn relative(origin: [f64; 3], pose: [f64; 3]) -> [f64; 3] {
    let (c, s) = (origin[2].cos(), origin[2].sin());
    let (dx, dy) = (pose[0] - origin[0], pose[1] - origin[1]);
    let yaw = (pose[2] - origin[2] + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
        - std::f64::consts::PI;
    [c * dx + s * dy, -s * dx + c * dy, yaw]
}

/// The numbers after `label` on the line of `text` that has it (`mapping ended at (x, y, yaw)`).
fn numbers_after(text: &str, label: &str) -> Vec<f64> {
    let line = text
        .lines()
        .find_map(|l| l.split_once(label).map(|(_, rest)| rest.to_owned()))
        .unwrap_or_else(|| panic!("no {label:?} in {text}"));
    line.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
        .filter_map(|w| w.parse().ok())
        .collect()
}

/// The map saved in `dir` loads: the cloud (PCD and PLY), the graph with a node per keyframe,
/// and the grid with free and occupied cells.
fn assert_saved_map_loads(dir: &std::path::Path, keyframes: usize) {
    let map = slam_core::io::read_pcd(dir.join("map.pcd")).unwrap();
    assert!(map.len() > 1000, "{} points", map.len());
    let ply = slam_core::io::read_ply(dir.join("map.ply")).unwrap();
    assert_eq!(ply.len(), map.len());
    let posegraph::g2o::G2oGraph::Se3(graph) =
        posegraph::g2o::read_g2o(dir.join("graph.g2o")).unwrap()
    else {
        panic!("a 2D graph")
    };
    assert_eq!(graph.node_count(), keyframes);
    let grid = gridmap::read_ros_map(dir.join("grid.yaml")).unwrap();
    let (free, occupied, _) = grid.counts();
    assert!(free > 0 && occupied > 0, "{free} free, {occupied} occupied");
}

#[test]
fn maps_a_room_by_walking_a_route_with_graph_slam_and_a_later_run_arrives_on_the_saved_map() {
    let mut fake = fake_spot!(
        "example-map-walk",
        &[
            "--world",
            "room",
            "--motors",
            "off",
            "--lease-held",
            // The odometry counts every motion 1.2 times: the map and the pose must come
            // from the engine registering the room's scans, not from the odometry.
            "--odom-scale",
            "1.2"
        ]
    );
    let origin = true_pose(&mut fake);

    // The tablet holds the lease: refused, naming --take-lease, before anything moves.
    let (output, _) = finish(spawn_spot(&fake, &[]), Duration::from_secs(30));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("--take-lease") && stderr.contains("\"tablet\""),
        "{stderr}"
    );
    assert!(fake.requests_of("RobotCommand").is_empty());

    // Run 1: take the lease, power on, stand, map with Graph-SLAM along the route, save.
    let route = fake.dir.join("route.txt");
    std::fs::write(
        &route,
        "# x y, metres in the start frame\n1.0 0.0\n1.0, 0.6\n",
    )
    .unwrap();
    let saved = fake.dir.join("map");
    let (output, took) = finish(
        spawn_example(
            &fake,
            &[
                "--take-lease",
                "--route",
                route.to_str().unwrap(),
                "--save-map",
                saved.to_str().unwrap(),
            ],
        ),
        Duration::from_secs(90),
    );
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(0), "{stdout}\n{stderr}");
    eprintln!("mapping run: {took:?}\n{stdout}");
    let keyframes: usize = stdout
        .split_once(" keyframes")
        .and_then(|(before, _)| before.rsplit(' ').next()?.parse().ok())
        .unwrap_or_else(|| panic!("no keyframe count: {stdout}"));
    assert!(keyframes >= 2, "{stdout}");
    // Walked the route: the true pose is at its last waypoint, and the engine's estimate
    // agrees with the truth where the odometry's does not.
    let [truth, odometry] = poses(&mut fake);
    let walked = relative(origin, truth);
    let odometry = relative(origin, odometry);
    assert!(
        (walked[0] - 1.0).hypot(walked[1] - 0.6) < 0.25,
        "{walked:?}"
    );
    let estimate = numbers_after(&stdout, "mapping ended at");
    eprintln!("after the route (start frame): true {walked:?}, odometry {odometry:?}");
    assert!(
        (estimate[0] - walked[0]).hypot(estimate[1] - walked[1]) < 0.05
            && (estimate[2] - walked[2]).abs() < 0.05,
        "{estimate:?} against the truth {walked:?}"
    );
    assert!(
        (odometry[2] - walked[2]).abs() > 0.2,
        "the odometry is off: {odometry:?} against the truth {walked:?}"
    );
    let run1 = fake.requests();
    position(&run1, |r| r["method"] == "TakeLease", "TakeLease");
    position(&run1, |r| r["method"] == "PowerCommand", "PowerCommand");
    assert_stopped_and_lease_returned(&run1);
    assert_saved_map_loads(&saved, keyframes);

    // Run 2: on the saved map, from where run 1 ended, back to the start, then sit.
    arrive_on_saved_map(&mut fake, &saved, origin, walked, run1.len());
}

/// A run on the map saved in `saved` from `walked` (the true pose, start frame) back to the
/// start (`origin`, odom): it arrives, sits and powers off, then stops and returns the lease
/// (the fake's requests from `before` on).
fn arrive_on_saved_map(
    fake: &mut FakeSpot,
    saved: &std::path::Path,
    origin: [f64; 3],
    walked: [f64; 3],
    before: usize,
) {
    let start = format!("--start={},{},{}", walked[0], walked[1], walked[2]);
    let (output, took) = finish(
        spawn_example(
            fake,
            &[
                "--map",
                saved.to_str().unwrap(),
                &start,
                "--goal",
                "0,0",
                "--sit",
            ],
        ),
        Duration::from_secs(90),
    );
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(0), "{stdout}\n{stderr}");
    eprintln!("navigation run: {took:?}\n{stdout}");
    assert!(
        stdout.contains("map loaded from") && stdout.contains("Arrived"),
        "{stdout}"
    );
    let back = relative(origin, true_pose(fake));
    eprintln!("true pose on arrival (start frame): {back:?}");
    assert!(back[0].hypot(back[1]) < 0.3, "{back:?}");
    let run2 = &fake.requests()[before..];
    let walked = position(run2, |r| is_command(r, "se2_velocity_request"), "walk");
    let sit = position(run2, |r| is_command(r, "sit_request"), "sit");
    let off = position(
        run2,
        |r| {
            r["method"] == "RobotCommand"
                && r["request"]["command"]["full_body_command"]
                    .get("safe_power_off_request")
                    .is_some()
        },
        "safe power off",
    );
    assert!(walked < sit && sit < off, "{walked} {sit} {off}");
    assert_stopped_and_lease_returned(run2);
}

#[test]
fn maps_a_room_by_turning_in_place_with_graph_slam_and_saves_it() {
    let mut fake = fake_spot!(
        "example-map-turn",
        &["--world", "room", "--odom-scale", "1.2"]
    );
    let origin = true_pose(&mut fake);
    let saved = fake.dir.join("map");
    let (output, took) = finish(
        spawn_example(
            &fake,
            &["--turn-rate", "1.0", "--save-map", saved.to_str().unwrap()],
        ),
        Duration::from_secs(60),
    );
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(0), "{stdout}\n{stderr}");
    eprintln!("turning run: {took:?}\n{stdout}");
    assert!(stdout.contains("turning once in place"), "{stdout}");
    // The odometry counts every turn 1.2 times; the engine ends where the robot truly is.
    let [truth, odometry] = poses(&mut fake);
    let (truth, odometry) = (relative(origin, truth), relative(origin, odometry));
    let estimate = numbers_after(&stdout, "mapping ended at");
    let heading_error = |a: f64, b: f64| {
        (a - b + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
    };
    assert!(
        heading_error(estimate[2], truth[2]).abs() < 0.05 && estimate[0].hypot(estimate[1]) < 0.05,
        "{estimate:?} against the truth {truth:?} (odometry {odometry:?})"
    );
    assert!(
        heading_error(odometry[2], truth[2]).abs() > 0.5,
        "{odometry:?} {truth:?}"
    );
    // A full circle truly turned (counted on the engine's estimate, not the odometry's).
    assert!(heading_error(truth[2], 0.0).abs() < 0.15, "{truth:?}");
    // The walls all round: the map spans the room (7 m by 6.5 m).
    let map = slam_core::io::read_pcd(saved.join("map.pcd")).unwrap();
    let (mut low, mut high) = ([f32::MAX; 2], [f32::MIN; 2]);
    for p in map.points() {
        for k in 0..2 {
            low[k] = low[k].min(p[k]);
            high[k] = high[k].max(p[k]);
        }
    }
    assert!(
        high[0] - low[0] > 6.0 && high[1] - low[1] > 6.0,
        "{low:?} {high:?}"
    );
    assert_stopped_and_lease_returned(&fake.requests());
}

/// Run the example with `args` and no robot behind `--host` (nothing listens on port 1).
fn without_robot(args: &[&str]) -> Output {
    let output = Command::new(common::example("spot"))
        .args([
            "--host",
            "127.0.0.1",
            "--port",
            "1",
            "--ca",
            "no-such-ca.pem",
        ])
        .args(["--user", "nobody"])
        .args(args)
        .env("SPOT_PASSWORD", "unused")
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(1), "{output:?}");
    output
}

#[test]
fn a_bad_route_or_a_missing_map_stops_the_example_before_it_connects() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("spot-example-files-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let route = dir.join("route.txt");
    std::fs::write(&route, "1.0 0.0\n# fine so far\n2.0 ahead\n").unwrap();
    let output = without_robot(&["--route", route.to_str().unwrap(), "--goal", "1,0"]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("line 3") && stderr.contains("is not `x y`"),
        "{stderr}"
    );
    // Not the CA: the route was read first.
    assert!(!stderr.contains("no-such-ca.pem"), "{stderr}");

    std::fs::write(&route, "# nothing\n").unwrap();
    let output = without_robot(&["--route", route.to_str().unwrap(), "--goal", "1,0"]);
    assert!(String::from_utf8_lossy(&output.stderr).contains("has no waypoint"));

    let missing = dir.join("no-map");
    std::fs::create_dir_all(&missing).unwrap();
    let output = without_robot(&["--map", missing.to_str().unwrap(), "--goal", "1,0"]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("map.pcd"), "{stderr}");
    assert!(!stderr.contains("no-such-ca.pem"), "{stderr}");
}
