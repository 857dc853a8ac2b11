//! Pose aliases, quaternion conversions that name their component order, and interpolation.

use nalgebra::{Isometry2, Isometry3, Quaternion, Translation3, UnitQuaternion};

use super::se3::{se3_exp, se3_log};

/// A rigid transform in 3D, named `a_T_b` where it maps points in frame b into frame a.
pub type Pose3 = Isometry3<f64>;
/// A rigid transform in the plane.
pub type Pose2 = Isometry2<f64>;

/// A unit quaternion from components in `[qx, qy, qz, qw]` order (TUM, g2o, ROS messages).
/// Returns `None` when the components are not finite or their norm is far from one (outside
/// `[0.9, 1.1]`); otherwise the quaternion is renormalised.
#[must_use]
pub fn quaternion_from_xyzw(q: [f64; 4]) -> Option<UnitQuaternion<f64>> {
    quaternion_checked(Quaternion::new(q[3], q[0], q[1], q[2]))
}

/// A unit quaternion from components in `[qw, qx, qy, qz]` order (Eigen's constructor, Spot's
/// API is xyzw). Same checks as [`quaternion_from_xyzw`].
#[must_use]
pub fn quaternion_from_wxyz(q: [f64; 4]) -> Option<UnitQuaternion<f64>> {
    quaternion_checked(Quaternion::new(q[0], q[1], q[2], q[3]))
}

fn quaternion_checked(q: Quaternion<f64>) -> Option<UnitQuaternion<f64>> {
    let n = q.norm();
    if !n.is_finite() || !(0.9..=1.1).contains(&n) {
        return None;
    }
    Some(UnitQuaternion::from_quaternion(q))
}

/// Components `[qx, qy, qz, qw]`.
#[must_use]
pub fn quaternion_to_xyzw(q: &UnitQuaternion<f64>) -> [f64; 4] {
    [q.i, q.j, q.k, q.w]
}

/// Components `[qw, qx, qy, qz]`.
#[must_use]
pub fn quaternion_to_wxyz(q: &UnitQuaternion<f64>) -> [f64; 4] {
    [q.w, q.i, q.j, q.k]
}

/// A pose from a translation and roll, pitch, yaw (radians; applied as yaw * pitch * roll about
/// fixed x, y, z axes).
#[must_use]
pub fn pose3_from_xyz_rpy(x: f64, y: f64, z: f64, roll: f64, pitch: f64, yaw: f64) -> Pose3 {
    Isometry3::from_parts(
        Translation3::new(x, y, z),
        UnitQuaternion::from_euler_angles(roll, pitch, yaw),
    )
}

/// Whether every number of `pose` is finite.
#[must_use]
pub fn pose3_is_finite(pose: &Pose3) -> bool {
    pose.translation.vector.iter().all(|v| v.is_finite())
        && pose.rotation.coords.iter().all(|v| v.is_finite())
}

/// The pose a fraction `t` of the way from `a` to `b` along the SE(3) geodesic
/// (`a exp(t log(a^-1 b))`); `t = 0` gives `a`, `t = 1` gives `b`. For timestamps between two
/// odometry readings, for example.
#[must_use]
pub fn interpolate(a: &Pose3, b: &Pose3, t: f64) -> Pose3 {
    let delta = se3_log(&(a.inverse() * b));
    a * se3_exp(&(delta * t))
}
