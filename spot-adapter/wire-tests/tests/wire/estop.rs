//! The software E-stop endpoint of a bench setup: registered, kept alive with the challenge
//! answered and settled on drop, as the official SDK's `EstopEndpoint` and `EstopKeepAlive`
//! do it against the same fake.

use std::time::Duration;

use serde_json::Value;
use spot_adapter::grpc::{SpotClient, SpotError};

use crate::fake_spot;
use crate::support;

const ESTOP_METHODS: [&str; 3] = ["GetEstopConfig", "RegisterEstopEndpoint", "EstopCheckIn"];

/// A request without its header, and without what differs from run to run (the endpoint's
/// unique id, which the robot assigns, and the challenge and its answer).
fn comparable(request: &Value) -> Value {
    let mut request = request["request"].clone();
    let fields = request.as_object_mut().unwrap();
    for varying in ["header", "challenge", "response"] {
        fields.remove(varying);
    }
    if let Some(endpoint) = fields.get_mut("endpoint") {
        endpoint.as_object_mut().unwrap().remove("unique_id");
    }
    request
}

fn levels(requests: &[Value]) -> Vec<&str> {
    requests
        .iter()
        .filter(|r| r["method"] == "EstopCheckIn")
        .map(|r| {
            r["request"]["stop_level"]
                .as_str()
                .unwrap_or("ESTOP_LEVEL_UNKNOWN")
        })
        .collect()
}

#[test]
fn a_software_estop_is_registered_kept_alive_and_settled_as_the_sdk_does_it() {
    let fake = fake_spot!("software-estop", &["--estop", "none"]);
    // Without an endpoint the robot lists no E-stop: the client refuses to start.
    let spot = SpotClient::connect(fake.config()).unwrap();
    assert!(matches!(
        spot.status().unwrap().check_ready(),
        Err(SpotError::NoEStop)
    ));
    drop(spot);
    let before = fake.requests().len();

    let mut config = fake.config();
    config.software_estop = Some(Duration::from_millis(900));
    let spot = SpotClient::connect(config).unwrap();
    let status = spot.status().unwrap();
    status.check_ready().unwrap();
    assert_eq!(status.estops.len(), 1, "{status:?}");
    assert_eq!(status.estops[0].name, "spot-nav");
    // Kept alive past its timeout: still released.
    std::thread::sleep(Duration::from_millis(1200));
    spot.status().unwrap().check_ready().unwrap();
    drop(spot);
    let ours: Vec<Value> = fake.requests()[before..]
        .iter()
        .filter(|r| ESTOP_METHODS.contains(&r["method"].as_str().unwrap()))
        .cloned()
        .collect();

    let mark = fake.requests().len();
    support::run_sdk_flow(&fake, &["--estop", "0.9"]);
    let sdk: Vec<Value> = fake.requests()[mark..]
        .iter()
        .filter(|r| ESTOP_METHODS.contains(&r["method"].as_str().unwrap()))
        .cloned()
        .collect();

    for requests in [&ours, &sdk] {
        let methods: Vec<&str> = requests
            .iter()
            .map(|r| r["method"].as_str().unwrap())
            .collect();
        assert_eq!(&methods[..3], &ESTOP_METHODS, "{methods:?}");
        let levels = levels(requests);
        // A first check-in at CUT seeds the challenge, then the keep-alive's at NONE (every
        // 0.3 s for a 0.9 s endpoint), then SETTLE_THEN_CUT at the end (the SDK's keep-alive
        // may repeat it before it shuts down).
        assert_eq!(levels[0], "ESTOP_LEVEL_CUT", "{levels:?}");
        let settle = levels
            .iter()
            .position(|l| *l == "ESTOP_LEVEL_SETTLE_THEN_CUT")
            .unwrap_or_else(|| panic!("never settled: {levels:?}"));
        assert!(
            levels[settle..]
                .iter()
                .all(|l| *l == "ESTOP_LEVEL_SETTLE_THEN_CUT"),
            "{levels:?}"
        );
        let keep_alive = &levels[1..settle];
        assert!(
            keep_alive.len() >= 3 && keep_alive.iter().all(|l| *l == "ESTOP_LEVEL_NONE"),
            "{levels:?}"
        );
        // Every check-in after the first answers the challenge the robot sent last, or (one
        // whose reply was lost in flight when the client was dropped) is answered again at
        // once at the same level.
        let check_ins: Vec<&Value> = requests
            .iter()
            .filter(|r| r["method"] == "EstopCheckIn")
            .collect();
        for (i, r) in check_ins.iter().enumerate().skip(1) {
            let retried = check_ins.get(i + 1).is_some_and(|next| {
                next["decoded"]["answered"] == true
                    && next["request"]["stop_level"] == r["request"]["stop_level"]
            });
            assert!(
                r["decoded"]["answered"] == true || retried,
                "{check_ins:#?}"
            );
        }
        assert_eq!(requests[0]["authority"], "estop.spot.robot");
    }
    // The same configuration request, registration and check-ins field by field.
    assert_eq!(comparable(&ours[0]), comparable(&sdk[0]));
    assert_eq!(comparable(&ours[1]), comparable(&sdk[1]));
    assert_eq!(
        ours[1]["request"]["new_endpoint"]["timeout"], "0.900s",
        "{:#?}",
        ours[1]
    );
    let check_ins = |requests: &[Value]| -> Vec<Value> {
        requests
            .iter()
            .filter(|r| r["method"] == "EstopCheckIn")
            .map(comparable)
            .collect()
    };
    let (ours, sdk) = (check_ins(&ours), check_ins(&sdk));
    assert_eq!(ours[..2], sdk[..2]);
    assert_eq!(ours.last(), sdk.last());
}
