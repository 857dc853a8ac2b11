//! What a robot is, as data: its geometry and how fast it may move.

use crate::robot::geometry::SpotGeometry;
use slam_core::InvalidSetting;

/// How fast the robot may be commanded to move; commands beyond these are clamped to them.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct MotionLimits {
    /// Largest forward or backward speed, m/s: 1.6 m/s, Spot's top walking speed.
    pub max_forward_speed: f64,
    /// Largest sideways speed, m/s: 0.5 m/s, a conservative choice below Spot's own limit.
    pub max_lateral_speed: f64,
    /// Largest turn rate, rad/s: 1.0 rad/s.
    pub max_yaw_rate: f64,
}

impl Default for MotionLimits {
    fn default() -> Self {
        Self {
            max_forward_speed: 1.6,
            max_lateral_speed: 0.5,
            max_yaw_rate: 1.0,
        }
    }
}

impl MotionLimits {
    /// Every limit finite and positive.
    ///
    /// # Errors
    /// [`InvalidSetting`] naming the first bad limit.
    pub fn validate(&self) -> Result<(), InvalidSetting> {
        for (setting, value) in [
            ("max_forward_speed", self.max_forward_speed),
            ("max_lateral_speed", self.max_lateral_speed),
            ("max_yaw_rate", self.max_yaw_rate),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(InvalidSetting {
                    setting,
                    value,
                    expected: "finite and positive",
                });
            }
        }
        Ok(())
    }
}

/// A robot's description: its body and LiDAR mounting, and its motion limits.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RobotDescription {
    /// Body size and LiDAR mounting.
    pub geometry: SpotGeometry,
    /// Speed and turn-rate limits.
    pub limits: MotionLimits,
}

impl RobotDescription {
    /// A description from its parts.
    #[must_use]
    pub fn new(geometry: SpotGeometry, limits: MotionLimits) -> Self {
        Self { geometry, limits }
    }
}
