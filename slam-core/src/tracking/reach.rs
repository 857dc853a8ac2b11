//! The correspondence reach that follows the motion: KISS-ICP's adaptive threshold over a
//! window of recent scans.

use std::collections::VecDeque;

use crate::error::InvalidSetting;
use crate::geometry::Pose3;

/// Settings of [`AdaptiveReach`]. Lengths in metres.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct ReachConfig {
    /// The reach before any prediction has been checked, 2.0 m (KISS-ICP's initial threshold).
    pub initial: f64,
    /// The smallest reach, 0.5 m: below it the coarse stage adds nothing to the backend's own.
    pub min: f64,
    /// The largest reach, 6.0 m: a scan's points are paired with surfaces at most this far.
    pub max: f64,
    /// The reach is this many RMS prediction errors, 3 (a three-sigma bound, as KISS-ICP).
    pub sigmas: f64,
    /// The RMS is over the last this many checked predictions, 30.
    pub window: usize,
}

impl Default for ReachConfig {
    fn default() -> Self {
        Self {
            initial: 2.0,
            min: 0.5,
            max: 6.0,
            sigmas: 3.0,
            window: 30,
        }
    }
}

impl ReachConfig {
    /// Every length finite and positive, `min <= initial <= max`, `sigmas` finite and positive,
    /// a window of at least one scan.
    ///
    /// # Errors
    /// [`InvalidSetting`] naming the first bad setting.
    pub fn validate(&self) -> Result<(), InvalidSetting> {
        for (setting, v) in [
            ("ReachConfig::initial", self.initial),
            ("ReachConfig::min", self.min),
            ("ReachConfig::max", self.max),
            ("ReachConfig::sigmas", self.sigmas),
        ] {
            InvalidSetting::check(v.is_finite() && v > 0.0, setting, v, "finite and positive")?;
        }
        InvalidSetting::check(
            self.min <= self.max,
            "ReachConfig::max",
            self.max,
            "at least ReachConfig::min",
        )?;
        InvalidSetting::check(
            (self.min..=self.max).contains(&self.initial),
            "ReachConfig::initial",
            self.initial,
            "from ReachConfig::min to ReachConfig::max",
        )?;
        InvalidSetting::check(
            self.window >= 1,
            "ReachConfig::window",
            self.window as f64,
            "at least 1",
        )
    }
}

/// How far a correction `prediction^-1 * result` moves a point up to `extent` metres from the
/// sensor: its translation plus the chord its rotation sweeps at that range (KISS-ICP eq. 5).
#[must_use]
pub fn point_displacement(correction: &Pose3, extent: f64) -> f64 {
    let angle = correction.rotation.angle();
    correction.translation.vector.norm() + 2.0 * extent * (0.5 * angle).sin()
}

/// The reach: three RMS prediction errors of the recent scans, within `[min, max]`.
///
/// ```
/// use slam_core::tracking::{AdaptiveReach, ReachConfig};
///
/// let mut reach = AdaptiveReach::new(ReachConfig::default())?;
/// assert_eq!(reach.current(), 2.0);
/// for _ in 0..30 {
///     reach.record(0.05); // predictions 5 cm off
/// }
/// assert_eq!(reach.current(), 0.5); // 3 x 5 cm, held at the minimum
/// reach.record(3.0); // a sudden turn
/// assert!(reach.current() > 1.5);
/// # Ok::<(), slam_core::InvalidSetting>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct AdaptiveReach {
    config: ReachConfig,
    /// The last `window` prediction errors (metres).
    errors: VecDeque<f64>,
    /// Their sum of squares.
    sum_of_squares: f64,
    /// Errors recorded since the sum was last recomputed from the window.
    since_recompute: usize,
}

impl AdaptiveReach {
    /// A reach at `config.initial` until predictions are checked.
    ///
    /// # Errors
    /// [`InvalidSetting`] naming the first bad setting ([`ReachConfig::validate`]).
    pub fn new(config: ReachConfig) -> Result<Self, InvalidSetting> {
        config.validate()?;
        Ok(Self {
            errors: VecDeque::with_capacity(config.window),
            config,
            sum_of_squares: 0.0,
            since_recompute: 0,
        })
    }

    /// The settings.
    #[must_use]
    pub fn config(&self) -> &ReachConfig {
        &self.config
    }

    /// The reach for the next scan (metres).
    #[must_use]
    pub fn current(&self) -> f64 {
        if self.errors.is_empty() {
            return self.config.initial;
        }
        let rms = (self.sum_of_squares.max(0.0) / self.errors.len() as f64).sqrt();
        (self.config.sigmas * rms).clamp(self.config.min, self.config.max)
    }

    /// Remembers how far off a prediction was (metres, [`point_displacement`] of its
    /// correction); a non-finite or negative error counts as the largest reach.
    pub fn record(&mut self, error: f64) {
        let error = if error.is_finite() && error >= 0.0 {
            error.min(self.config.max)
        } else {
            self.config.max
        };
        if self.errors.len() == self.config.window
            && let Some(old) = self.errors.pop_front()
        {
            self.sum_of_squares -= old * old;
        }
        self.errors.push_back(error);
        self.sum_of_squares += error * error;
        // Recompute once a window so that rounding in the running sum cannot build up.
        self.since_recompute += 1;
        if self.since_recompute >= self.config.window {
            self.since_recompute = 0;
            self.sum_of_squares = self.errors.iter().map(|e| e * e).sum();
        }
    }

    /// Forgets every recorded error: the reach is `initial` again (after a relocalisation,
    /// say, when the recent predictions say nothing about the next).
    pub fn reset(&mut self) {
        self.errors.clear();
        self.sum_of_squares = 0.0;
        self.since_recompute = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reach_is_three_rms_errors_of_the_window() {
        let config = ReachConfig {
            window: 4,
            ..ReachConfig::default()
        };
        let mut reach = AdaptiveReach::new(config).unwrap_or_else(|e| panic!("{e}"));
        for e in [0.1, 0.2, 0.3, 0.4, 0.5] {
            reach.record(e);
        }
        // The window holds 0.2..0.5: RMS sqrt((0.04 + 0.09 + 0.16 + 0.25) / 4).
        let expected = 3.0 * (0.54f64 / 4.0).sqrt();
        assert!((reach.current() - expected).abs() < 1e-12);
        reach.record(f64::NAN);
        assert!(reach.current() > expected);
        reach.reset();
        assert!((reach.current() - 2.0).abs() < f64::EPSILON);
    }

    #[test]
    fn bad_settings_are_named() {
        for (config, setting) in [
            (
                ReachConfig {
                    initial: f64::NAN,
                    ..ReachConfig::default()
                },
                "ReachConfig::initial",
            ),
            (
                ReachConfig {
                    min: 0.0,
                    ..ReachConfig::default()
                },
                "ReachConfig::min",
            ),
            (
                ReachConfig {
                    max: -1.0,
                    ..ReachConfig::default()
                },
                "ReachConfig::max",
            ),
            (
                ReachConfig {
                    max: 0.3,
                    ..ReachConfig::default()
                },
                "ReachConfig::max",
            ),
            (
                ReachConfig {
                    initial: 9.0,
                    ..ReachConfig::default()
                },
                "ReachConfig::initial",
            ),
            (
                ReachConfig {
                    window: 0,
                    ..ReachConfig::default()
                },
                "ReachConfig::window",
            ),
        ] {
            let err = AdaptiveReach::new(config).err();
            assert_eq!(err.map(|e| e.setting), Some(setting));
        }
    }

    #[test]
    fn a_turn_moves_far_points_by_the_chord() {
        let turn = Pose3::from_parts(
            nalgebra::Translation3::new(0.1, 0.0, 0.0),
            nalgebra::UnitQuaternion::from_euler_angles(0.0, 0.0, 10f64.to_radians()),
        );
        // A point 10 m away moves by the chord of 10 degrees: 2 * 10 * sin(5 degrees).
        let expected = 0.1 + 20.0 * 5f64.to_radians().sin();
        assert!((point_displacement(&turn, 10.0) - expected).abs() < 1e-12);
    }
}
