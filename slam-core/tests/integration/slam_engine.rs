//! The Graph-SLAM engine on a synthetic building with drifting odometry, driven by small
//! test-only backends (brute-force point-to-point ICP and dense Gauss-Newton), so the engine's own
//! logic (prediction, keyframes, local map, loop closure, edge frames, optimisation, outputs) is
//! checked against ground truth independently of the real backends.
#![allow(
    clippy::unwrap_used,
    clippy::panic,
    clippy::many_single_char_names,
    clippy::too_many_lines
)]

use nalgebra::{DMatrix, DVector, Matrix3, Matrix6, Point3, Vector3, Vector6};
use slam_core::io::StampedPose;
use slam_core::tracking::{FallbackReason, ReachConfig, TrackerConfig};
use slam_core::{
    Alignment, EdgeInformation, FactorizationFailure, GraphPose, GraphSlam, GraphSlamConfig,
    LoopOutcome, LoopRejection, MapRegistrator, OptimizationReport, OptimizeError, Optimizer,
    PointCloud, Pose3, PoseGraph, Reach, RegistrationError, Registrator, ScanInput, ScanOutcome,
    StopReason, pose3_from_xyz_rpy, se3_exp, se3_left_jacobian, se3_log,
};

/// Point-to-point ICP with brute-force nearest neighbours (Arun/Umeyama step).
struct BruteIcp {
    max_distance: f64,
}

struct Prepared(Vec<Point3<f64>>);

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

impl MapRegistrator for BruteIcp {
    fn target_from_sources(
        &self,
        parts: &[(&Prepared, Pose3)],
    ) -> Result<Prepared, RegistrationError> {
        let mut cloud = PointCloud::new();
        for (src, pose) in parts {
            let pts = src.0.iter().map(|p| (pose * p).cast::<f32>()).collect();
            cloud.extend_from(&PointCloud::from_points(pts)).unwrap();
        }
        Ok(Prepared(points(&cloud, 0.2)))
    }
}

/// Dense Gauss-Newton on SE(3) with numeric-free analytic Jacobians of the log-map error
/// (small graphs only).
struct DenseGaussNewton;

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

/// Points scattered at random (16 per square metre) on the walls, floor and pillars of a
/// 24 m x 12 m x 3 m hall: random, not a lattice, so that ICP cannot snap to a grid.
fn hall() -> Vec<Point3<f64>> {
    let mut pts = Vec::new();
    let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut rnd = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut patch = |f: &dyn Fn(f64, f64) -> Point3<f64>, a: f64, b: f64| {
        let n = (16.0 * a * b) as usize;
        for _ in 0..n {
            let (u, v) = (rnd() * a, rnd() * b);
            pts.push(f(u, v));
        }
    };
    patch(&|u, v| Point3::new(u, 0.0, v), 24.0, 3.0);
    patch(&|u, v| Point3::new(u, 12.0, v), 24.0, 3.0);
    patch(&|u, v| Point3::new(0.0, u, v), 12.0, 3.0);
    patch(&|u, v| Point3::new(24.0, u, v), 12.0, 3.0);
    patch(&|u, v| Point3::new(u, v, 0.0), 24.0, 12.0);
    // Pillars and boxes that break the symmetry.
    for (cx, cy, s) in [
        (6.0, 4.0, 0.6),
        (15.0, 8.5, 1.0),
        (19.0, 3.0, 0.5),
        (9.5, 9.0, 1.4),
        (12.0, 5.5, 0.4),
    ] {
        patch(&|u, v| Point3::new(cx + u, cy, v), s, 3.0);
        patch(&|u, v| Point3::new(cx + u, cy + s, v), s, 3.0);
        patch(&|u, v| Point3::new(cx, cy + u, v), s, 3.0);
        patch(&|u, v| Point3::new(cx + s, cy + u, v), s, 3.0);
    }
    pts
}

/// Ground-truth LiDAR poses around a rectangular loop (3 m .. 21 m by 2 m .. 10 m), 0.15 m apart,
/// ending back at the start.
fn loop_poses() -> Vec<Pose3> {
    let corners = [
        (3.0, 2.0),
        (21.0, 2.0),
        (21.0, 10.0),
        (3.0, 10.0),
        (3.0, 2.0),
    ];
    let mut out = Vec::new();
    for w in corners.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        let (dx, dy): (f64, f64) = (x1 - x0, y1 - y0);
        let len = dx.hypot(dy);
        let yaw = dy.atan2(dx);
        let n = (len / 0.15).round() as usize;
        for k in 0..n {
            let t = k as f64 / n as f64;
            out.push(pose3_from_xyz_rpy(
                x0 + t * dx,
                y0 + t * dy,
                1.0,
                0.0,
                0.0,
                yaw,
            ));
        }
    }
    out.push(pose3_from_xyz_rpy(3.0, 2.0, 1.0, 0.0, 0.0, 0.0));
    out
}

fn scan(world: &[Point3<f64>], pose: &Pose3) -> PointCloud {
    let inv = pose.inverse();
    PointCloud::from_points(
        world
            .iter()
            .filter(|p| (p.coords - pose.translation.vector).norm() < 9.0)
            .map(|p| (inv * p).cast::<f32>())
            .collect(),
    )
}

/// The odometry of `truth` with a 3 % scale error and a yaw drift of 1 degree per 10 m.
fn drifting_odometry(truth: &[Pose3]) -> Vec<Pose3> {
    let mut odom = vec![truth[0]];
    for w in truth.windows(2) {
        let d = w[0].inverse() * w[1];
        let dist = d.translation.vector.norm();
        let noisy = Pose3::from_parts((d.translation.vector * 1.03).into(), d.rotation)
            * pose3_from_xyz_rpy(0.0, 0.0, 0.0, 0.0, 0.0, (0.1f64).to_radians() * dist);
        odom.push(odom.last().unwrap() * noisy);
    }
    odom
}

/// Feeds scan `k` (0.2 s apart) of `world` seen from `truth`, with the odometry `odom`.
fn feed<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    slam: &mut GraphSlam<R, C, O>,
    world: &[Point3<f64>],
    k: usize,
    truth: &Pose3,
    odom: Pose3,
) -> ScanOutcome {
    let cloud = scan(world, truth);
    slam.process(&ScanInput {
        stamp: k as f64 * 0.2,
        odom_t_body: Some(odom),
        body_t_lidar: Pose3::identity(),
        cloud: &cloud,
        gyro_orientation: None,
    })
}

/// Settings for the loop with the test ICP.
fn loop_config() -> GraphSlamConfig {
    GraphSlamConfig {
        keyframe_distance: 0.45,
        local_map_keyframes: 10,
        loop_neighbours: 5,
        loop_search_radius: 1.0,
        loop_max_mean_squared_error: 0.02,
        min_scan_points: 50,
        // The test-only registrator reports no real information (identity), so loop edges take
        // fixed sigmas here rather than the default registration information.
        loop_information: EdgeInformation::Fixed {
            translation_sigma: 0.02,
            rotation_sigma: 0.3f64.to_radians(),
        },
        ..GraphSlamConfig::default()
    }
}

#[test]
fn loop_closure_removes_odometry_drift() {
    let world = hall();
    let truth = loop_poses();
    let odom = drifting_odometry(&truth);
    let mut slam = GraphSlam::try_new(
        loop_config(),
        BruteIcp { max_distance: 0.5 },
        BruteIcp { max_distance: 1.0 },
        BruteIcp { max_distance: 0.5 },
        DenseGaussNewton,
    )
    .unwrap();
    let body_t_lidar = Pose3::identity();
    let mut keyframes = 0;
    for (k, (gt, od)) in truth.iter().zip(&odom).enumerate() {
        let cloud = scan(&world, gt);
        let outcome = slam.process(&ScanInput {
            stamp: k as f64 * 0.2,
            odom_t_body: Some(*od),
            body_t_lidar,
            cloud: &cloud,
            gyro_orientation: None,
        });
        if matches!(outcome, ScanOutcome::Keyframe { .. }) {
            keyframes += 1;
        }
    }
    // Bad input is skipped and counted, never fatal.
    let empty = PointCloud::new();
    let last = *odom.last().unwrap();
    let far = last * Pose3::translation(1.0, 0.0, 0.0);
    assert_eq!(
        slam.process(&ScanInput {
            stamp: 0.0,
            odom_t_body: Some(far),
            body_t_lidar,
            cloud: &empty,
            gyro_orientation: None,
        }),
        ScanOutcome::Skipped(slam_core::SkipReason::OutOfOrderStamp)
    );
    let nan = Pose3::translation(f64::NAN, 0.0, 0.0);
    assert!(matches!(
        slam.process(&ScanInput {
            stamp: 1e6,
            odom_t_body: Some(nan),
            body_t_lidar,
            cloud: &empty,
            gyro_orientation: None,
        }),
        ScanOutcome::Skipped(_)
    ));
    assert!(matches!(
        slam.process(&ScanInput {
            stamp: 1e6 + 1.0,
            odom_t_body: Some(far),
            body_t_lidar,
            cloud: &empty,
            gyro_orientation: None,
        }),
        ScanOutcome::Skipped(_)
    ));

    let report = slam.report();
    assert!(keyframes > 80, "{keyframes} keyframes");
    eprintln!(
        "loops {} of {}, fallbacks {}",
        report.loops_closed,
        report.loops_attempted,
        report.fallbacks()
    );
    assert!(report.loops_closed >= 1, "{report:?}");
    // The map frame is the odometry frame at the first scan, which is the ground truth's here.
    let traj = slam.scan_trajectory();
    let err_end = (traj.last().unwrap().pose.translation.vector
        - truth.last().unwrap().translation.vector)
        .norm();
    let odom_end =
        (odom.last().unwrap().translation.vector - truth.last().unwrap().translation.vector).norm();
    let max_err = traj
        .iter()
        .zip(&truth)
        .map(|(s, g)| (s.pose.translation.vector - g.translation.vector).norm())
        .fold(0.0, f64::max);
    for q in [0.25, 0.5, 0.75, 0.9, 0.95, 1.0] {
        let k = ((traj.len() - 1) as f64 * q) as usize;
        let StampedPose { stamp, pose: p } = traj[k];
        let i = (stamp / 0.2).round() as usize;
        eprintln!(
            "at {q}: slam {:.3} m, odometry {:.3} m",
            (p.translation.vector - truth[i].translation.vector).norm(),
            (odom[i].translation.vector - truth[i].translation.vector).norm()
        );
    }
    assert!(
        odom_end > 0.5,
        "the odometry must drift for the test to mean anything: {odom_end}"
    );
    assert!(
        err_end < 0.05,
        "end error {err_end} m (odometry alone: {odom_end} m)"
    );
    // The test ICP is crude (point-to-point on 0.4 m voxels), so the odometry between loop closures
    // drifts; the bound checks that the optimisation spreads the correction along the loop.
    assert!(max_err < 0.4, "largest position error {max_err} m");
    let rms = |v: Vec<f64>| (v.iter().map(|e| e * e).sum::<f64>() / v.len() as f64).sqrt();
    let slam_rms = rms(traj
        .iter()
        .map(|s| {
            let truth = truth[(s.stamp / 0.2).round() as usize];
            (s.pose.translation.vector - truth.translation.vector).norm()
        })
        .collect());
    let odom_rms = rms(odom
        .iter()
        .zip(&truth)
        .map(|(o, g)| (o.translation.vector - g.translation.vector).norm())
        .collect());
    assert!(
        slam_rms < 0.5 * odom_rms,
        "RMS error {slam_rms} m against odometry's {odom_rms} m"
    );
    let map = slam.map(0.1).unwrap();
    assert!(map.len() > 1000);
    // Every map point lies near the hall's true geometry.
    let near = map
        .points()
        .iter()
        .filter(|p| {
            let p = p.cast::<f64>();
            world.iter().any(|w| (w - p).norm() < 0.3)
        })
        .count();
    assert!(
        near as f64 > 0.98 * map.len() as f64,
        "{near} of {}",
        map.len()
    );
}

/// `BruteIcp` whose local map is edited in place: it keeps the parts by key and rebuilds the
/// union after each change exactly as `target_from_sources` would from the window's parts.
struct InPlaceIcp(BruteIcp);

struct InPlaceMap {
    parts: std::collections::BTreeMap<u32, (Vec<Point3<f64>>, Pose3)>,
    union: Prepared,
}

impl InPlaceMap {
    fn refresh(&mut self, r: &BruteIcp) {
        let owned: Vec<(Prepared, Pose3)> = self
            .parts
            .values()
            .map(|(p, pose)| (Prepared(p.clone()), *pose))
            .collect();
        let refs: Vec<(&Prepared, Pose3)> = owned.iter().map(|(p, pose)| (p, *pose)).collect();
        self.union = if refs.is_empty() {
            Prepared(Vec::new())
        } else {
            r.target_from_sources(&refs).unwrap()
        };
    }
}

impl Registrator for InPlaceIcp {
    type Source = Prepared;
    type Target = InPlaceMap;
    fn prepare_source(&self, cloud: &PointCloud) -> Result<Prepared, RegistrationError> {
        self.0.prepare_source(cloud)
    }
    fn prepare_target(&self, cloud: &PointCloud) -> Result<InPlaceMap, RegistrationError> {
        Ok(InPlaceMap {
            parts: std::collections::BTreeMap::new(),
            union: self.0.prepare_target(cloud)?,
        })
    }
    fn align(
        &self,
        s: &Prepared,
        t: &InPlaceMap,
        initial: &Pose3,
    ) -> Result<Alignment, RegistrationError> {
        self.0.align(s, &t.union, initial)
    }
    fn align_within(
        &self,
        s: &Prepared,
        t: &InPlaceMap,
        initial: &Pose3,
        reach: &Reach,
    ) -> Result<Alignment, RegistrationError> {
        self.0.align_within(s, &t.union, initial, reach)
    }
}

impl MapRegistrator for InPlaceIcp {
    fn target_from_sources(
        &self,
        parts: &[(&Prepared, Pose3)],
    ) -> Result<InPlaceMap, RegistrationError> {
        Ok(InPlaceMap {
            parts: std::collections::BTreeMap::new(),
            union: self.0.target_from_sources(parts)?,
        })
    }
    fn empty_map(&self) -> Option<InPlaceMap> {
        Some(InPlaceMap {
            parts: std::collections::BTreeMap::new(),
            union: Prepared(Vec::new()),
        })
    }
    fn add_to_map(&self, map: &mut InPlaceMap, key: u32, source: &Prepared, pose: &Pose3) {
        map.parts.insert(key, (source.0.clone(), *pose));
        map.refresh(&self.0);
    }
    fn remove_from_map(&self, map: &mut InPlaceMap, key: u32) {
        assert!(
            map.parts.remove(&key).is_some(),
            "removed {key}, never added"
        );
        map.refresh(&self.0);
    }
}

/// A local map slid in place (one keyframe in, the oldest out) must hold exactly the window a
/// rebuild would: same trajectory, bit for bit, as the engine that rebuilds it whole.
#[test]
fn local_map_slid_in_place_equals_rebuilt() {
    let world = hall();
    let truth = loop_poses();
    let config = GraphSlamConfig {
        keyframe_distance: 0.45,
        local_map_keyframes: 6,
        min_scan_points: 50,
        // No loop closure: the window slides through the whole run.
        loop_search_radius: 1e-6,
        ..GraphSlamConfig::default()
    };
    let mut rebuilt = GraphSlam::try_new(
        config.clone(),
        BruteIcp { max_distance: 0.5 },
        BruteIcp { max_distance: 1.0 },
        BruteIcp { max_distance: 0.5 },
        DenseGaussNewton,
    )
    .unwrap();
    let mut in_place = GraphSlam::try_new(
        config,
        InPlaceIcp(BruteIcp { max_distance: 0.5 }),
        BruteIcp { max_distance: 1.0 },
        InPlaceIcp(BruteIcp { max_distance: 0.5 }),
        DenseGaussNewton,
    )
    .unwrap();
    // The first third of the loop, odometry 3 % long.
    let n = truth.len() / 3;
    let mut odom = truth[0];
    for k in 0..n {
        if k > 0 {
            let d = truth[k - 1].inverse() * truth[k];
            odom *= Pose3::from_parts((d.translation.vector * 1.03).into(), d.rotation);
        }
        let cloud = scan(&world, &truth[k]);
        let input = ScanInput {
            stamp: k as f64 * 0.2,
            odom_t_body: Some(odom),
            body_t_lidar: Pose3::identity(),
            cloud: &cloud,
            gyro_orientation: None,
        };
        assert_eq!(
            rebuilt.process(&input),
            in_place.process(&input),
            "scan {k}"
        );
    }
    assert!(in_place.keyframe_count() > 12, "the window slid");
    assert_eq!(rebuilt.report().fallbacks(), 0);
    assert_eq!(rebuilt.scan_trajectory(), in_place.scan_trajectory());
}

/// The engine with the test backends.
fn brute_engine(
    config: GraphSlamConfig,
) -> Result<GraphSlam<BruteIcp, BruteIcp, DenseGaussNewton>, slam_core::InvalidSetting> {
    GraphSlam::try_new(
        config,
        BruteIcp { max_distance: 0.5 },
        BruteIcp { max_distance: 1.0 },
        BruteIcp { max_distance: 0.5 },
        DenseGaussNewton,
    )
}

/// Settings for runs without loop closure (the test ICP on the hall).
fn no_loop_config() -> GraphSlamConfig {
    GraphSlamConfig {
        keyframe_distance: 0.45,
        local_map_keyframes: 10,
        min_scan_points: 50,
        loop_search_radius: 1e-6,
        ..GraphSlamConfig::default()
    }
}

/// The first half of the loop with exact odometry except for a `jump` (metres along x, in the
/// odometry frame) from scan `at` on, through `config`: the end error of the scan trajectory
/// against the truth and the report.
fn lap_with_odometry_jump(
    config: GraphSlamConfig,
    jump: f64,
    at: usize,
) -> (f64, slam_core::SlamReport) {
    let world = hall();
    let truth = loop_poses();
    let n = truth.len() / 2;
    let mut slam = brute_engine(config).unwrap();
    for (k, gt) in truth.iter().take(n).enumerate() {
        let odom = if k >= at {
            Pose3::translation(jump, 0.0, 0.0) * gt
        } else {
            *gt
        };
        feed(&mut slam, &world, k, gt, odom);
    }
    let end = slam.current_lidar_pose().unwrap();
    let err = (end.translation.vector - truth[n - 1].translation.vector).norm();
    (err, slam.report().clone())
}

#[test]
fn an_odometry_jump_is_detected_and_not_trusted() {
    let config = no_loop_config();
    // Ground truth is the oracle: a 10 m jump of the odometry frame at scan 40 (the odometry
    // alone ends 10 m off; trusted, the keyframe after the jump landed there too).
    let (err, report) = lap_with_odometry_jump(config.clone(), 10.0, 40);
    assert_eq!(report.odometry_faults, 1, "{report:?}");
    // Without the jump nothing is flagged; the end error is the crude test ICP's own.
    let (clean, clean_report) = lap_with_odometry_jump(config, 0.0, 40);
    eprintln!("end error {err} m with the jump, {clean} m without");
    assert_eq!(clean_report.odometry_faults, 0, "{clean_report:?}");
    assert!(clean < 0.3, "end error {clean} m");
    assert!(
        err < clean + 0.05,
        "end error {err} m with the jump detected, {clean} m without"
    );
}

#[test]
fn bad_settings_are_refused_by_name() {
    let build = |config: GraphSlamConfig| brute_engine(config).err().map(|e| (e.setting, e.value));
    assert_eq!(build(GraphSlamConfig::default()), None);
    let zero_sigma = GraphSlamConfig {
        loop_information: EdgeInformation::Fixed {
            translation_sigma: 0.0,
            rotation_sigma: 0.01,
        },
        ..GraphSlamConfig::default()
    };
    assert_eq!(
        build(zero_sigma),
        Some(("GraphSlamConfig::loop_information::translation_sigma", 0.0))
    );
    let tiny_sigma = GraphSlamConfig {
        odometry_information: EdgeInformation::Fixed {
            translation_sigma: 0.01,
            rotation_sigma: 1e-200,
        },
        ..GraphSlamConfig::default()
    };
    assert_eq!(
        build(tiny_sigma),
        Some((
            "GraphSlamConfig::odometry_information::rotation_sigma",
            1e-200
        ))
    );
    let nan_scale = GraphSlamConfig {
        odometry_information: EdgeInformation::FixedAndRegistration {
            translation_sigma: 0.01,
            rotation_sigma: 0.01,
            scale: f64::NAN,
        },
        ..GraphSlamConfig::default()
    };
    assert_eq!(
        build(nan_scale).map(|(setting, _)| setting),
        Some("GraphSlamConfig::odometry_information::scale")
    );
    let cases: [(GraphSlamConfig, &str); 12] = [
        (
            GraphSlamConfig {
                sweep_min_gain: f64::NAN,
                ..GraphSlamConfig::default()
            },
            "GraphSlamConfig::sweep_min_gain",
        ),
        (
            GraphSlamConfig {
                sweep_min_gain: -0.1,
                ..GraphSlamConfig::default()
            },
            "GraphSlamConfig::sweep_min_gain",
        ),
        (
            GraphSlamConfig {
                sweep_min_gain: 1.0,
                ..GraphSlamConfig::default()
            },
            "GraphSlamConfig::sweep_min_gain",
        ),
        (
            GraphSlamConfig {
                loop_max_drift_rate: f64::NAN,
                ..GraphSlamConfig::default()
            },
            "GraphSlamConfig::loop_max_drift_rate",
        ),
        (
            GraphSlamConfig {
                loop_max_drift_rate: -0.01,
                ..GraphSlamConfig::default()
            },
            "GraphSlamConfig::loop_max_drift_rate",
        ),
        (
            GraphSlamConfig {
                keyframe_distance: f64::NAN,
                ..GraphSlamConfig::default()
            },
            "GraphSlamConfig::keyframe_distance",
        ),
        (
            GraphSlamConfig {
                local_map_keyframes: 0,
                ..GraphSlamConfig::default()
            },
            "GraphSlamConfig::local_map_keyframes",
        ),
        (
            GraphSlamConfig {
                tracker: TrackerConfig {
                    arbitration_distance: 0.0,
                    ..TrackerConfig::default()
                },
                ..GraphSlamConfig::default()
            },
            "TrackerConfig::arbitration_distance",
        ),
        (
            GraphSlamConfig {
                tracker: TrackerConfig {
                    reach: ReachConfig {
                        max: f64::NAN,
                        ..ReachConfig::default()
                    },
                    ..TrackerConfig::default()
                },
                ..GraphSlamConfig::default()
            },
            "ReachConfig::max",
        ),
        (
            GraphSlamConfig {
                loop_kernel: Some(slam_core::RobustKernel::Cauchy { c: -1.0 }),
                ..GraphSlamConfig::default()
            },
            "GraphSlamConfig::loop_kernel",
        ),
        (
            GraphSlamConfig {
                loop_information: EdgeInformation::FromRegistration { scale: 0.0 },
                ..GraphSlamConfig::default()
            },
            "GraphSlamConfig::loop_information::scale",
        ),
        (
            GraphSlamConfig {
                map_voxel_size: -0.05,
                ..GraphSlamConfig::default()
            },
            "GraphSlamConfig::map_voxel_size",
        ),
    ];
    for (config, setting) in cases {
        assert_eq!(build(config).map(|(s, _)| s), Some(setting));
    }
}

#[test]
fn an_overflowing_keyframe_pose_is_reported_as_such() {
    let world = hall();
    let truth = loop_poses();
    let config = no_loop_config();
    let mut slam = brute_engine(config).unwrap();
    for (k, gt) in truth.iter().take(6).enumerate() {
        feed(&mut slam, &world, k, gt, *gt);
    }
    // Points 500 m away match nothing, so no registration can stand in for the odometry.
    let far: PointCloud = PointCloud::from_points(
        (0..100)
            .map(|i| Point3::new(500.0 + 0.1 * i as f32, 0.0, 0.0))
            .collect(),
    );
    let input = |k: usize, odom: Pose3| ScanInput {
        stamp: k as f64 * 0.2,
        odom_t_body: Some(odom),
        body_t_lidar: Pose3::identity(),
        cloud: &far,
        gyro_orientation: None,
    };
    // Finite odometry: a keyframe at about 1.8e308 m (kept, unregistered)...
    assert!(matches!(
        slam.process(&input(6, Pose3::translation(f64::MAX, 0.0, 0.0))),
        ScanOutcome::Keyframe {
            registered: false,
            ..
        }
    ));
    // ... then a step from it that overflows to infinity.
    assert_eq!(
        slam.process(&input(7, Pose3::translation(-f64::MAX, 0.0, 0.0))),
        ScanOutcome::Skipped(slam_core::SkipReason::NonFinitePose)
    );
    let report = slam.report();
    assert_eq!(report.skipped_non_finite_pose, 1, "{report:?}");
    assert_eq!(report.skipped_non_finite_odometry, 0, "{report:?}");
    // The graph is untouched by the refusal: one node per keyframe, a chain of edges.
    assert_eq!(slam.graph().node_count(), slam.keyframe_count());
    assert_eq!(slam.graph().edge_count(), slam.keyframe_count() - 1);
}

/// A gyro orientation that is not finite (a corrupt IMU message) is ignored: the run is the
/// one without a gyro, bit for bit, and no scan counts as gyro-predicted; a finite one predicts
/// every LiDAR-only scan after the first.
#[test]
fn a_non_finite_gyro_is_ignored_and_a_finite_one_predicts_each_turn() {
    let world = hall();
    let truth = loop_poses();
    let n = 12;
    let run = |gyro: &dyn Fn(usize) -> Option<nalgebra::UnitQuaternion<f64>>| {
        let mut slam = brute_engine(no_loop_config()).unwrap();
        for (k, pose) in truth.iter().take(n).enumerate() {
            let cloud = scan(&world, pose);
            slam.process(&ScanInput {
                stamp: k as f64 * 0.2,
                odom_t_body: None,
                body_t_lidar: Pose3::identity(),
                cloud: &cloud,
                gyro_orientation: gyro(k),
            });
        }
        (slam.scan_trajectory(), slam.report().gyro_predictions)
    };
    let (plain, none) = run(&|_| None);
    let nan =
        nalgebra::UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(f64::NAN, 0.0, 0.0, 0.0));
    let (corrupt, counted) = run(&|_| Some(nan));
    assert_eq!(none, 0);
    assert_eq!(counted, 0);
    assert_eq!(plain, corrupt);
    let (_, predicted) = run(&|k| Some(truth[0].rotation.inverse() * truth[k].rotation));
    assert_eq!(predicted, n - 1);
}

/// The drifting loop through `config` with the caller running the loop-closure steps (as a
/// scheduler would): every step's outcome that had a candidate, and the report.
fn loop_steps(config: &GraphSlamConfig) -> (Vec<LoopOutcome>, slam_core::SlamReport) {
    let world = hall();
    let truth = loop_poses();
    let odom = drifting_odometry(&truth);
    let mut slam = brute_engine(GraphSlamConfig {
        inline_loop_closure: false,
        ..config.clone()
    })
    .unwrap();
    let mut outcomes = Vec::new();
    for (k, (gt, od)) in truth.iter().zip(&odom).enumerate() {
        feed(&mut slam, &world, k, gt, *od);
        loop {
            match slam.loop_closure_step() {
                LoopOutcome::Idle => break,
                other => outcomes.push(other),
            }
        }
    }
    (outcomes, slam.report().clone())
}

#[test]
fn every_rejected_loop_is_counted_by_its_reason() {
    let counted = |outcomes: &[LoopOutcome], reason: LoopRejection| {
        outcomes
            .iter()
            .filter(|o| matches!(o, LoopOutcome::Rejected { reason: r, .. } if *r == reason))
            .count()
    };
    // An acceptance threshold nothing meets: every candidate that converges is a mismatch.
    let (outcomes, report) = loop_steps(&GraphSlamConfig {
        loop_max_mean_squared_error: 1e-12,
        ..loop_config()
    });
    eprintln!("{:?}", report.loop_rejections.nonzero());
    assert_eq!(report.loops_closed, 0);
    assert!(!outcomes.is_empty());
    assert_eq!(report.loops_attempted, outcomes.len());
    assert_eq!(report.loops_attempted, report.loop_rejections.total());
    for reason in LoopRejection::ALL {
        assert_eq!(
            counted(&outcomes, reason),
            report.loop_rejections.get(reason),
            "{reason:?}"
        );
    }
    assert_eq!(
        counted(&outcomes, LoopRejection::CoarseMismatch)
            + counted(&outcomes, LoopRejection::CoarseNotConverged),
        outcomes.len(),
        "{:?}",
        report.loop_rejections.nonzero()
    );
    assert!(report.loop_rejections.get(LoopRejection::CoarseMismatch) >= 1);
}

/// `BruteIcp` whose local map can never be built.
struct NoMapIcp(BruteIcp);

impl Registrator for NoMapIcp {
    type Source = Prepared;
    type Target = Prepared;
    fn prepare_source(&self, cloud: &PointCloud) -> Result<Prepared, RegistrationError> {
        self.0.prepare_source(cloud)
    }
    fn prepare_target(&self, cloud: &PointCloud) -> Result<Prepared, RegistrationError> {
        self.0.prepare_target(cloud)
    }
    fn align(
        &self,
        s: &Prepared,
        t: &Prepared,
        initial: &Pose3,
    ) -> Result<Alignment, RegistrationError> {
        self.0.align(s, t, initial)
    }
    fn align_within(
        &self,
        s: &Prepared,
        t: &Prepared,
        initial: &Pose3,
        reach: &Reach,
    ) -> Result<Alignment, RegistrationError> {
        self.0.align_within(s, t, initial, reach)
    }
}

impl MapRegistrator for NoMapIcp {
    fn target_from_sources(
        &self,
        _parts: &[(&Prepared, Pose3)],
    ) -> Result<Prepared, RegistrationError> {
        Err(RegistrationError::TooFewPoints {
            what: "target",
            points: 0,
            required: 1,
        })
    }
}

#[test]
fn a_local_map_the_backend_cannot_build_is_counted_and_each_scan_falls_back() {
    let world = hall();
    let truth = loop_poses();
    let mut slam = GraphSlam::try_new(
        no_loop_config(),
        NoMapIcp(BruteIcp { max_distance: 0.5 }),
        BruteIcp { max_distance: 1.0 },
        NoMapIcp(BruteIcp { max_distance: 0.5 }),
        DenseGaussNewton,
    )
    .unwrap();
    for (k, gt) in truth.iter().take(20).enumerate() {
        feed(&mut slam, &world, k, gt, *gt);
    }
    let report = slam.report();
    let no_target = report.tracking.fallbacks.get(FallbackReason::NoTarget);
    assert!(report.keyframes > 2, "{report:?}");
    // Every keyframe after the first asked for the map, and each refusal was counted.
    assert_eq!(report.local_map_failures, report.keyframes - 1);
    assert_eq!(no_target, report.local_map_failures);
}
