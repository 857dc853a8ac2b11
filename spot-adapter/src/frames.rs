//! Spot's body geometry and where the LiDAR sits on it.

use nalgebra::{Translation3, UnitQuaternion};
use slam_core::Pose3;

/// Spot's size and the LiDAR mounting (metres).
///
/// The body frame follows Spot's API: origin at the body's centre, x forward, z up; standing, it
/// sits [`SpotGeometry::body_height`] = 0.50 m above the ground and the body's top is about 0.10 m
/// above the origin. The default mounting puts a VLP-16 on a payload rail 0.30 m above the body
/// origin and 0.05 m behind it, level with the body: the LiDAR's optical centre is then 0.80 m
/// above the ground and the top of the puck (72 mm tall) near 0.84 m, the robot's height with
/// the sensor.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct SpotGeometry {
    /// Height of the body frame above the ground when standing, 0.50 m.
    pub body_height: f64,
    /// Half the robot's width (legs included), 0.25 m: the clearance routes keep from obstacles
    /// is this plus a margin.
    pub half_width: f64,
    /// LiDAR pose in the body frame.
    pub body_t_lidar: Pose3,
}

impl Default for SpotGeometry {
    fn default() -> Self {
        Self {
            body_height: 0.50,
            half_width: 0.25,
            body_t_lidar: Pose3::from_parts(
                Translation3::new(-0.05, 0.0, 0.30),
                UnitQuaternion::identity(),
            ),
        }
    }
}

/// The body's sway while trotting: a vertical bob and roll/pitch oscillations at the step
/// frequency, added to the level ground-truth pose. Off by default (all amplitudes zero); about
/// 0.01 m and 0.01 rad (0.6°) at 1.8 Hz resemble a walking Spot.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
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
