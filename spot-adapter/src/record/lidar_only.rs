//! Odometry for a source that has none (a folder of scans, a bag without odometry or tf): each
//! scan registered against the previous one from a constant-velocity guess, the motion of the
//! last step continued for this step's time. The engine then refines keyframes against its
//! local map as it does with robot odometry; without this, an identity odometry would never
//! move the LiDAR far enough to make a second keyframe.

use slam_core::{PointCloud, Pose3, Registrator, se3_exp, se3_log};

use crate::error::AdapterError;
use crate::robot::Sample;

/// Settings of [`ScanToScanOdometry`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScanToScanConfig {
    /// Voxel (metres) the scans are thinned to before registration; usual value 0.25 m.
    pub voxel_size: f32,
    /// A registration that moves the guess by more than this (metres) is taken as diverged and
    /// the guess kept; usual value 1.0 m.
    pub max_correction: f64,
}

impl Default for ScanToScanConfig {
    fn default() -> Self {
        Self {
            voxel_size: 0.25,
            max_correction: 1.0,
        }
    }
}

/// The scan before, prepared as a registration target.
struct Previous<T> {
    target: T,
    stamp: f64,
    odom_t_lidar: Pose3,
}

/// Wraps a sample source without odometry and fills in `odom_T_body` from the scans (the
/// samples' own odometry is ignored). `registrator` aligns each scan to the one before.
pub struct ScanToScanOdometry<R: Registrator, I> {
    registrator: R,
    samples: I,
    config: ScanToScanConfig,
    previous: Option<Previous<R::Target>>,
    /// The last step's twist per second (se(3), LiDAR frame).
    velocity: Option<nalgebra::Vector6<f64>>,
    fallbacks: usize,
}

impl<R: Registrator, I> std::fmt::Debug for ScanToScanOdometry<R, I> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ScanToScanOdometry")
            .field("config", &self.config)
            .field("fallbacks", &self.fallbacks)
            .finish_non_exhaustive()
    }
}

impl<R: Registrator, I> ScanToScanOdometry<R, I> {
    /// `samples` with odometry from `registrator`.
    pub fn new(registrator: R, samples: I, config: ScanToScanConfig) -> Self {
        Self {
            registrator,
            samples,
            config,
            previous: None,
            velocity: None,
            fallbacks: 0,
        }
    }

    /// Scans whose registration failed or diverged, for which the guess was kept.
    #[must_use]
    pub fn fallbacks(&self) -> usize {
        self.fallbacks
    }

    /// The wrapped source.
    #[must_use]
    pub fn inner(&self) -> &I {
        &self.samples
    }

    fn odometry(&mut self, sample: &Sample) -> Pose3 {
        let thinned = sample
            .cloud
            .voxel_downsample(self.config.voxel_size)
            .unwrap_or_else(|_| PointCloud::from_points(sample.cloud.points().to_vec()));
        let target = self.registrator.prepare_target(&thinned).ok();
        let Some(prev) = self.previous.take() else {
            if let Some(target) = target {
                self.previous = Some(Previous {
                    target,
                    stamp: sample.stamp,
                    odom_t_lidar: Pose3::identity(),
                });
            }
            return Pose3::identity();
        };
        let dt = sample.stamp - prev.stamp;
        let guess = match self.velocity {
            Some(v) if dt > 0.0 && dt.is_finite() => se3_exp(&(v * dt)),
            _ => Pose3::identity(),
        };
        let step = self
            .registrator
            .prepare_source(&thinned)
            .ok()
            .and_then(|source| self.registrator.align(&source, &prev.target, &guess).ok())
            .filter(|a| {
                a.converged
                    && (a.pose.translation.vector - guess.translation.vector).norm()
                        <= self.config.max_correction
            })
            .map_or_else(
                || {
                    self.fallbacks += 1;
                    guess
                },
                |a| a.pose,
            );
        if dt > 0.0 && dt.is_finite() {
            self.velocity = Some(se3_log(&step) / dt);
        }
        let odom_t_lidar = prev.odom_t_lidar * step;
        self.previous = Some(match target {
            Some(target) => Previous {
                target,
                stamp: sample.stamp,
                odom_t_lidar,
            },
            None => prev,
        });
        odom_t_lidar
    }
}

impl<R, I> Iterator for ScanToScanOdometry<R, I>
where
    R: Registrator,
    I: Iterator<Item = Result<Sample, AdapterError>>,
{
    type Item = Result<Sample, AdapterError>;

    fn next(&mut self) -> Option<Self::Item> {
        let mut sample = match self.samples.next()? {
            Ok(s) => s,
            Err(e) => return Some(Err(e)),
        };
        let odom_t_lidar = self.odometry(&sample);
        sample.odom_t_body = odom_t_lidar * sample.body_t_lidar.inverse();
        Some(Ok(sample))
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        self.samples.size_hint()
    }
}

impl<R, I> ExactSizeIterator for ScanToScanOdometry<R, I>
where
    R: Registrator,
    I: ExactSizeIterator<Item = Result<Sample, AdapterError>>,
{
}
