//! spot-nav recording calibrations (`body_T_lidar tx ty tz qx qy qz qw`): the same mounting
//! after writing (to rounding of the quaternion).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = spot_nav_fuzz::round_trip::recording_calibration(data);
});
