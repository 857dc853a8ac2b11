//! `nav_msgs/Odometry`, `tf2_msgs/TFMessage` and `sensor_msgs/Imu` payloads (ROS 1 or CDR):
//! finite stamps and poses with unit rotations (`src/invariants.rs`).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = spot_nav_fuzz::invariants::ros_message(data);
});
