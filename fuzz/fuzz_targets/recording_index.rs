//! spot-nav recording indexes (`index stamp cloud` lines): the same entries after writing.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = spot_nav_fuzz::round_trip::recording_index(data);
});
