//! PCD (ascii, binary and `binary_compressed` data: one reader): a file that parses is written in
//! both of our encodings and must read back to the same cloud.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = spot_nav_fuzz::round_trip::pcd(data);
});
