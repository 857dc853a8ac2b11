//! Moving AI `.scen` scenarios: every field the same after writing (the tolerance follows the
//! version written, so it is not compared).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = spot_nav_fuzz::round_trip::movingai_scen(data);
});
