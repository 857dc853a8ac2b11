//! The `spot` example against a fake Spot built on the official `bosdyn-api` servicers
//! (spot-adapter/wire-tests/fake_spot): it powers a robot with its motors off on and stands
//! it before walking; it refuses to start while an E-stop is asserted or with a behaviour
//! fault; it stops a robot that does not move; Ctrl-C ends the run with a stop command and
//! the lease returned, also while the motors power on; it maps a room with the Graph-SLAM
//! engine while walking a route, saves the map, and a later run walks on the saved map to
//! its goal and sits. The fake's request log is the witness.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

#[path = "../../../spot-adapter/wire-tests/tests/support/mod.rs"]
mod support;

#[path = "../common/mod.rs"]
mod common;

mod faults;
mod mapping;

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
