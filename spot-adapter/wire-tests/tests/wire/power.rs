//! Power, posture, E-stops and faults: the client brings a sitting robot with its motors off
//! up and down as the official SDK does, and reads the robot's readiness from its state.

use std::time::{Duration, Instant};

use serde_json::Value;
use spot_adapter::grpc::{MotorPower, SpotError};
use spot_adapter::robot::Robot;

use crate::fake_spot;
use crate::{connect, support};

/// The `RobotCommand` requests' kinds and the `PowerCommand` requests, in order, of one fake.
fn bring_up_requests(fake: &support::FakeSpot) -> (Vec<Value>, Vec<Value>) {
    let power: Vec<Value> = fake
        .requests_of("PowerCommand")
        .into_iter()
        .map(|r| r["request"]["request"].clone())
        .collect();
    let commands: Vec<Value> = fake
        .requests_of("RobotCommand")
        .into_iter()
        .map(|r| {
            let command = &r["request"]["command"];
            let mobility = &command["synchronized_command"]["mobility_command"];
            let kind = ["stand_request", "sit_request"]
                .into_iter()
                .find(|k| mobility.get(k).is_some())
                .map_or_else(|| r["decoded"]["kind"].clone(), Value::from);
            serde_json::json!([kind, command["full_body_command"].clone()])
        })
        .collect();
    (power, commands)
}

#[test]
fn power_on_stand_sit_and_power_off_as_the_official_sdk_does() {
    let ours = fake_spot!("power-ours", &["--motors", "off"]);
    let spot = connect(&ours);
    assert_eq!(spot.status().unwrap().motor_power, MotorPower::Off);
    spot.power_on().unwrap();
    assert_eq!(spot.status().unwrap().motor_power, MotorPower::On);
    spot.stand().unwrap();
    spot.sit().unwrap();
    spot.power_off().unwrap();
    assert_eq!(spot.status().unwrap().motor_power, MotorPower::Off);
    drop(spot);

    let sdk = fake_spot!("power-sdk", &["--motors", "off"]);
    support::run_sdk_flow(&sdk, &["--power"]);

    let (our_power, our_commands) = bring_up_requests(&ours);
    let (sdk_power, sdk_commands) = bring_up_requests(&sdk);
    // The same PowerCommand (REQUEST_ON_MOTORS) and the same stand, sit and safe power off.
    assert_eq!(our_power, sdk_power);
    assert_eq!(our_power.len(), 1, "{our_power:?}");
    // Ours ends with the stop the client sends when it is dropped.
    assert_eq!(our_commands[..sdk_commands.len()], sdk_commands[..]);
    assert_eq!(sdk_commands.len(), 3, "{sdk_commands:?}");
    // Both polled the power feedback and then the command feedback.
    for fake in [&ours, &sdk] {
        assert!(!fake.requests_of("PowerCommandFeedback").is_empty());
        assert!(!fake.requests_of("RobotCommandFeedback").is_empty());
        let lease = &fake.requests_of("PowerCommand")[0]["request"]["lease"];
        assert_eq!(lease["resource"], "body");
    }
}

#[test]
fn power_on_is_refused_while_the_estop_is_asserted() {
    let fake = fake_spot!("estopped", &["--motors", "off", "--estop", "asserted"]);
    let spot = connect(&fake);
    let status = spot.status().unwrap();
    assert!(
        matches!(status.check_ready(), Err(SpotError::EStopped { ref names }) if names == &["hardware_estop"]),
        "{status:?}"
    );
    let started = Instant::now();
    let error = spot.power_on().unwrap_err();
    assert!(started.elapsed() < Duration::from_secs(5));
    assert!(
        matches!(error, SpotError::StepFailed { step: "power on", ref reply } if reply == "STATUS_ESTOPPED"),
        "{error}"
    );
}

#[test]
fn the_robot_state_names_missing_estops_and_faults() {
    let fake = fake_spot!("no-estop", &["--estop", "none"]);
    let error = connect(&fake).status().unwrap().check_ready().unwrap_err();
    assert!(matches!(error, SpotError::NoEStop), "{error}");
    assert!(error.to_string().contains("E-stop"), "{error}");

    let fake = fake_spot!(
        "faults",
        &[
            "--behavior-fault",
            "--system-fault",
            "left_hip_motor_overheat"
        ]
    );
    let error = connect(&fake).status().unwrap().check_ready().unwrap_err();
    let message = error.to_string();
    assert!(
        message.contains("CAUSE_FALL (STATUS_CLEARABLE)")
            && message.contains("left_hip_motor_overheat"),
        "{message}"
    );
}

#[test]
fn a_cloud_already_delivered_is_not_delivered_again() {
    let fake = fake_spot!("stale-cloud", &["--stale-cloud"]);
    let mut spot = connect(&fake);
    let first = spot.next_sample().unwrap();
    let started = Instant::now();
    let error = spot.next_sample().unwrap_err();
    assert!(
        matches!(error, SpotError::NoNewScan { .. }),
        "{error} after the scan of {}",
        first.stamp
    );
    // The client's call timeout in the tests is 3 s.
    assert!(started.elapsed() < Duration::from_secs(5));
}

#[test]
fn a_panic_while_holding_the_client_sends_a_stop_and_returns_the_lease() {
    let fake = fake_spot!("panic");
    let result = std::panic::catch_unwind(|| {
        let _spot = connect(&fake);
        panic!("a bug in the caller");
    });
    assert!(result.is_err());
    let requests = fake.requests();
    let returned = requests
        .iter()
        .position(|r| r["method"] == "ReturnLease")
        .expect("the lease is returned");
    assert!(
        requests[..returned]
            .iter()
            .any(|r| r["method"] == "RobotCommand" && r["decoded"]["kind"] == "full_body_command"),
        "a stop before the lease is returned"
    );
}
