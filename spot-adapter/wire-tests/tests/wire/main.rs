//! spot-adapter's gRPC client against a fake Spot on loopback built on the official
//! `bosdyn-api` 5.2.0 servicers: every assertion on the wire is on what the official classes
//! decoded (the fake's request log), field by field.
// Exact float comparisons on purpose: a double crosses the wire bit for bit.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::float_cmp
)]

#[path = "../support/mod.rs"]
mod support;

mod estop;
mod power;
mod robot;
mod session;

use serde_json::Value;
use spot_adapter::grpc::SpotClient;

fn connect(fake: &support::FakeSpot) -> SpotClient {
    SpotClient::connect(fake.config()).expect("the client connects to the fake Spot")
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}
