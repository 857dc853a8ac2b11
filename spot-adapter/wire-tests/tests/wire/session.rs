//! The session with the robot: login, TLS, credentials, time sync, token renewal and the lease.

use std::time::{Duration, Instant};

use serde_json::Value;
use spot_adapter::grpc::{Credentials, RpcCode, SpotClient, SpotError};
use spot_adapter::robot::{Robot, VelocityCommand};

use super::{connect, f, support};
use crate::fake_spot;

#[test]
fn login_directory_and_authorities_as_the_sdk_does_them() {
    let fake = fake_spot!("login");
    let spot = connect(&fake);
    assert_eq!(spot.identity().serial_number, "fake-0001");
    assert_eq!(spot.identity().nickname, "loopback");
    for service in [
        "time-sync",
        "lease",
        "robot-state",
        "robot-command",
        "velodyne-point-cloud",
        "local-grid-service",
    ] {
        assert!(spot.services().iter().any(|s| s == service), "{service}");
    }
    let requests = fake.requests();
    let login = &requests[0];
    assert_eq!(login["method"], "GetAuthToken");
    assert_eq!(login["authority"], "auth.spot.robot");
    assert_eq!(login["request"]["username"], support::USERNAME);
    assert_eq!(
        login["request"]["password"], "<given>",
        "the fake saw a password"
    );
    assert_eq!(login["request"]["header"]["client_name"], "spot-nav");
    // Every later call carries the one token the fake issued, to the authority of its service.
    let bearer = requests[1]["authorization"].as_str().unwrap().to_owned();
    assert!(
        bearer.starts_with("Bearer ") && bearer.len() == "Bearer ".len() + 32,
        "{bearer}"
    );
    let expected_authority = |method: &str| match method {
        "GetRobotId" => "id.spot.robot",
        "ListServiceEntries" => "api.spot.robot",
        "TimeSyncUpdate" => "time-sync.spot.robot",
        "AcquireLease" | "RetainLease" | "ReturnLease" => "lease.spot.robot",
        other => panic!("unexpected call {other} while connecting"),
    };
    for r in &requests[1..] {
        let method = r["method"].as_str().unwrap();
        assert_eq!(r["authorization"], bearer.as_str(), "{method}");
        assert_eq!(r["authority"], expected_authority(method), "{method}");
        assert_eq!(
            r["request"]["header"]["client_name"], "spot-nav",
            "{method}"
        );
        assert!(
            r["request"]["header"]["request_timestamp"].is_string(),
            "{method}"
        );
    }
    let methods: Vec<&str> = requests
        .iter()
        .map(|r| r["method"].as_str().unwrap())
        .collect();
    assert_eq!(
        &methods[..3],
        &["GetAuthToken", "GetRobotId", "ListServiceEntries"]
    );
    assert!(
        methods.contains(&"TimeSyncUpdate") && methods.ends_with(&["AcquireLease"]),
        "{methods:?}"
    );
    assert_eq!(
        fake.requests_of("AcquireLease")[0]["request"]["resource"],
        "body"
    );
}

#[test]
fn a_robot_whose_certificate_is_not_from_the_given_ca_is_refused() {
    let fake = fake_spot!("wrong-ca");
    let other = fake_spot!("other-ca");
    let mut config = fake.config();
    config.ca_pem = other.ca_pem();
    let error = SpotClient::connect(config).expect_err("TLS must fail");
    assert!(
        matches!(
            error,
            SpotError::Unreachable {
                method: "GetAuthToken",
                ..
            }
        ),
        "{error:?}"
    );
    assert!(
        fake.requests().is_empty(),
        "nothing reached the fake without TLS trust"
    );
}

#[test]
fn bad_credentials_are_a_login_error_that_never_shows_the_password() {
    let fake = fake_spot!("bad-login");
    let mut config = fake.config();
    let wrong = "wrong-password-5417";
    config.credentials = Credentials::new(support::USERNAME, wrong);
    let logged = format!("{config:?}");
    let error = SpotClient::connect(config).expect_err("the login must fail");
    assert!(
        matches!(&error, SpotError::Login { status: "STATUS_INVALID_LOGIN", username } if username == support::USERNAME),
        "{error:?}"
    );
    let mut text = format!("{error} {error:?} {logged}");
    let mut source = std::error::Error::source(&error);
    while let Some(cause) = source {
        text = format!("{text} {cause} {cause:?}");
        source = cause.source();
    }
    assert!(!text.contains(wrong), "the password leaked: {text}");
    assert!(!format!("{:?}", fake.config()).contains(support::PASSWORD));
}

#[test]
fn an_unreachable_robot_is_a_clear_error_within_the_timeout() {
    let fake = fake_spot!("unreachable");
    let mut config = fake.config();
    // A port nobody listens on: bound, then closed.
    config.port = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let start = Instant::now();
    let error = SpotClient::connect(config).expect_err("nothing listens");
    assert!(
        matches!(
            error,
            SpotError::Unreachable {
                method: "GetAuthToken",
                ..
            }
        ),
        "{error:?}"
    );
    assert!(
        start.elapsed() < Duration::from_secs(4),
        "{:?}",
        start.elapsed()
    );
}

#[test]
fn time_sync_recovers_the_robot_clock_offset_and_times_commands_in_robot_time() {
    let fake = fake_spot!("time-sync", &["--clock-offset", "12.5"]);
    let spot = connect(&fake);
    let skew = spot.clock_skew().expect("converged");
    // The estimate is good to half the best round trip: a few milliseconds on loopback.
    assert!((skew - 12.5).abs() < 0.05, "skew {skew}");
    let rounds = fake.requests_of("TimeSyncUpdate");
    assert!(
        rounds.len() >= 4,
        "the fake needs three round trips, then reports OK"
    );
    // Each round after the first reports the previous round trip's four times.
    for r in &rounds[1..] {
        let trip = &r["request"]["previous_round_trip"];
        for field in ["client_tx", "server_rx", "server_tx", "client_rx"] {
            assert!(trip[field].is_string(), "{field} missing in {r}");
        }
        assert_eq!(r["request"]["clock_identifier"], "fake-spot-clock");
    }
    spot.command(&VelocityCommand::new(0.2, 0.0).into())
        .unwrap();
    let command = fake.requests_of("RobotCommand").pop().unwrap();
    let end = f(&command["decoded"]["end_time"]);
    let robot_time = f(&command["robot_time"]);
    // The velocity holds 0.6 s past its sending, on the robot's clock (12.5 s ahead of ours).
    assert!(
        (end - robot_time - 0.6).abs() < 0.1,
        "end {end} robot {robot_time}"
    );
}

#[test]
fn the_token_is_renewed_before_it_expires_and_the_fake_refuses_an_expired_one() {
    let fake = fake_spot!("refresh", &["--token-lifetime", "2"]);
    let mut config = fake.config();
    config.token_refresh_interval = Duration::from_millis(700);
    let spot = SpotClient::connect(config).unwrap();
    let start = Instant::now();
    while start.elapsed() < Duration::from_secs(5) {
        spot.frame_tree()
            .expect("calls keep working past the first token's lifetime");
        std::thread::sleep(Duration::from_millis(200));
    }
    let renewals: Vec<Value> = fake
        .requests_of("GetAuthToken")
        .into_iter()
        .filter(|r| r["request"]["token"].is_string())
        .collect();
    assert!(renewals.len() >= 5, "{} renewals", renewals.len());
    assert!(
        renewals
            .iter()
            .all(|r| r["request"].get("password").is_none())
    );
    let tokens: std::collections::HashSet<_> = fake
        .requests_of("GetRobotState")
        .iter()
        .map(|r| r["authorization"].as_str().unwrap().to_owned())
        .collect();
    assert!(tokens.len() >= 3, "later calls carry the renewed tokens");
    drop(spot);

    // Without renewal the fake refuses the token once it expired.
    let mut config = fake.config();
    config.token_refresh_interval = Duration::from_secs(600);
    let stale = SpotClient::connect(config).unwrap();
    std::thread::sleep(Duration::from_millis(2300));
    let error = stale.frame_tree().unwrap_err();
    assert!(
        matches!(
            error,
            SpotError::Rpc {
                method: "GetRobotState",
                code: RpcCode::Unauthenticated,
                ..
            }
        ),
        "{error:?}"
    );
}

#[test]
fn the_lease_is_retained_in_the_background_and_returned_on_drop() {
    let fake = fake_spot!("lease");
    let mut config = fake.config();
    config.lease_retain_interval = Duration::from_millis(250);
    let spot = SpotClient::connect(config).unwrap();
    std::thread::sleep(Duration::from_millis(1200));
    drop(spot);
    let requests = fake.requests();
    let acquired = fake.requests_of("AcquireLease");
    assert_eq!(acquired.len(), 1);
    let retains = fake.requests_of("RetainLease");
    assert!(retains.len() >= 3, "{} retains in 1.2 s", retains.len());
    let lease = &retains[0]["request"]["lease"];
    assert_eq!(lease["resource"], "body");
    assert_eq!(lease["sequence"], serde_json::json!([1]));
    assert!(retains.iter().all(|r| r["request"]["lease"] == *lease));
    let last = requests.last().unwrap();
    assert_eq!(last["method"], "ReturnLease");
    assert_eq!(last["request"]["lease"], *lease);
}

#[test]
fn a_lease_taken_by_another_client_stops_every_command() {
    let mut fake = fake_spot!("lease-taken");
    let mut config = fake.config();
    config.lease_retain_interval = Duration::from_millis(200);
    let mut spot = SpotClient::connect(config).unwrap();
    spot.send(&VelocityCommand::new(0.2, 0.0).into()).unwrap();
    fake.control("take-lease");
    std::thread::sleep(Duration::from_millis(700));
    assert_eq!(
        spot.lease_lost(),
        Some(("STATUS_OLDER", "another-client".to_owned()))
    );
    let sent = fake.requests_of("RobotCommand").len();
    let error = spot
        .send(&VelocityCommand::new(0.2, 0.0).into())
        .unwrap_err();
    assert!(
        matches!(&error, SpotError::LeaseLost { status: "STATUS_OLDER", owner } if owner == "another-client"),
        "{error:?}"
    );
    assert!(matches!(spot.stop(), Err(SpotError::LeaseLost { .. })));
    assert_eq!(
        fake.requests_of("RobotCommand").len(),
        sent,
        "nothing sent without the lease"
    );
}

#[test]
fn a_command_answered_with_a_newer_lease_marks_the_lease_lost() {
    let mut fake = fake_spot!("lease-command");
    let mut config = fake.config();
    config.lease_retain_interval = Duration::from_secs(60);
    let spot = SpotClient::connect(config).unwrap();
    fake.control("take-lease");
    let error = spot
        .command(&VelocityCommand::new(0.2, 0.0).into())
        .unwrap_err();
    assert!(
        matches!(
            error,
            SpotError::LeaseLost {
                status: "STATUS_OLDER",
                ..
            }
        ),
        "{error:?}"
    );
    assert!(spot.lease_lost().is_some());
}

/// A request's fields without its header (whose client name and time differ between clients).
fn without_header(request: &Value) -> Value {
    let mut request = request["request"].clone();
    request.as_object_mut().unwrap().remove("header");
    request
}

#[test]
fn a_lease_the_tablet_holds_is_refused_and_taken_with_take_lease_as_the_sdk_takes_it() {
    let fake = fake_spot!("lease-held", &["--lease-held"]);
    let error = SpotClient::connect(fake.config()).expect_err("the lease is the tablet's");
    assert!(
        matches!(
            &error,
            SpotError::LeaseRefused { status: "STATUS_RESOURCE_ALREADY_CLAIMED", owner, .. }
                if owner == "tablet"
        ),
        "{error:?}"
    );
    assert!(fake.requests_of("TakeLease").is_empty());

    let mut config = fake.config();
    config.take_lease = true;
    let mut spot = SpotClient::connect(config).expect("the lease is taken");
    spot.send(&VelocityCommand::new(0.2, 0.0).into()).unwrap();
    drop(spot);
    let commands = fake.requests_of("RobotCommand");
    assert_eq!(commands[0]["request"]["lease"]["sequence"][0], 2);
    let ours = fake.requests_of("TakeLease");
    assert_eq!(ours.len(), 1);
    let returned = fake.requests_of("ReturnLease");
    assert_eq!(returned.len(), 1);
    assert_eq!(returned[0]["request"]["lease"]["sequence"][0], 2);

    // The official client's `LeaseClient.take` against the same fake.
    support::run_sdk_flow(&fake, &["--take"]);
    let sdk = fake.requests_of("TakeLease");
    assert_eq!(sdk.len(), 2);
    assert_eq!(without_header(&ours[0]), without_header(&sdk[1]));
    assert_eq!(
        without_header(&ours[0]),
        serde_json::json!({"resource": "body"})
    );
    assert_eq!(ours[0]["authority"], sdk[1]["authority"]);
    let fields = |r: &Value| {
        let mut keys: Vec<String> = r["request"]["header"]
            .as_object()
            .unwrap()
            .keys()
            .cloned()
            .collect();
        keys.sort();
        keys
    };
    assert_eq!(fields(&ours[0]), fields(&sdk[1]));
}
