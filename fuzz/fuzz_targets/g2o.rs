//! g2o graphs (SE(2) and SE(3)): ids, fixed flags, information exact; poses to rounding.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = spot_nav_fuzz::round_trip::g2o(data);
});
