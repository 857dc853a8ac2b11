//! Point-to-plane ICP: Gauss-Newton on SE(3) with target normals from PCA.

use nalgebra::{Matrix6, Point3, Vector6};
use slam_core::{
    Alignment, Degeneracy, MapRegistrator, PointCloud, Pose3, Reach, RegistrationError,
    Registrator, SweepAlignment,
};

use crate::config::IcpConfig;
use crate::icp::{IcpStep, Pair, align};
use crate::icp_target;
use crate::target::{PreparedTarget, prepare_source_points};

/// Point-to-plane ICP: residual `n . (T p - q)` against the target point's normal (PCA over its
/// nearest neighbours), minimised by Gauss-Newton steps on SE(3) with robust weights.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PointToPlaneIcp {
    /// Settings.
    pub config: IcpConfig,
}

struct GaussNewtonPlane;

/// `(J^T W J, J^T W r)` of the pairs with a non-zero weight.
fn normal_equations(pairs: &[Pair], weights: &[f64]) -> (Matrix6<f64>, Vector6<f64>) {
    let mut h = Matrix6::zeros();
    let mut b = Vector6::zeros();
    for (p, w) in pairs.iter().zip(weights) {
        if *w == 0.0 {
            continue;
        }
        let j = row(p);
        // Lower triangle only, in place.
        h.syger(*w, &j, &j, 1.0);
        b.axpy(GaussNewtonPlane::residual(p) * w, &j, 1.0);
    }
    h.fill_upper_triangle_with_lower_triangle();
    (h, b)
}

/// `J = [n^T, (p x n)^T]` for a left perturbation of the moved point `p`.
fn row(pair: &Pair) -> Vector6<f64> {
    let n = pair.n.unwrap_or_default();
    let c = pair.p.coords.cross(&n);
    Vector6::new(n.x, n.y, n.z, c.x, c.y, c.z)
}

impl IcpStep for GaussNewtonPlane {
    const TARGET_NORMALS: bool = true;

    fn residual(pair: &Pair) -> f64 {
        pair.n.map_or(f64::INFINITY, |n| n.dot(&(pair.p - pair.q)))
    }

    fn step(pairs: &[Pair], weights: &[f64]) -> Result<Vector6<f64>, RegistrationError> {
        let (h, b) = normal_equations(pairs, weights);
        h.cholesky()
            .map(|c| -c.solve(&b))
            .ok_or(RegistrationError::Degenerate {
                cause: Degeneracy::SingularNormalEquations,
            })
    }

    fn normal_equations(pairs: &[Pair], weights: &[f64]) -> Option<(Matrix6<f64>, Vector6<f64>)> {
        Some(normal_equations(pairs, weights))
    }

    fn information(pairs: &[Pair], weights: &[f64]) -> Matrix6<f64> {
        normal_equations(pairs, weights).0
    }
}

impl Registrator for PointToPlaneIcp {
    type Source = Vec<Point3<f64>>;
    type Target = PreparedTarget;

    fn prepare_source(&self, cloud: &PointCloud) -> Result<Self::Source, RegistrationError> {
        prepare_source_points(&self.config, cloud)
    }

    fn prepare_target(&self, cloud: &PointCloud) -> Result<Self::Target, RegistrationError> {
        icp_target::prepare_target::<GaussNewtonPlane>(&self.config, cloud)
    }

    fn align(
        &self,
        source: &Self::Source,
        target: &Self::Target,
        initial: &Pose3,
    ) -> Result<Alignment, RegistrationError> {
        align::<GaussNewtonPlane>(&self.config, 1, source, target, initial)
    }

    fn align_within(
        &self,
        source: &Self::Source,
        target: &Self::Target,
        initial: &Pose3,
        reach: &Reach,
    ) -> Result<Alignment, RegistrationError> {
        align::<GaussNewtonPlane>(&self.config.within(reach)?, 1, source, target, initial)
    }

    /// Point-to-plane registration of the sweep together with the correction to the velocity
    /// it was deskewed with (see the crate docs' sweep section).
    fn align_sweep(
        &self,
        sweep: &PointCloud,
        target: &Self::Target,
        initial: &Pose3,
    ) -> Option<Result<SweepAlignment, RegistrationError>> {
        Some(crate::sweep::align_sweep(
            &self.config,
            sweep,
            target,
            initial,
        ))
    }
}

impl MapRegistrator for PointToPlaneIcp {
    fn target_from_sources(
        &self,
        parts: &[(&Self::Source, Pose3)],
    ) -> Result<Self::Target, RegistrationError> {
        icp_target::target_from_sources::<GaussNewtonPlane>(&self.config, parts)
    }

    /// [`IcpConfig::source_voxel`] when above zero: the source is the scan's voxel centroids.
    fn source_voxel(&self) -> Option<f32> {
        icp_target::source_voxel(&self.config)
    }

    /// With a [`IcpConfig::target_voxel`] above zero (and a valid configuration), a map kept
    /// as per-voxel sums: a keyframe enters and leaves at the cost of its own points, and the
    /// k-d tree is rebuilt over the voxel centroids on the first alignment after a change.
    /// It holds the points [`MapRegistrator::target_from_sources`] would (up to rounding).
    fn empty_map(&self) -> Option<Self::Target> {
        icp_target::empty_map::<GaussNewtonPlane>(&self.config)
    }

    fn add_to_map(&self, map: &mut Self::Target, key: u32, source: &Self::Source, pose: &Pose3) {
        map.add_part(key, source, pose);
    }

    fn remove_from_map(&self, map: &mut Self::Target, key: u32) {
        map.remove_part(key);
    }
}
