//! The simulator's seeded random source: PCG-64 with uniform and normal draws.

use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg64Mcg;
use rand_pcg::rand_core::{Rng, SeedableRng};

/// A seeded generator whose streams are the same on every platform: PCG-64 (MCG variant) for the
/// integers, the top 53 bits for uniform floats, and `rand_distr`'s ziggurat (pinned version, libm
/// maths) for normal draws.
///
/// The simulator's geometry also calls `f64::sin`/`cos`/`atan2`, which Rust takes from the
/// platform's maths library; those may differ in the last bit between platforms, so a seed gives
/// the same building, route and noise everywhere, and the same points to within rounding.
#[derive(Clone, Debug)]
pub struct SimRng(Pcg64Mcg);

impl SimRng {
    /// A generator for `seed`; `stream` separates independent uses of one seed (building, sensor
    /// noise, odometry) so that changing one does not shift the others.
    #[must_use]
    pub fn new(seed: u64, stream: u64) -> Self {
        // SplitMix64-style mixing so that nearby seeds give unrelated states.
        let mix = |mut z: u64| {
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        };
        let hi = mix(seed.wrapping_add(0x9e37_79b9_7f4a_7c15));
        let lo = mix(stream ^ hi.rotate_left(17));
        Self(Pcg64Mcg::seed_from_u64(hi ^ lo.rotate_left(32)))
    }

    /// A uniform draw in `[0, 1)`.
    pub fn uniform(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A uniform draw in `[lo, hi)`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// A uniform integer in `0..n` (`n > 0`; returns 0 for `n == 0`).
    pub fn index(&mut self, n: usize) -> usize {
        if n == 0 {
            return 0;
        }
        // Plain modulo: for the small n used here (< 2^10) its bias is below 2^-50.
        (self.0.next_u64() % n as u64) as usize
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f64) -> bool {
        self.uniform() < p
    }

    /// A normal draw with mean 0 and standard deviation `sigma`.
    pub fn normal(&mut self, sigma: f64) -> f64 {
        let z: f64 = StandardNormal.sample(&mut self.0);
        sigma * z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let a: Vec<f64> = (0..5)
            .map({
                let mut r = SimRng::new(7, 1);
                move |_| r.uniform()
            })
            .collect();
        let b: Vec<f64> = (0..5)
            .map({
                let mut r = SimRng::new(7, 1);
                move |_| r.uniform()
            })
            .collect();
        let c: Vec<f64> = (0..5)
            .map({
                let mut r = SimRng::new(7, 2);
                move |_| r.uniform()
            })
            .collect();
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn normal_moments_match() {
        let mut r = SimRng::new(3, 0);
        let n = 200_000;
        let v: Vec<f64> = (0..n).map(|_| r.normal(2.0)).collect();
        let mean = v.iter().sum::<f64>() / f64::from(n);
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / f64::from(n);
        // Standard errors: mean 2/sqrt(n) = 0.0045, variance about 4*sqrt(2/n) = 0.013.
        assert!(mean.abs() < 0.02, "mean {mean}");
        assert!((var - 4.0).abs() < 0.06, "variance {var}");
    }
}
