//! Point-to-point ICP with a closed-form weighted SVD (Arun/Umeyama) step
//! ([`slam_core::fit_weighted_rigid_transform`]).

use nalgebra::{Matrix6, Point3, Vector6};
use slam_core::{
    Alignment, MapRegistrator, PointCloud, Pose3, Reach, RegistrationError, Registrator,
    WeightedPair, fit_weighted_rigid_transform, se3_log,
};

use crate::config::IcpConfig;
use crate::icp::{IcpStep, Pair, align, point_jacobian};
use crate::icp_target;
use crate::target::{PreparedTarget, prepare_source_points};

/// Point-to-point ICP: each iteration pairs every source point with its nearest target point and
/// takes the weighted least-squares rigid transform between the pairs in closed form.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PointToPointIcp {
    /// Settings.
    pub config: IcpConfig,
}

struct Svd;

impl IcpStep for Svd {
    const TARGET_NORMALS: bool = false;

    fn residual(pair: &Pair) -> f64 {
        (pair.p - pair.q).norm()
    }

    fn step(pairs: &[Pair], weights: &[f64]) -> Result<Vector6<f64>, RegistrationError> {
        let step = fit_weighted_rigid_transform(pairs.iter().zip(weights).map(|(p, &weight)| {
            WeightedPair {
                from: p.p,
                to: p.q,
                weight,
            }
        }))?;
        Ok(se3_log(&step))
    }

    fn information(pairs: &[Pair], weights: &[f64]) -> Matrix6<f64> {
        pairs
            .iter()
            .zip(weights)
            .fold(Matrix6::zeros(), |m, (p, w)| {
                let j = point_jacobian(&p.p);
                m + j.transpose() * j * *w
            })
    }
}

impl Registrator for PointToPointIcp {
    type Source = Vec<Point3<f64>>;
    type Target = PreparedTarget;

    fn prepare_source(&self, cloud: &PointCloud) -> Result<Self::Source, RegistrationError> {
        prepare_source_points(&self.config, cloud)
    }

    fn prepare_target(&self, cloud: &PointCloud) -> Result<Self::Target, RegistrationError> {
        icp_target::prepare_target::<Svd>(&self.config, cloud)
    }

    fn align(
        &self,
        source: &Self::Source,
        target: &Self::Target,
        initial: &Pose3,
    ) -> Result<Alignment, RegistrationError> {
        align::<Svd>(
            &self.config,
            self.config.pair_target_points,
            source,
            target,
            initial,
        )
    }

    fn align_within(
        &self,
        source: &Self::Source,
        target: &Self::Target,
        initial: &Pose3,
        reach: &Reach,
    ) -> Result<Alignment, RegistrationError> {
        align::<Svd>(
            &self.config.within(reach)?,
            self.config.pair_target_points,
            source,
            target,
            initial,
        )
    }
}

impl MapRegistrator for PointToPointIcp {
    fn target_from_sources(
        &self,
        parts: &[(&Self::Source, Pose3)],
    ) -> Result<Self::Target, RegistrationError> {
        icp_target::target_from_sources::<Svd>(&self.config, parts)
    }

    /// [`IcpConfig::source_voxel`] when above zero: the source is the scan's voxel centroids.
    fn source_voxel(&self) -> Option<f32> {
        icp_target::source_voxel(&self.config)
    }

    /// As [`PointToPlaneIcp`](crate::PointToPlaneIcp)'s: with a
    /// [`IcpConfig::target_voxel`] above zero, a map of per-voxel sums updated in place.
    fn empty_map(&self) -> Option<Self::Target> {
        icp_target::empty_map::<Svd>(&self.config)
    }

    fn add_to_map(&self, map: &mut Self::Target, key: u32, source: &Self::Source, pose: &Pose3) {
        map.add_part(key, source, pose);
    }

    fn remove_from_map(&self, map: &mut Self::Target, key: u32) {
        map.remove_part(key);
    }
}
