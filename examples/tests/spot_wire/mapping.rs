//! Mapping a room with the Graph-SLAM engine (walking a route, turning in place), saving the map,
//! a later run on it, and bad routes and maps refused before connecting.

use super::*;

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
