//! `sensor_msgs/PointCloud2` payloads (ROS 1 or CDR) through `PointCloud2Decoder`: every point
//! accounted for and finite, the same cloud decoded twice (`src/invariants.rs`).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = spot_nav_fuzz::invariants::point_cloud2(data);
});
