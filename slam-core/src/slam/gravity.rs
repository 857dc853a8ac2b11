//! The registered pose levelled on the odometry's gravity: its roll and pitch replaced by the
//! odometry's, its heading and position kept.
//!
//! A robot's odometry frame has its z axis up (Spot's state estimator takes roll and pitch from
//! its IMU), and the engine's map frame is the odometry frame at the first scan, so the body's
//! roll and pitch in the map are the odometry's, to the IMU's accuracy, for ever. Registration
//! against a local map that drifts with the walk does not keep them: on a simulated 800 m walk
//! the estimate tilted 1 degree, and walking forward on a tilted estimate is climbing (0.4 m).

use nalgebra::UnitQuaternion;

use crate::geometry::Pose3;

/// `map_t_lidar` with the body's roll and pitch set to those of `odom_t_body` (the LiDAR mounted
/// at `body_t_lidar`): the body's heading and position in the map are kept. Both frames must
/// have their z axis up (the map made from that odometry, e.g. by [`GraphSlam`](crate::GraphSlam)).
/// For a body pose, pass the identity as `body_t_lidar`.
///
/// ```
/// use slam_core::{Pose3, level_on_gravity};
/// use slam_core::nalgebra::{Translation3, UnitQuaternion};
///
/// let tilted = Pose3::from_parts(
///     Translation3::new(1.0, 2.0, 0.5),
///     UnitQuaternion::from_euler_angles(0.02, -0.01, 0.7),
/// );
/// let level = level_on_gravity(&tilted, &Pose3::identity(), &Pose3::identity());
/// let (roll, pitch, yaw) = level.rotation.euler_angles();
/// assert!(roll.abs() < 1e-12 && pitch.abs() < 1e-12 && (yaw - 0.7).abs() < 1e-12);
/// ```
#[must_use]
pub fn level_on_gravity(map_t_lidar: &Pose3, odom_t_body: &Pose3, body_t_lidar: &Pose3) -> Pose3 {
    let map_t_body = map_t_lidar * body_t_lidar.inverse();
    let (_, _, heading) = map_t_body.rotation.euler_angles();
    let (roll, pitch, _) = odom_t_body.rotation.euler_angles();
    let levelled = Pose3::from_parts(
        map_t_body.translation,
        UnitQuaternion::from_euler_angles(roll, pitch, heading),
    );
    levelled * body_t_lidar
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::{Translation3, Vector3};

    fn pose(x: f64, y: f64, z: f64, roll: f64, pitch: f64, yaw: f64) -> Pose3 {
        Pose3::from_parts(
            Translation3::new(x, y, z),
            UnitQuaternion::from_euler_angles(roll, pitch, yaw),
        )
    }

    /// A body tilted 1 degree in the estimate and level in the odometry comes out level, at the
    /// same heading and position; the LiDAR 0.3 m above the body moves with the body's turn.
    #[test]
    fn the_tilt_is_the_odometrys_and_the_heading_and_position_the_estimates() {
        let body_t_lidar = pose(0.1, 0.0, 0.3, 0.0, 0.0, 0.0);
        let map_t_body = pose(4.0, -2.0, 0.35, 0.01, -0.015, 2.5);
        let odom_t_body = pose(40.0, 7.0, -3.0, 0.002, 0.001, -1.0);
        let out = level_on_gravity(&(map_t_body * body_t_lidar), &odom_t_body, &body_t_lidar);
        let body = out * body_t_lidar.inverse();
        let (roll, pitch, yaw) = body.rotation.euler_angles();
        assert_relative_eq!(roll, 0.002, epsilon = 1e-12);
        assert_relative_eq!(pitch, 0.001, epsilon = 1e-12);
        assert_relative_eq!(yaw, 2.5, epsilon = 1e-12);
        assert_relative_eq!(
            body.translation.vector,
            Vector3::new(4.0, -2.0, 0.35),
            epsilon = 1e-12
        );
        // The body's up axis in the map is the odometry's.
        let up = body.rotation * Vector3::z();
        let odom_up = odom_t_body.rotation * Vector3::z();
        assert_relative_eq!(up.z, odom_up.z, epsilon = 1e-12);
    }

    /// A pose already on gravity is returned unchanged.
    #[test]
    fn a_level_estimate_is_kept() {
        let body_t_lidar = pose(0.0, 0.0, 0.3, 0.0, 0.05, 0.0);
        let map_t_lidar = pose(1.0, 2.0, 0.8, 0.0, 0.05, 0.7);
        let odom_t_body = pose(0.0, 0.0, 0.0, 0.0, 0.0, 1.9);
        let out = level_on_gravity(&map_t_lidar, &odom_t_body, &body_t_lidar);
        assert_relative_eq!(
            out.translation.vector,
            map_t_lidar.translation.vector,
            epsilon = 1e-12
        );
        assert!(out.rotation.angle_to(&map_t_lidar.rotation) < 1e-12);
    }
}
