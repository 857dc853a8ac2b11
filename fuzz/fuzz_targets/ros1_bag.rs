//! ROS 1 bags through `Bag::open` and its samples: no panic, finite clouds and poses, the
//! samples announced (`src/invariants.rs`).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = spot_nav_fuzz::invariants::ros1_bag(data);
});
