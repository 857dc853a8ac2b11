//! How the simulated sensor moves along its route: Spot's walk, Spot turning at corners
//! at its full yaw rate, or a person carrying the LiDAR.

use crate::sim::SimError;
use crate::sim::hand_shake::HandShake;
use crate::sim::setting_checks::require_positive;

/// How a [`SimulatedSpot`](crate::sim::SimulatedSpot) moves along its route.
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(tag = "kind")
)]
#[non_exhaustive]
pub enum MotionProfile {
    /// Spot walks at a constant [`SimulationConfig::speed`](crate::sim::SimulationConfig::speed)
    /// with its heading along a 1.2 m chord of the route, so it turns through a corner while
    /// walking on, over 1.2 m (at 0.6 m/s the turn rate rises to 1 rad/s at the corner itself;
    /// about four pairs of 5 Hz scans differ by more than 10° at a right-angled corner). One
    /// sample per LiDAR sweep.
    #[default]
    Walk,
    /// Spot walks each leg at [`SimulationConfig::speed`](crate::sim::SimulationConfig::speed),
    /// stops at each corner and turns in place at its full yaw rate
    /// ([`MotionLimits::max_yaw_rate`](crate::robot::MotionLimits::max_yaw_rate), 1 rad/s) for
    /// as long as the corner takes: 11.5° between 5 Hz scans, with no translation, for about
    /// 1.6 s of a right-angled corner (six pairs of scans differ by more than 10°). One sample
    /// per LiDAR sweep.
    FastTurns(FastTurnsConfig),
    /// A person carries the LiDAR: a brisk walk with a shaking hand, quick turns at the
    /// corners, samples at a lower rate than the sweeps (each sample is one sweep, the others
    /// are dropped, as a recording thinned to 2 Hz).
    Handheld(HandheldConfig),
}

impl MotionProfile {
    /// Spot stopping at corners to turn in place at full yaw rate, with default accelerations.
    #[must_use]
    pub fn fast_turns() -> Self {
        Self::FastTurns(FastTurnsConfig::default())
    }

    /// A person carrying the LiDAR, with the default walk and shake.
    #[must_use]
    pub fn handheld() -> Self {
        Self::Handheld(HandheldConfig::default())
    }
}

/// Spot's accelerations when it stops at corners to turn in place ([`MotionProfile::FastTurns`]);
/// its walking speed and yaw rate are [`SimulationConfig::speed`](crate::sim::SimulationConfig::speed)
/// and [`MotionLimits::max_yaw_rate`](crate::robot::MotionLimits::max_yaw_rate).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct FastTurnsConfig {
    /// Speeding up and slowing down along a leg (m/s²), 1.0: 0.6 m/s reached in 0.6 s.
    pub acceleration: f64,
    /// Starting and stopping a turn (rad/s²), 2.0: 1 rad/s reached in 0.5 s.
    pub yaw_acceleration: f64,
}

impl Default for FastTurnsConfig {
    fn default() -> Self {
        Self {
            acceleration: 1.0,
            yaw_acceleration: 2.0,
        }
    }
}

impl FastTurnsConfig {
    /// Every setting valid.
    ///
    /// # Errors
    /// [`SimError::InvalidConfig`] naming the first setting that is not finite and
    /// positive (`fast_turns.acceleration`, `fast_turns.yaw_acceleration`).
    pub fn validate(&self) -> Result<(), SimError> {
        require_positive(&[
            (
                "fast_turns.acceleration",
                self.acceleration,
                "finite and positive (m/s²)",
            ),
            (
                "fast_turns.yaw_acceleration",
                self.yaw_acceleration,
                "finite and positive (rad/s²)",
            ),
        ])
    }
}

/// A person walking with the LiDAR in hand ([`MotionProfile::Handheld`]).
///
/// The defaults resemble a handheld recording with an Ouster at 2 Hz: 1.2 m/s along the legs,
/// slowing to 0.4 m/s through a corner while turning at up to 1.6 rad/s (92°/s), so that two
/// samples 0.5 s apart differ by up to about 50° of heading around a right-angled corner (and
/// by a few degrees along a corridor, from the hand's sway). The
/// LiDAR is the body (`body_T_lidar` is the identity; [`SimulationConfig::spot`] is not used),
/// carried 1.3 m above the floor.
///
/// [`SimulationConfig::spot`]: crate::sim::SimulationConfig::spot
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct HandheldConfig {
    /// Walking speed along a leg (m/s), 1.2.
    pub speed: f64,
    /// Speed through a corner while turning (m/s), 0.4; 0 stops to turn on the spot. At most
    /// `speed`.
    pub corner_speed: f64,
    /// Speeding up and slowing down (m/s²), 0.8.
    pub acceleration: f64,
    /// Largest turn rate at a corner (rad/s), 1.6.
    pub turn_rate: f64,
    /// Starting and stopping a turn (rad/s²), 6.0.
    pub turn_acceleration: f64,
    /// Height of the LiDAR above the floor (metres), 1.3 (chest height); only the shake
    /// changes it.
    pub height: f64,
    /// Samples per second (hertz), 2: each is one sweep starting at its stamp, the sweeps
    /// between are dropped. At most the LiDAR's rotation rate.
    pub sample_rate: f64,
    /// The hand's shake.
    pub shake: HandShake,
}

impl Default for HandheldConfig {
    fn default() -> Self {
        Self {
            speed: 1.2,
            corner_speed: 0.4,
            acceleration: 0.8,
            turn_rate: 1.6,
            turn_acceleration: 6.0,
            height: 1.3,
            sample_rate: 2.0,
            shake: HandShake::default(),
        }
    }
}

impl HandheldConfig {
    /// Every setting valid for a LiDAR turning at `rotation_rate` (hertz).
    ///
    /// # Errors
    /// [`SimError::InvalidConfig`] naming the first bad setting (`handheld.speed`,
    /// `.acceleration`, `.turn_rate`, `.turn_acceleration`, `.height`, `.sample_rate`: not
    /// finite and positive; `handheld.corner_speed` outside `[0, speed]`;
    /// `handheld.sample_rate` above `rotation_rate`), or as [`HandShake::validate`].
    pub fn validate(&self, rotation_rate: f64) -> Result<(), SimError> {
        require_positive(&[
            ("handheld.speed", self.speed, "finite and positive (m/s)"),
            (
                "handheld.acceleration",
                self.acceleration,
                "finite and positive (m/s²)",
            ),
            (
                "handheld.turn_rate",
                self.turn_rate,
                "finite and positive (rad/s)",
            ),
            (
                "handheld.turn_acceleration",
                self.turn_acceleration,
                "finite and positive (rad/s²)",
            ),
            (
                "handheld.height",
                self.height,
                "finite and positive (metres)",
            ),
            (
                "handheld.sample_rate",
                self.sample_rate,
                "finite and positive (hertz)",
            ),
        ])?;
        if !(0.0..=self.speed).contains(&self.corner_speed) {
            return Err(SimError::invalid(
                "handheld.corner_speed",
                self.corner_speed,
                "within [0, speed] (m/s)",
            ));
        }
        if self.sample_rate > rotation_rate {
            return Err(SimError::invalid(
                "handheld.sample_rate",
                self.sample_rate,
                "at most the LiDAR's rotation rate (hertz): a sample is one whole sweep",
            ));
        }
        self.shake.validate()
    }
}
