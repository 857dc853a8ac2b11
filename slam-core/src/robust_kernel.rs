//! Robust kernels for pose-graph edges that may be wrong (loop closures).

/// A robust kernel `rho(s)` applied to an edge's squared Mahalanobis error `s = e^T Omega e`.
/// All three equal `s` near zero and grow slower than `s` for large errors.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(tag = "kind", deny_unknown_fields)
)]
pub enum RobustKernel {
    /// Quadratic up to `delta` (in Mahalanobis units), linear beyond.
    Huber {
        /// Threshold on `sqrt(s)`.
        delta: f64,
    },
    /// `c^2 ln(1 + s / c^2)`.
    Cauchy {
        /// Scale.
        c: f64,
    },
    /// `c^2 s / (c^2 + s)`: bounded, so a gross outlier stops pulling.
    GemanMcClure {
        /// Scale.
        c: f64,
    },
}

impl RobustKernel {
    /// `rho(s)`.
    #[must_use]
    pub fn rho(&self, s: f64) -> f64 {
        match *self {
            Self::Huber { delta } => {
                if s <= delta * delta {
                    s
                } else {
                    2.0 * delta * s.sqrt() - delta * delta
                }
            }
            Self::Cauchy { c } => c * c * (s / (c * c)).ln_1p(),
            Self::GemanMcClure { c } => c * c * s / (c * c + s),
        }
    }

    /// `d rho / d s`, the weight of the edge in iteratively reweighted least squares.
    #[must_use]
    pub fn weight(&self, s: f64) -> f64 {
        match *self {
            Self::Huber { delta } => {
                if s <= delta * delta {
                    1.0
                } else {
                    delta / s.sqrt()
                }
            }
            Self::Cauchy { c } => 1.0 / (1.0 + s / (c * c)),
            Self::GemanMcClure { c } => {
                let d = c * c + s;
                c * c * c * c / (d * d)
            }
        }
    }

    /// Whether the parameter is finite and positive.
    #[must_use]
    pub fn is_valid(&self) -> bool {
        let p = match *self {
            Self::Huber { delta } => delta,
            Self::Cauchy { c } | Self::GemanMcClure { c } => c,
        };
        p.is_finite() && p > 0.0
    }
}

/// An optional kernel in a settings file: `{ kind = "None" }` for none, else the kernel itself
/// (`{ kind = "Cauchy", c = 1.0 }`). A plain `Option` would write none by leaving the field out,
/// which a file with defaults reads as the default kernel.
#[cfg(feature = "serde")]
pub(crate) mod optional_kernel {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    use super::RobustKernel;

    /// [`RobustKernel`]'s variants and `None`, tagged as `RobustKernel` is.
    #[derive(Serialize, Deserialize)]
    #[serde(tag = "kind", deny_unknown_fields)]
    enum Repr {
        None,
        Huber { delta: f64 },
        Cauchy { c: f64 },
        GemanMcClure { c: f64 },
    }

    #[allow(clippy::ref_option)] // serde's `with` passes the field by reference.
    pub(crate) fn serialize<S: Serializer>(
        kernel: &Option<RobustKernel>,
        serializer: S,
    ) -> Result<S::Ok, S::Error> {
        match *kernel {
            None => Repr::None,
            Some(RobustKernel::Huber { delta }) => Repr::Huber { delta },
            Some(RobustKernel::Cauchy { c }) => Repr::Cauchy { c },
            Some(RobustKernel::GemanMcClure { c }) => Repr::GemanMcClure { c },
        }
        .serialize(serializer)
    }

    pub(crate) fn deserialize<'de, D: Deserializer<'de>>(
        deserializer: D,
    ) -> Result<Option<RobustKernel>, D::Error> {
        Ok(match Repr::deserialize(deserializer)? {
            Repr::None => None,
            Repr::Huber { delta } => Some(RobustKernel::Huber { delta }),
            Repr::Cauchy { c } => Some(RobustKernel::Cauchy { c }),
            Repr::GemanMcClure { c } => Some(RobustKernel::GemanMcClure { c }),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weight_is_derivative_of_rho() {
        for k in [
            RobustKernel::Huber { delta: 1.5 },
            RobustKernel::Cauchy { c: 0.7 },
            RobustKernel::GemanMcClure { c: 2.0 },
        ] {
            assert!(k.is_valid());
            for s in [0.01, 0.5, 1.0, 3.0, 10.0, 100.0] {
                let h = 1e-6 * s;
                let fd = (k.rho(s + h) - k.rho(s - h)) / (2.0 * h);
                assert!(
                    (fd - k.weight(s)).abs() < 1e-5,
                    "{k:?} at {s}: {fd} vs {}",
                    k.weight(s)
                );
                assert!(k.rho(s) <= s + 1e-12);
            }
            assert!((k.rho(1e-8) - 1e-8).abs() < 1e-12);
        }
        assert!(!RobustKernel::Huber { delta: -1.0 }.is_valid());
    }
}
