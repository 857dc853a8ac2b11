//! The body's sway while trotting, added to the level ground-truth pose of a simulated walk.

use nalgebra::{Translation3, UnitQuaternion};
use slam_core::Pose3;

/// The body's sway while trotting: a vertical bob and roll/pitch oscillations at the step
/// frequency, added to the level ground-truth pose. Off by default (all amplitudes zero); about
/// 0.01 m and 0.01 rad (0.6°) at 1.8 Hz resemble a walking Spot.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct GaitSway {
    /// Vertical bob amplitude (metres), 0 by default.
    pub height: f64,
    /// Roll and pitch amplitude (radians), 0 by default.
    pub tilt: f64,
    /// Step frequency (hertz), 1.8 Hz.
    pub frequency: f64,
}

impl Default for GaitSway {
    fn default() -> Self {
        Self {
            height: 0.0,
            tilt: 0.0,
            frequency: 1.8,
        }
    }
}

impl GaitSway {
    /// The sway at time `t` (seconds) as a body-frame offset: bob at the step frequency, roll
    /// at half of it (left and right legs alternate), pitch a quarter period after the bob.
    #[must_use]
    pub fn offset(&self, t: f64) -> Pose3 {
        let w = std::f64::consts::TAU * self.frequency * t;
        Pose3::from_parts(
            Translation3::new(0.0, 0.0, self.height * w.sin()),
            UnitQuaternion::from_euler_angles(
                self.tilt * (0.5 * w).sin(),
                self.tilt * w.cos(),
                0.0,
            ),
        )
    }
}
