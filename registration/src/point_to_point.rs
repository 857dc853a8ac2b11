//! Point-to-point ICP with a closed-form weighted SVD (Arun/Umeyama) step
//! ([`slam_core::fit_weighted_rigid_transform`]).

use nalgebra::{Matrix6, Vector6};
use slam_core::{RegistrationError, WeightedPair, fit_weighted_rigid_transform, se3_log};

use crate::config::IcpConfig;
use crate::icp::{IcpStep, Pair, point_jacobian};
use crate::icp_backend::icp_backend;

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

    fn pair_points(config: &IcpConfig) -> usize {
        config.pair_target_points
    }

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

icp_backend!(PointToPointIcp, Svd);
