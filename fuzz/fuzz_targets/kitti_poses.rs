//! KITTI pose files (3x4 matrices): the poses written back read the same (the reader
//! re-orthonormalises rotations, so to rounding).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = spot_nav_fuzz::round_trip::kitti_poses(data);
});
