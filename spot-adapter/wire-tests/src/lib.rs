//! Nothing but tests: `tests/` drives spot-adapter's gRPC client against a fake Spot written on
//! the official `bosdyn-api` package (`fake_spot/`), in a Python venv the tests make under
//! `target/`.
