//! Moving AI `.map` grids: the same blocked cells and terrain letters after writing.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = spot_nav_fuzz::round_trip::movingai_map(data);
});
