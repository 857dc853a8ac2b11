//! TORO 2D graphs: ids and information exact (ids as integers), poses to rounding.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = spot_nav_fuzz::round_trip::toro(data);
});
