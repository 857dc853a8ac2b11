//! The `spot` example against a fake Spot built on the official `bosdyn-api` servicers
//! (spot-adapter/wire-tests/fake_spot): it powers a robot with its motors off on and stands
//! it before walking; it refuses to start while an E-stop is asserted or with a behaviour
//! fault; it stops a robot that does not move; and Ctrl-C ends the run with a stop command and
//! the lease returned. The fake's request log is the witness.
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
    Command::new(common::example("spot"))
        .args(["--host", "127.0.0.1", "--port", &fake.port.to_string()])
        .arg("--ca")
        .arg(fake.dir.join("ca.pem"))
        .args(["--user", support::USERNAME, "--goal", "1,0"])
        .args(extra)
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
fn interrupt_while_walking(fake: &FakeSpot) -> Vec<Value> {
    let child = spawn_spot(fake, &[]);
    let started = Instant::now();
    while !fake
        .requests()
        .iter()
        .any(|r| is_command(r, "se2_velocity_request"))
    {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "no velocity command: {:#?}",
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
    let requests = interrupt_while_walking(&fake);
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
    let fake = fake_spot!("example-ctrl-c");
    let requests = interrupt_while_walking(&fake);
    // Motors on at start: no power command, still a stand.
    assert!(!requests.iter().any(|r| r["method"] == "PowerCommand"));
    position(&requests, |r| is_command(r, "stand_request"), "stand");
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
