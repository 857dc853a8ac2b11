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
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
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
