//! Tracking and the local map: a map slid in place, odometry jumps, gyro predictions, and a
//! backend that cannot build the map.

use super::backends::{BruteIcp, DenseGaussNewton, Prepared};
use super::{brute_engine, feed, hall, loop_poses, no_loop_config, scan};
use nalgebra::Point3;
use slam_core::tracking::FallbackReason;
use slam_core::{
    Alignment, GraphSlam, GraphSlamConfig, MapRegistrator, PointCloud, Pose3, Reach,
    RegistrationError, Registrator, ScanInput, WholeMapRegistrator,
};

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
    fn fit_to_scan(&mut self, _points: usize) {}
    fn map_voxel(&self) -> Option<f32> {
        None
    }
    fn keyframe_source(&self, source: Prepared) -> Prepared {
        source
    }
    fn source_voxel(&self) -> Option<f32> {
        None
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
    fn ready_map_beside(&self, _map: &mut InPlaceMap, beside: &mut (dyn FnMut() + Send)) {
        beside();
    }
    fn ready_map_ahead(&self, _map: &mut InPlaceMap) {}
    fn stored_source(&self, _source: &Prepared) -> Option<Vec<u8>> {
        None
    }
    fn restored_source(&self, _bytes: &[u8]) -> Option<Prepared> {
        None
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

impl WholeMapRegistrator for NoMapIcp {
    fn whole_map(&self, _parts: &[(&Prepared, Pose3)]) -> Result<Prepared, RegistrationError> {
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
