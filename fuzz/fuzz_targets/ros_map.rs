//! ROS `map_server` maps: the input is the YAML text, a NUL byte, then the image file's bytes
//! (PGM or PNG). The YAML keys read back from their text; the grid, written as `map_saver`
//! would (PGM and YAML), reads back cell for cell.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = spot_nav_fuzz::round_trip::ros_map(data);
});
