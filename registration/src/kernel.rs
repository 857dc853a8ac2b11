//! Robust weights for correspondence residuals.

/// The weight of a residual `r` (metres) in iteratively reweighted least squares.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(tag = "kind", deny_unknown_fields)
)]
pub enum IcpKernel {
    /// Every correspondence weighs 1.
    None,
    /// 1 up to `k`, then `k / |r|`.
    Huber {
        /// Threshold, metres.
        k: f64,
    },
    /// `(1 - (r/k)^2)^2` up to `k`, 0 beyond (thesis eq. 4.7): outliers stop counting.
    Tukey {
        /// Threshold, metres (thesis: 5 cm for odometry, 10 cm for loop refinement).
        k: f64,
    },
}

impl IcpKernel {
    /// Weight of residual `r`.
    #[inline]
    #[must_use]
    pub fn weight(&self, r: f64) -> f64 {
        match *self {
            Self::None => 1.0,
            Self::Huber { k } => {
                let a = r.abs();
                if a <= k { 1.0 } else { k / a }
            }
            Self::Tukey { k } => {
                let u = r / k;
                if u.abs() <= 1.0 {
                    let t = 1.0 - u * u;
                    t * t
                } else {
                    0.0
                }
            }
        }
    }
}
