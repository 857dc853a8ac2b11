//! `Sample`: one LiDAR scan with the robot's odometry and the sensor's mounting, as every source
//! (live robot, simulator, recording) delivers it to the SLAM engine.

use nalgebra::UnitQuaternion;
use slam_core::{PointCloud, Pose3, ScanInput};

/// One scan and what the robot knew when it was taken.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    /// Seconds (the scan's start).
    pub stamp: f64,
    /// The robot's odometry: body pose in its odometry frame.
    pub odom_t_body: Pose3,
    /// The LiDAR's mounting: LiDAR pose in the body frame.
    pub body_t_lidar: Pose3,
    /// Points in the LiDAR frame.
    pub cloud: PointCloud,
    /// Ground truth `world_T_body` when the source knows it (simulator, recordings with ground
    /// truth, KITTI poses). For evaluation only: never feed it to the estimator.
    pub ground_truth: Option<Pose3>,
    /// The body's orientation at `stamp` integrated from a gyro since the start of the recording
    /// (`start_R_body`): it drifts, but its change between two samples is the body's rotation
    /// between them. `None` when the source has no IMU, outside the IMU's readings, and for the
    /// first sample after a gap in them (so that two consecutive samples that both have one are
    /// joined by integrated readings). Bags: see `record::GyroIntegrator` (feature `record`).
    pub gyro_orientation: Option<UnitQuaternion<f64>>,
}

impl Sample {
    /// The sample as the Graph-SLAM engine's input (ground truth left out).
    #[must_use]
    pub fn scan_input(&self) -> ScanInput<'_> {
        ScanInput {
            stamp: self.stamp,
            odom_t_body: Some(self.odom_t_body),
            body_t_lidar: self.body_t_lidar,
            cloud: &self.cloud,
            gyro_orientation: self.gyro_orientation,
        }
    }

    /// The sample as the engine's input without its odometry: the engine tracks the scan by
    /// registration alone (for a source with no odometry, or to leave the robot's out), its
    /// orientation predicted by the gyro when the sample has one.
    #[must_use]
    pub fn lidar_only_input(&self) -> ScanInput<'_> {
        ScanInput {
            odom_t_body: None,
            ..self.scan_input()
        }
    }

    /// The LiDAR's pose in the odometry frame, `odom_T_body * body_T_lidar`.
    #[must_use]
    pub fn odom_t_lidar(&self) -> Pose3 {
        self.odom_t_body * self.body_t_lidar
    }
}
