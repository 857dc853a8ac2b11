//! ROS 2 bags in MCAP through `Bag::open` and its samples: no panic, finite clouds and poses,
//! the samples announced (`src/invariants.rs`).
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = spot_nav_fuzz::invariants::mcap_bag(data);
});
