//! With the `grpc` feature: compile the Spot API subset in `proto/` into Rust (prost messages,
//! tonic clients). protox parses the files in pure Rust, so no `protoc` binary is needed.
//! Without the feature it does nothing.

#[cfg(not(feature = "grpc"))]
fn main() {}

#[cfg(feature = "grpc")]
fn main() -> Result<(), Box<dyn std::error::Error>> {
    const FILES: &[&str] = &[
        "bosdyn/api/auth.proto",
        "bosdyn/api/directory.proto",
        "bosdyn/api/robot_id.proto",
        "bosdyn/api/time_sync.proto",
        "bosdyn/api/lease.proto",
        "bosdyn/api/robot_state.proto",
        "bosdyn/api/point_cloud.proto",
        "bosdyn/api/local_grid.proto",
        "bosdyn/api/robot_command.proto",
        "bosdyn/api/power.proto",
        "bosdyn/api/estop.proto",
        "bosdyn/api/spot/robot_command.proto",
    ];
    println!("cargo::rerun-if-changed=proto");
    let descriptors = protox::compile(FILES, ["proto"])?;
    tonic_prost_build::configure()
        .build_server(false)
        .build_transport(false)
        .compile_fds(descriptors)?;
    Ok(())
}
