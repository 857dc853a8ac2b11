//! The surrogate losses of graduated non-convexity (Yang, Antonante, Tzoumas, Carlone, RA-L 2020,
//! section III): their weights as a function of the control parameter `mu`, `mu`'s start and its
//! schedule, and the chi-square quantile that sets the inlier threshold.
//!
//! `s = e^T Omega e` is an edge's squared Mahalanobis error and `c2` (`c-bar^2` in the paper) the
//! largest `s` of an inlier.

/// The robust loss graduated non-convexity minimises in the end.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum GncLoss {
    /// Truncated least squares, `min(s, c2)`: an edge beyond the threshold costs a constant and
    /// pulls on nothing. Its surrogate is convex for a small `mu`, which grows by
    /// [`GncConfig::mu_step`](crate::GncConfig::mu_step) until every weight is 0 or 1.
    #[default]
    TruncatedLeastSquares,
    /// Geman-McClure, `c2 s / (c2 + s)`: smooth and bounded. Its surrogate `mu c2 s / (mu c2 + s)`
    /// starts nearly quadratic (a large `mu`) and `mu` shrinks to 1.
    GemanMcClure,
}

impl GncLoss {
    /// The loss of an edge with squared error `s` (threshold `c2`).
    #[must_use]
    pub fn cost(self, s: f64, c2: f64) -> f64 {
        match self {
            Self::TruncatedLeastSquares => s.min(c2),
            Self::GemanMcClure => c2 * s / (c2 + s),
        }
    }

    /// The first `mu` (paper, remark 5): the surrogate is convex over every residual, the largest
    /// being `s_max`. `None` when even `s_max` is an inlier for the loss itself (nothing to
    /// graduate).
    pub(crate) fn initial_mu(self, s_max: f64, c2: f64) -> Option<f64> {
        match self {
            Self::TruncatedLeastSquares => (2.0 * s_max > c2).then(|| c2 / (2.0 * s_max - c2)),
            Self::GemanMcClure => (2.0 * s_max > c2).then(|| 2.0 * s_max / c2),
        }
    }

    /// `mu` after one outer iteration: times `step` (TLS), divided by it down to 1 (GM).
    pub(crate) fn next_mu(self, mu: f64, step: f64) -> f64 {
        match self {
            Self::TruncatedLeastSquares => mu * step,
            Self::GemanMcClure => (mu / step).max(1.0),
        }
    }

    /// Whether `mu` has reached the end of its schedule (GM: 1; TLS never: its weights decide).
    pub(crate) fn mu_at_end(self, mu: f64) -> bool {
        match self {
            Self::TruncatedLeastSquares => false,
            Self::GemanMcClure => mu <= 1.0,
        }
    }

    /// The weight in `[0, 1]` of an edge with squared error `s` at control parameter `mu`: the
    /// closed-form minimiser of the Black-Rangarajan dual of the surrogate (paper, propositions
    /// 3 and 4).
    pub(crate) fn weight(self, s: f64, c2: f64, mu: f64) -> f64 {
        match self {
            Self::TruncatedLeastSquares => {
                if s <= mu / (mu + 1.0) * c2 {
                    1.0
                } else if s >= (mu + 1.0) / mu * c2 {
                    0.0
                } else {
                    ((c2 / s).sqrt() * (mu * (mu + 1.0)).sqrt() - mu).clamp(0.0, 1.0)
                }
            }
            Self::GemanMcClure => {
                let m = mu * c2;
                let w = m / (s + m);
                w * w
            }
        }
    }
}

/// The regularised lower incomplete gamma function `P(a, x)` by its power series (converges for
/// every `x >= 0`; the arguments here are small).
fn lower_gamma_regularised(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    let mut term = 1.0 / a;
    let mut sum = term;
    let mut n = 1.0;
    while term > sum * 1e-16 && n < 10_000.0 {
        term *= x / (a + n);
        sum += term;
        n += 1.0;
    }
    // x^a e^-x / Gamma(a), Gamma(a) for the integer and half-integer `a` used here.
    (a * x.ln() - x - ln_gamma_half_integer(a)).exp() * sum
}

/// `ln Gamma(a)` for `a` a positive multiple of 1/2.
fn ln_gamma_half_integer(a: f64) -> f64 {
    let (mut g, mut t) = if (a.fract() - 0.5).abs() < 1e-12 {
        (std::f64::consts::PI.sqrt().ln(), 0.5)
    } else {
        (0.0, 1.0)
    };
    while t < a - 1e-12 {
        g += t.ln();
        t += 1.0;
    }
    g
}

/// The `p` quantile of the chi-square distribution with `dof` degrees of freedom (bisection on
/// its CDF, to 1e-12 relative). `p` must be in `(0, 1)`.
pub(crate) fn chi2_quantile(dof: usize, p: f64) -> f64 {
    let a = dof as f64 / 2.0;
    let (mut lo, mut hi) = (0.0, 1.0);
    while lower_gamma_regularised(a, hi / 2.0) < p && hi < 1e6 {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if lower_gamma_regularised(a, mid / 2.0) < p {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-12 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
// The weights are exactly 0 and 1 outside the surrogate's band, by construction.
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;

    #[test]
    fn chi2_quantiles_match_tables() {
        // Abramowitz & Stegun table 26.8 (and scipy.stats.chi2.ppf).
        for (dof, p, want) in [
            (3, 0.99, 11.344_866_730_144_373),
            (6, 0.99, 16.811_893_829_770_927),
            (3, 0.95, 7.814_727_903_251_178),
            (6, 0.95, 12.591_587_243_743_977),
            (1, 0.5, 0.454_936_423_119_572_7),
        ] {
            let got = chi2_quantile(dof, p);
            assert!(
                (got - want).abs() < 1e-9 * want,
                "{dof} {p}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn tls_weights_are_continuous_and_binary_at_the_ends() {
        let (c2, mu) = (10.0, 0.7);
        let loss = GncLoss::TruncatedLeastSquares;
        let lo = mu / (mu + 1.0) * c2;
        let hi = (mu + 1.0) / mu * c2;
        assert!((loss.weight(lo * (1.0 + 1e-12), c2, mu) - 1.0).abs() < 1e-9);
        assert!(loss.weight(hi * (1.0 - 1e-12), c2, mu) < 1e-9);
        assert_eq!(loss.weight(0.0, c2, mu), 1.0);
        assert_eq!(loss.weight(1e9, c2, mu), 0.0);
        // The first mu makes every residual up to s_max a (partial) inlier.
        let mu0 = loss.initial_mu(1000.0, c2).unwrap_or(0.0);
        assert!(loss.weight(1000.0 * (1.0 - 1e-9), c2, mu0) > 0.0);
        assert!(loss.initial_mu(4.0, c2).is_none());
    }

    #[test]
    fn gm_surrogate_ends_at_the_loss() {
        let loss = GncLoss::GemanMcClure;
        let c2 = 3.0;
        // At mu = 1 the weight is d rho / d s of c2 s / (c2 + s).
        for s in [0.1, 1.0, 10.0, 1e4] {
            let h = 1e-6 * s;
            let fd = (loss.cost(s + h, c2) - loss.cost(s - h, c2)) / (2.0 * h);
            assert!((fd - loss.weight(s, c2, 1.0)).abs() < 1e-6);
        }
        assert_eq!(loss.next_mu(1.2, 1.4), 1.0);
        assert!(loss.mu_at_end(1.0));
    }
}
