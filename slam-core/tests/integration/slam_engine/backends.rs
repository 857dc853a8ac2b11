//! The test-only backends: brute-force point-to-point ICP and dense Gauss-Newton.

use nalgebra::{DMatrix, DVector, Matrix3, Matrix6, Point3, Vector3, Vector6};
use slam_core::{
    Alignment, FactorizationFailure, GraphPose, OptimizationReport, OptimizeError, Optimizer,
    PointCloud, Pose3, PoseGraph, Reach, RegistrationError, Registrator, StopReason,
    WholeMapRegistrator, se3_exp, se3_left_jacobian, se3_log,
};

/// Point-to-point ICP with brute-force nearest neighbours (Arun/Umeyama step).
pub(super) struct BruteIcp {
    pub(super) max_distance: f64,
}

pub(super) struct Prepared(pub(super) Vec<Point3<f64>>);

/// How many sources the engines of this test binary read back from a keyframe store.
pub(super) static RESTORED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

fn points(cloud: &PointCloud, voxel: f32) -> Vec<Point3<f64>> {
    cloud
        .voxel_downsample(voxel)
        .unwrap()
        .points()
        .iter()
        .map(|p| p.cast::<f64>())
        .collect()
}

impl Registrator for BruteIcp {
    type Source = Prepared;
    type Target = Prepared;
    fn prepare_source(&self, cloud: &PointCloud) -> Result<Prepared, RegistrationError> {
        Ok(Prepared(points(cloud, 0.4)))
    }
    fn prepare_target(&self, cloud: &PointCloud) -> Result<Prepared, RegistrationError> {
        Ok(Prepared(points(cloud, 0.2)))
    }
    fn align(
        &self,
        s: &Prepared,
        t: &Prepared,
        initial: &Pose3,
    ) -> Result<Alignment, RegistrationError> {
        Self::align_reaching(s, t, initial, self.max_distance)
    }
    fn align_within(
        &self,
        s: &Prepared,
        t: &Prepared,
        initial: &Pose3,
        reach: &Reach,
    ) -> Result<Alignment, RegistrationError> {
        Self::align_reaching(s, t, initial, reach.distance)
    }
}

impl BruteIcp {
    /// Brute-force nearest-point ICP pairing points at most `max_distance` apart.
    fn align_reaching(
        s: &Prepared,
        t: &Prepared,
        initial: &Pose3,
        max_distance: f64,
    ) -> Result<Alignment, RegistrationError> {
        let mut pose = *initial;
        let mut converged = false;
        let (mut inliers, mut sq) = (0, 0.0);
        let mut iterations = 0;
        for it in 0..30 {
            iterations = it + 1;
            let pairs: Vec<(Point3<f64>, Point3<f64>)> =
                s.0.iter()
                    .filter_map(|p| {
                        let q = pose * p;
                        let (best, d2) =
                            t.0.iter()
                                .map(|c| (c, (c - q).norm_squared()))
                                .min_by(|a, b| a.1.total_cmp(&b.1))?;
                        (d2 < max_distance * max_distance).then_some((q, *best))
                    })
                    .collect();
            if pairs.len() < 10 {
                return Err(RegistrationError::TooFewCorrespondences {
                    found: pairs.len(),
                    required: 10,
                });
            }
            let n = pairs.len() as f64;
            let ca = pairs
                .iter()
                .fold(Vector3::zeros(), |a, (p, _)| a + p.coords)
                / n;
            let cb = pairs
                .iter()
                .fold(Vector3::zeros(), |a, (_, q)| a + q.coords)
                / n;
            let h = pairs.iter().fold(Matrix3::zeros(), |m, (p, q)| {
                m + (p.coords - ca) * (q.coords - cb).transpose()
            });
            let svd = h.svd(true, true);
            let (u, vt) = (svd.u.unwrap(), svd.v_t.unwrap());
            let mut d = Matrix3::identity();
            d[(2, 2)] = (vt.transpose() * u.transpose()).determinant().signum();
            let r = vt.transpose() * d * u.transpose();
            let step = Pose3::from_parts(
                (cb - r * ca).into(),
                nalgebra::UnitQuaternion::from_matrix(&r),
            );
            pose = step * pose;
            inliers = pairs.len();
            sq = pairs
                .iter()
                .map(|(p, q)| (step * p - q).norm_squared())
                .sum::<f64>()
                / n;
            if se3_log(&step).norm() < 1e-6 {
                converged = true;
                break;
            }
        }
        Ok(Alignment {
            pose,
            converged,
            iterations,
            inliers,
            inlier_ratio: inliers as f64 / s.0.len() as f64,
            rmse: sq.sqrt(),
            information: Matrix6::identity(),
            min_eigenvalue_ratio: 1.0,
        })
    }
}

impl WholeMapRegistrator for BruteIcp {
    fn whole_map(&self, parts: &[(&Prepared, Pose3)]) -> Result<Prepared, RegistrationError> {
        let mut cloud = PointCloud::new();
        for (src, pose) in parts {
            let pts = src.0.iter().map(|p| (pose * p).cast::<f32>()).collect();
            cloud.extend_from(&PointCloud::from_points(pts)).unwrap();
        }
        Ok(Prepared(points(&cloud, 0.2)))
    }

    /// Exact little-endian f64 coordinates, so that the engine may keep old keyframes' points in
    /// its keyframe store.
    fn stored_source(&self, source: &Prepared) -> Option<Vec<u8>> {
        Some(
            source
                .0
                .iter()
                .flat_map(|p| [p.x, p.y, p.z])
                .flat_map(f64::to_le_bytes)
                .collect(),
        )
    }

    fn restored_source(&self, bytes: &[u8]) -> Option<Prepared> {
        RESTORED.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let values: Vec<f64> = bytes
            .chunks_exact(8)
            .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
            .collect();
        bytes.len().is_multiple_of(24).then(|| {
            Prepared(
                values
                    .chunks_exact(3)
                    .map(|v| Point3::new(v[0], v[1], v[2]))
                    .collect(),
            )
        })
    }
}

/// Dense Gauss-Newton on SE(3) with numeric-free analytic Jacobians of the log-map error
/// (small graphs only).
pub(super) struct DenseGaussNewton;

impl Optimizer<Pose3> for DenseGaussNewton {
    fn optimize(&mut self, g: &mut PoseGraph<Pose3>) -> Result<OptimizationReport, OptimizeError> {
        g.check_gauge()?;
        let n = g.node_count();
        let initial = g.cost();
        let mut iterations = 0;
        for _ in 0..20 {
            iterations += 1;
            let mut h = DMatrix::<f64>::zeros(6 * n, 6 * n);
            let mut b = DVector::<f64>::zeros(6 * n);
            for e in g.edges() {
                let (a, c) = (g.nodes()[e.from].pose, g.nodes()[e.to].pose);
                let err = Pose3::edge_error(&e.measurement, &a, &c);
                // Left perturbations X <- exp(d) X: d err / d d_c = J_r^-1(err) Ad(c^-1), and
                // d err / d d_a = -J_r^-1(err) Ad(c^-1) with J_r^-1(err) = J_l^-1(-err).
                let jr_inv = se3_left_jacobian(&(-err)).try_inverse().unwrap();
                let ad = slam_core::se3_adjoint(&c.inverse());
                let jc = jr_inv * ad;
                let ja = -jc;
                let w = e.kernel.map_or(1.0, |k| {
                    k.weight(Pose3::mahalanobis_squared(&err, &e.information))
                });
                let om = e.information * w;
                for (i, ji) in [(e.from, ja), (e.to, jc)] {
                    let r = (ji.transpose() * om * err).into_owned();
                    b.rows_mut(6 * i, 6).axpy(1.0, &r, 1.0);
                    for (k, jk) in [(e.from, ja), (e.to, jc)] {
                        let blk = ji.transpose() * om * jk;
                        let mut v = h.view_mut((6 * i, 6 * k), (6, 6));
                        v += blk;
                    }
                }
            }
            for (i, node) in g.nodes().iter().enumerate() {
                if node.fixed {
                    for k in 0..6 * n {
                        for j in 6 * i..6 * i + 6 {
                            h[(j, k)] = 0.0;
                            h[(k, j)] = 0.0;
                        }
                    }
                    for j in 6 * i..6 * i + 6 {
                        h[(j, j)] = 1.0;
                        b[j] = 0.0;
                    }
                }
            }
            let dx = h
                .cholesky()
                .ok_or(OptimizeError::Factorization {
                    stage: "dense Cholesky",
                    cause: FactorizationFailure::NotPositiveDefinite,
                })?
                .solve(&(-b));
            for i in 0..n {
                let d = Vector6::from_iterator(dx.rows(6 * i, 6).iter().copied());
                let p = g.nodes()[i].pose;
                g.set_pose(i, se3_exp(&d) * p);
            }
            if dx.norm() < 1e-8 {
                break;
            }
        }
        Ok(OptimizationReport {
            iterations,
            initial_cost: initial,
            final_cost: g.cost(),
            stop_reason: StopReason::StepConverged,
        })
    }
}

/// `inner` behind a check of what an incremental optimiser needs of its caller: at each call
/// the graph is the graph of the last call grown (every node's id and fixed flag and every
/// edge, measurement and information included, as they were; nodes and edges only appended).
pub(super) struct GrowthCheck<O> {
    pub(super) inner: O,
    /// The graph as the last call left it.
    last: Option<PoseGraph<Pose3>>,
    /// Calls so far.
    pub(super) calls: usize,
}

impl<O> GrowthCheck<O> {
    pub(super) fn new(inner: O) -> Self {
        Self {
            inner,
            last: None,
            calls: 0,
        }
    }
}

impl<O: Optimizer<Pose3>> Optimizer<Pose3> for GrowthCheck<O> {
    fn optimize(&mut self, g: &mut PoseGraph<Pose3>) -> Result<OptimizationReport, OptimizeError> {
        if let Some(last) = &self.last {
            assert!(g.node_count() >= last.node_count() && g.edge_count() >= last.edge_count());
            for (now, before) in g.nodes().iter().zip(last.nodes()) {
                assert_eq!(
                    (now.id, now.fixed),
                    (before.id, before.fixed),
                    "call {}",
                    self.calls
                );
            }
            for (k, (now, before)) in g.edges().iter().zip(last.edges()).enumerate() {
                assert_eq!(now, before, "edge {k} changed before call {}", self.calls);
            }
        }
        self.calls += 1;
        let report = self.inner.optimize(g);
        self.last = Some(g.clone());
        report
    }
}
