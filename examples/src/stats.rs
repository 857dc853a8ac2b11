//! Order statistics of repeated measurements: best, median, mean, percentiles, worst.

/// The `q` quantile (0 to 1, clamped) of `sorted` (ascending) by nearest rank, the element at
/// `round((n - 1) q)`: `q = 0.5` is the median (the upper one of an even count), `q = 1` the
/// largest. `None` when `sorted` is empty.
#[must_use]
pub fn quantile<T: Copy>(sorted: &[T], q: f64) -> Option<T> {
    let last = sorted.len().checked_sub(1)?;
    sorted
        .get((last as f64 * q.clamp(0.0, 1.0)).round() as usize)
        .copied()
}

/// A summary of timings (or any measurements; the unit is the caller's, usually milliseconds).
#[derive(Clone, Debug, PartialEq)]
pub struct Timings {
    sorted: Vec<f64>,
    mean: f64,
}

impl Timings {
    /// The summary of `values` (NaNs sort last); `None` when there are none.
    #[must_use]
    pub fn new(values: impl IntoIterator<Item = f64>) -> Option<Self> {
        let mut sorted: Vec<f64> = values.into_iter().collect();
        if sorted.is_empty() {
            return None;
        }
        let mean = sorted.iter().sum::<f64>() / sorted.len() as f64;
        sorted.sort_by(f64::total_cmp);
        Some(Self { sorted, mean })
    }

    /// How many values.
    #[must_use]
    pub fn len(&self) -> usize {
        self.sorted.len()
    }

    /// Always false: a summary has at least one value.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.sorted.is_empty()
    }

    /// The smallest value (the best time).
    #[must_use]
    pub fn best(&self) -> f64 {
        self.sorted[0]
    }

    /// The median ([`quantile`] 0.5).
    #[must_use]
    pub fn median(&self) -> f64 {
        self.quantile(0.5)
    }

    /// The arithmetic mean.
    #[must_use]
    pub fn mean(&self) -> f64 {
        self.mean
    }

    /// The largest value.
    #[must_use]
    pub fn max(&self) -> f64 {
        self.sorted[self.sorted.len() - 1]
    }

    /// The `q` quantile by nearest rank, as [`quantile`].
    #[must_use]
    pub fn quantile(&self, q: f64) -> f64 {
        quantile(&self.sorted, q).unwrap_or(self.mean)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank() {
        assert_eq!(quantile::<f64>(&[], 0.5), None);
        assert_eq!(quantile(&[7], 0.99), Some(7));
        // The upper median of an even count, as `v[n / 2]`.
        assert_eq!(quantile(&[1, 2, 3, 4], 0.5), Some(3));
        assert_eq!(quantile(&[1, 2, 3, 4, 5], 0.5), Some(3));
        let hundred: Vec<u32> = (0..100).collect();
        assert_eq!(quantile(&hundred, 0.99), Some(98));
        assert_eq!(quantile(&hundred, 2.0), Some(99));
    }

    #[test]
    fn summary() {
        assert!(Timings::new([]).is_none());
        let t = Timings::new([4.0, 1.0, 3.0, 2.0]).unwrap();
        assert_eq!((t.len(), t.best(), t.median(), t.max()), (4, 1.0, 3.0, 4.0));
        assert!((t.mean() - 2.5).abs() < 1e-12);
    }
}
