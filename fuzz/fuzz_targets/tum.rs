//! TUM trajectories (`stamp tx ty tz qx qy qz qw`): stamps exact, poses to rounding.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = spot_nav_fuzz::round_trip::tum(data);
});
