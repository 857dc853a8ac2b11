//! Power, E-stop, faults, a robot that does not move or refuses commands, and Ctrl-C at each
//! step: the example ends with a stop and the lease returned.

use super::*;
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
