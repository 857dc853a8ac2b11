//! The tests' random numbers: a small linear congruential generator (Knuth's MMIX constants),
//! so that every run draws the same cases.

/// A generator of `u32`s from `seed` (the state's high bits).
pub(super) fn lcg(seed: u64) -> impl FnMut() -> u32 {
    let mut state = seed;
    move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 33) as u32
    }
}
