//! The unit of a scan's per-point times, decided from the values.
//!
//! Drivers disagree on the time's unit: Velodyne writes float seconds since the header stamp,
//! Ouster and Livox integer nanoseconds since it, Hesai float absolute seconds, some split
//! absolute time in two fields. The unit is decided from the values: the one (seconds or
//! nanoseconds, absolute or relative to the stamp) under which every point lies within one scan
//! period of the stamp. It is decided once per topic (or folder), on the first cloud whose times
//! are not all equal, and every later cloud is checked against it; a cloud that fits no unit, or
//! two units at once, is an error rather than a guess.
//!
//! Used by the `sensor_msgs/PointCloud2` decoder and by the PCD/PLY folder reader (whose files
//! store the time relative to the scan's start).

use slam_core::PointCloud;

use crate::record::{MessageError, TimeUnitProblem};

/// The least spread (seconds) of per-point times that differ.
const MIN_SPREAD: f64 = 1e-5;
/// The longest scan period (seconds) per-point times may span by default (a 5 Hz LiDAR's 0.2 s
/// sweep and some margin).
pub(super) const DEFAULT_MAX_SCAN_PERIOD: f64 = 0.25;

/// The unit of a per-point time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum TimeUnit {
    /// Seconds since the header stamp (Velodyne).
    SecondsRelative,
    /// Nanoseconds since the header stamp (Ouster, Livox).
    NanosecondsRelative,
    /// Seconds on the same clock as the header stamp (Hesai; split sec + nsec fields).
    SecondsAbsolute,
    /// Nanoseconds on the same clock as the header stamp.
    NanosecondsAbsolute,
}

impl TimeUnit {
    /// Preference when units tie (all times equal): relative before absolute, seconds first.
    const ALL: [Self; 4] = [
        Self::SecondsRelative,
        Self::NanosecondsRelative,
        Self::SecondsAbsolute,
        Self::NanosecondsAbsolute,
    ];

    /// Seconds after `stamp` of a raw value `v`.
    #[must_use]
    pub fn offset(self, v: f64, stamp: f64) -> f64 {
        match self {
            Self::SecondsRelative => v,
            Self::NanosecondsRelative => v * 1e-9,
            Self::SecondsAbsolute => v - stamp,
            Self::NanosecondsAbsolute => v * 1e-9 - stamp,
        }
    }

    /// `(scale, shift)` with `offset(v, stamp) == v * scale - shift`, bit for bit (a product
    /// by 1 and a difference with 0 are exact).
    pub(super) fn scale_shift(self, stamp: f64) -> (f64, f64) {
        match self {
            Self::SecondsRelative => (1.0, 0.0),
            Self::NanosecondsRelative => (1e-9, 0.0),
            Self::SecondsAbsolute => (1.0, stamp),
            Self::NanosecondsAbsolute => (1e-9, stamp),
        }
    }

    pub(crate) fn name(self) -> &'static str {
        match self {
            Self::SecondsRelative => "s since the stamp",
            Self::NanosecondsRelative => "ns since the stamp",
            Self::SecondsAbsolute => "s absolute",
            Self::NanosecondsAbsolute => "ns absolute",
        }
    }
}

/// The least and greatest of `values`, or NaN for the least when one is not finite (the unit
/// check refuses it). Four lanes, so the comparisons do not wait on one another.
pub(super) fn finite_range(values: &[f64]) -> (f64, f64) {
    let (mut lo, mut hi) = ([f64::INFINITY; 4], [f64::NEG_INFINITY; 4]);
    let mut finite = true;
    let chunks = values.chunks_exact(4);
    let rest = chunks.remainder();
    for c in chunks {
        for k in 0..4 {
            finite &= c[k].is_finite();
            lo[k] = if c[k] < lo[k] { c[k] } else { lo[k] };
            hi[k] = if c[k] > hi[k] { c[k] } else { hi[k] };
        }
    }
    for &v in rest {
        finite &= v.is_finite();
        lo[0] = if v < lo[0] { v } else { lo[0] };
        hi[0] = if v > hi[0] { v } else { hi[0] };
    }
    let min = lo.iter().fold(f64::INFINITY, |a, &b| a.min(b));
    let max = hi.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b));
    (if finite { min } else { f64::NAN }, max)
}

/// The time unit of one topic's (or folder's) clouds: given, or decided on the first cloud whose
/// times differ and checked on every later one.
#[derive(Clone, Debug)]
pub(super) struct TimeUnitInference {
    /// The longest scan period (seconds) per-point times may span.
    max_scan_period: f64,
    unit: Option<TimeUnit>,
}

impl Default for TimeUnitInference {
    fn default() -> Self {
        Self::new(None, DEFAULT_MAX_SCAN_PERIOD)
    }
}

impl TimeUnitInference {
    /// `unit` when known (`None` decides it from the first cloud), times within
    /// `max_scan_period` (seconds) of the stamp.
    pub(super) fn new(unit: Option<TimeUnit>, max_scan_period: f64) -> Self {
        Self {
            max_scan_period,
            unit,
        }
    }

    /// The time unit decided so far (or given).
    pub(super) fn unit(&self) -> Option<TimeUnit> {
        self.unit
    }

    /// `cloud`'s time channel (read from a file as it was stored, relative to the scan's start)
    /// in seconds: kept when it fits seconds, scaled when it fits nanoseconds (Ouster's PCDs),
    /// by the same rule and with the same memory of the unit as [`TimeUnitInference::unit_of`].
    ///
    /// # Errors
    /// [`MessageError::TimeUnit`] when the times fit neither.
    pub(super) fn times_in_seconds(
        &mut self,
        cloud: PointCloud,
    ) -> Result<PointCloud, MessageError> {
        let Some(time) = cloud.time() else {
            return Ok(cloud);
        };
        let (min, max) = time
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &t| {
                (lo.min(f64::from(t)), hi.max(f64::from(t)))
            });
        let min = if time.iter().all(|t| t.is_finite()) {
            min
        } else {
            f64::NAN
        };
        match self.unit_of(|| "t".into(), 0.0, min, max)? {
            TimeUnit::SecondsRelative | TimeUnit::SecondsAbsolute => Ok(cloud),
            TimeUnit::NanosecondsRelative | TimeUnit::NanosecondsAbsolute => {
                let (points, ring, intensity, time) = cloud.into_parts();
                let seconds: Vec<f32> = time
                    .unwrap_or_default()
                    .iter()
                    .map(|&t| (f64::from(t) * 1e-9) as f32)
                    .collect();
                let mut out = PointCloud::from_points(points);
                // The channels keep their lengths, so these cannot fail.
                let bad = |_| MessageError::TimeUnit {
                    field: "t".into(),
                    min,
                    max,
                    stamp: 0.0,
                    period: self.max_scan_period,
                    problem: TimeUnitProblem::ChannelLengths,
                };
                if let Some(r) = ring {
                    out = out.with_ring(r).map_err(bad)?;
                }
                if let Some(i) = intensity {
                    out = out.with_intensity(i).map_err(bad)?;
                }
                out.with_time(seconds).map_err(bad)
            }
        }
    }

    /// The unit of raw times in `[min, max]` (one cloud stamped `stamp`, the time read from the
    /// field named by `field`), deciding it on the first cloud whose times differ.
    ///
    /// # Errors
    /// [`MessageError::TimeUnit`] when the times fit no unit, fit two, or no longer fit the one
    /// decided.
    // Exactly equal times are the case where nothing can be decided.
    #[allow(clippy::float_cmp)]
    pub(super) fn unit_of(
        &mut self,
        field: impl FnOnce() -> String,
        stamp: f64,
        min: f64,
        max: f64,
    ) -> Result<TimeUnit, MessageError> {
        let period = self.max_scan_period;
        let error = |problem: TimeUnitProblem| MessageError::TimeUnit {
            field: field(),
            min,
            max,
            stamp,
            period,
            problem,
        };
        if min > max {
            // No point: any unit will do.
            return Ok(self.unit.unwrap_or(TimeUnit::SecondsRelative));
        }
        if !(min.is_finite() && max.is_finite()) {
            return Err(error(TimeUnitProblem::NotFinite));
        }
        // A unit fits when it puts every point within one period of the stamp, and spreads
        // differing times over at least 10 us (the 0.04 degrees a 10 Hz LiDAR turns in that
        // time): seconds read as nanoseconds would squeeze a sweep into nanoseconds.
        let fits = |u: TimeUnit| {
            let (lo, hi) = (u.offset(min, stamp), u.offset(max, stamp));
            let spread = hi - lo;
            lo >= -period
                && hi <= period
                && spread <= period
                && (max == min || spread >= MIN_SPREAD)
        };
        if let Some(unit) = self.unit {
            return if fits(unit) {
                Ok(unit)
            } else {
                Err(error(TimeUnitProblem::DecidedUnitDoesNotFit { unit }))
            };
        }
        let spread = |u: TimeUnit| u.offset(max, stamp) - u.offset(min, stamp);
        let candidates: Vec<TimeUnit> = TimeUnit::ALL.into_iter().filter(|&u| fits(u)).collect();
        // The widest spread; on a tie the first in preference order.
        let Some(best) = candidates
            .iter()
            .copied()
            .reduce(|a, b| if spread(b) > spread(a) { b } else { a })
        else {
            return Err(error(TimeUnitProblem::NoUnitFits));
        };
        if spread(best) == 0.0 {
            // All times equal: nothing to decide from; take the preferred unit for this cloud.
            return Ok(candidates[0]);
        }
        // Another unit that spreads the points as widely but places them elsewhere.
        if let Some(other) = candidates.iter().find(|&&u| {
            u != best
                && spread(u) >= 0.1 * spread(best)
                && (u.offset(min, stamp) - best.offset(min, stamp)).abs() > 1e-6
        }) {
            return Err(error(TimeUnitProblem::TwoUnitsFit {
                first: best,
                second: *other,
            }));
        }
        self.unit = Some(best);
        Ok(best)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::point_cloud2::test_clouds::{cloud, points};
    use crate::record::point_cloud2::{PointCloud2Config, PointCloud2Decoder};

    #[test]
    fn time_units_are_decided_once_and_checked_after() {
        let data = points(&[0.0, 0.05, 0.099]);
        let mut decoder = PointCloud2Decoder::new(PointCloud2Config::default());
        let got = decoder.decode(&cloud(&data, 1.7e9)).unwrap();
        assert_eq!(decoder.time_unit(), Some(TimeUnit::SecondsRelative));
        assert_eq!(got.cloud.time(), Some(&[0.0, 0.05, 0.099][..]));
        // A later cloud spanning 2 s no longer fits the unit decided.
        let data = points(&[0.0, 2.0]);
        assert!(matches!(
            decoder.decode(&cloud(&data, 1.7e9 + 0.1)),
            Err(MessageError::TimeUnit { .. })
        ));
        // Near a zero stamp, absolute and relative seconds both fit and disagree.
        let data = points(&[0.06, 0.1]);
        let mut fresh = PointCloud2Decoder::new(PointCloud2Config::default());
        let err = fresh.decode(&cloud(&data, 0.05)).unwrap_err();
        assert!(
            matches!(
                &err,
                MessageError::TimeUnit {
                    problem: TimeUnitProblem::TwoUnitsFit { .. },
                    ..
                }
            ) && err.to_string().contains("both"),
            "{err}"
        );
        // Equal times decide nothing.
        let data = points(&[0.0, 0.0]);
        let mut fresh = PointCloud2Decoder::new(PointCloud2Config::default());
        fresh.decode(&cloud(&data, 5.0)).unwrap();
        assert_eq!(fresh.time_unit(), None);
    }
}
