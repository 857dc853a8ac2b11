//! KITTI velodyne scans (`x y z reflectance` as f32): written back bit for bit.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = spot_nav_fuzz::round_trip::kitti_bin(data);
});
