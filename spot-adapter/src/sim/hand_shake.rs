//! How a LiDAR carried in the hand shakes: height bob, roll, pitch and yaw sway added to the
//! level pose of a simulated handheld walk.

use std::f64::consts::TAU;

use nalgebra::{Translation3, UnitQuaternion};
use slam_core::Pose3;

use crate::sim::SimError;
use crate::sim::setting_checks::{require_non_negative, require_positive};

/// Seconds over which the shake fades in after the start and out before the end.
const FADE: f64 = 1.0;

/// The shake of a LiDAR carried by a walking person, as a body-frame offset on the level pose.
///
/// Each motion is bounded by its amplitude: the height bobs at the step frequency, the pitch
/// nods at the step frequency plus a slow wander, the roll rocks at half the step frequency (the
/// weight shifts from foot to foot) plus a slow wander, and the yaw sways at two frequencies
/// that are no multiple of the steps (the carrier's hand and shoulders, looking around). It fades in over the
/// first second and out over the last, as the carrier starts and stops, so a closed lap ends at
/// the pose it started from. The phases are fixed, so the ground truth does not depend on the
/// seed.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct HandShake {
    /// Height bob amplitude (metres), 0.02 m.
    pub height: f64,
    /// Roll amplitude (radians), 3°.
    pub roll: f64,
    /// Pitch amplitude (radians), 3°.
    pub pitch: f64,
    /// Yaw sway amplitude (radians), 8°: along a corridor the heading changes by about 5°
    /// between samples 0.5 s apart (median), as in a real handheld recording.
    pub yaw: f64,
    /// Step frequency (hertz), 1.9 Hz (a brisk walk).
    pub step_frequency: f64,
}

impl Default for HandShake {
    fn default() -> Self {
        Self {
            height: 0.02,
            roll: 3f64.to_radians(),
            pitch: 3f64.to_radians(),
            yaw: 8f64.to_radians(),
            step_frequency: 1.9,
        }
    }
}

impl HandShake {
    /// No shake at all.
    #[must_use]
    pub fn none() -> Self {
        Self {
            height: 0.0,
            roll: 0.0,
            pitch: 0.0,
            yaw: 0.0,
            ..Self::default()
        }
    }

    /// Every setting valid.
    ///
    /// # Errors
    /// [`SimError::InvalidConfig`] naming the first amplitude that is negative or not
    /// finite (`hand_shake.height`, `.roll`, `.pitch`, `.yaw`), or a step frequency that is
    /// not finite and positive (`hand_shake.step_frequency`).
    pub fn validate(&self) -> Result<(), SimError> {
        require_non_negative(&[
            ("hand_shake.height", self.height),
            ("hand_shake.roll", self.roll),
            ("hand_shake.pitch", self.pitch),
            ("hand_shake.yaw", self.yaw),
        ])?;
        require_positive(&[(
            "hand_shake.step_frequency",
            self.step_frequency,
            "finite and positive (hertz)",
        )])
    }

    /// The shake at time `t` (seconds) of a walk lasting `duration` seconds, as a body-frame
    /// offset.
    #[must_use]
    pub fn offset(&self, t: f64, duration: f64) -> Pose3 {
        // Smoothstep from 0 at either end to 1 a second in.
        let e = (t.min(duration - t) / FADE).clamp(0.0, 1.0);
        let envelope = e * e * (3.0 - 2.0 * e);
        let step = TAU * self.step_frequency * t;
        let wave = |hz: f64, phase: f64| (TAU * hz * t + phase).sin();
        let roll = self.roll * (0.7 * (0.5 * step).sin() + 0.3 * wave(0.23, 1.0));
        let pitch = self.pitch * (0.6 * step.cos() + 0.4 * wave(0.31, 2.0));
        let yaw = self.yaw * (0.6 * wave(0.47, 0.5) + 0.4 * wave(1.13, 2.5));
        Pose3::from_parts(
            Translation3::new(0.0, 0.0, envelope * self.height * step.sin()),
            UnitQuaternion::from_euler_angles(envelope * roll, envelope * pitch, envelope * yaw),
        )
    }
}
