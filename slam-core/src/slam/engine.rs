//! `GraphSlam`: keyframes, LiDAR odometry against a local map, loop closure and map assembly.

use std::time::Instant;

use nalgebra::{Matrix6, UnitQuaternion, Vector6};

use super::config::{EdgeInformation, GraphSlamConfig};
use super::deskew::deskew;
use super::information::{combined_information, fixed_information};
use super::node_index::NodeIndex;
use super::report::{LoopOutcome, ScanOutcome, SkipReason, SlamReport};
use crate::cloud::PointCloud;
use crate::error::{CloudError, InvalidSlamConfig, OptimizeError};
use crate::geometry::{Pose3, pose3_is_finite, se3_adjoint, se3_exp, se3_log};
use crate::io::StampedPose;
use crate::pose_graph::{GraphPose, PoseGraph};
use crate::tracking::{Tracker, scan_extent};
use crate::traits::optimizer::Optimizer;
use crate::traits::place_recognizer::{PlaceMatch, PlaceRecognizer};
use crate::traits::registrator::MapRegistrator;

/// One LiDAR scan with the robot's odometry at the same instant (the `spot-adapter` sample).
#[derive(Clone, Copy, Debug)]
pub struct ScanInput<'a> {
    /// Seconds; must increase from scan to scan.
    pub stamp: f64,
    /// The robot's odometry: body pose in its odometry frame; `None` without odometry
    /// (LiDAR-only): the engine then registers every scan against its local map from a
    /// constant-velocity extrapolation of the last two.
    pub odom_t_body: Option<Pose3>,
    /// The LiDAR's mounting: LiDAR pose in the body frame.
    pub body_t_lidar: Pose3,
    /// Points in the LiDAR frame.
    pub cloud: &'a PointCloud,
    /// The body's orientation at `stamp` integrated from a gyro (`start_R_body`, drifting
    /// slowly), when the source has one. Without odometry, the rotation between two scans that
    /// both have one predicts the next scan's orientation instead of the constant velocity of
    /// the last two: a hand-held sensor turns faster and less evenly than any extrapolation.
    pub gyro_orientation: Option<UnitQuaternion<f64>>,
}

/// A keyframe: a node of the graph with what the engine keeps of its scan.
struct Keyframe<S, C> {
    stamp: f64,
    /// The odometry at the keyframe, `None` for a LiDAR-only scan.
    odom_t_lidar: Option<Pose3>,
    /// Prepared for the odometry/refinement registrator.
    source: S,
    /// Prepared for the coarse loop registrator.
    coarse: C,
    /// Voxel-filtered scan (LiDAR frame) for the map.
    cloud: PointCloud,
    /// Distance walked from the first keyframe to this one along the estimate when it was
    /// made (metres): the drift a loop may correct grows with it.
    walked: f64,
}

/// A scan made ready for the odometry.
struct Prepared<S> {
    /// Deskewed, finite points (LiDAR frame), at the map's voxel when `thinned` is given.
    cloud: PointCloud,
    /// The scan thinned to the map's voxel before deskewing, when the backend takes it so.
    thinned: Option<PointCloud>,
    /// `cloud` thinned again to the odometry's source voxel when `thinned` is given: what the
    /// source is prepared from and the sweep's motion is found on (voxelised once, not twice).
    coarse: Option<PointCloud>,
    /// How it was deskewed, when it was.
    sweep: Option<Sweep>,
    /// Prepared for the odometry registrator.
    source: S,
    /// How far the scan reaches ([`scan_extent`]).
    extent: f64,
}

impl Sweep {
    /// The sweep of `cloud` (its time channel) deskewed with `velocity`; `None` without times.
    fn of(cloud: &PointCloud, velocity: Vector6<f64>) -> Option<Self> {
        let times = cloud.time()?;
        let (lo, hi) = times
            .iter()
            .filter(|t| t.is_finite())
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &t| {
                (a.min(t), b.max(t))
            });
        (lo <= hi).then(|| Self {
            middle: 0.5 * f64::from(lo + hi),
            velocity,
        })
    }
}

/// An accepted scan: its stamp and LiDAR pose relative to its keyframe, so that it rides on the
/// keyframe's optimised pose.
#[derive(Clone, Copy, Debug)]
struct ScanPose {
    stamp: f64,
    /// Index of the keyframe.
    keyframe: usize,
    /// The scan's LiDAR pose in the keyframe's LiDAR frame.
    keyframe_t_lidar: Pose3,
    /// How the scan was deskewed, when it was.
    sweep: Option<Sweep>,
}

/// The motion a scan was deskewed with.
#[derive(Clone, Copy, Debug)]
struct Sweep {
    /// The middle of the sweep (seconds after the stamp).
    middle: f64,
    /// The velocity (LiDAR-frame twist per second).
    velocity: Vector6<f64>,
}

/// A loop to check: an old keyframe near a new one.
#[derive(Clone, Copy, Debug)]
struct LoopCandidate {
    /// Index of the old keyframe.
    old: usize,
    /// Index of the new keyframe.
    new: usize,
    /// Where place recognition puts the new keyframe (the old keyframe's pose turned by the
    /// heading between the scans), when the candidate came from it: the start of the check
    /// instead of the new keyframe's own estimate, which may have drifted far.
    guess: Option<Pose3>,
}

/// The target the odometry registers against: the last `local_map_keyframes` keyframes placed
/// at their poses (keyed by their index).
struct LocalMap<T> {
    target: T,
    /// Whether the backend updates it in place ([`MapRegistrator::empty_map`]); otherwise it is
    /// rebuilt whole after every keyframe.
    in_place: bool,
}

/// Graph-SLAM over any [`MapRegistrator`] (odometry and loop refinement), a second one for coarse
/// loop checks (the thesis uses point-to-point ICP), and any [`Optimizer`].
///
/// Loop closure runs as a bounded step: each call of [`GraphSlam::loop_closure_step`] tries at
/// most one queued candidate, optimises at most once and then rebuilds the local map. With
/// [`GraphSlamConfig::inline_loop_closure`] (the default) [`GraphSlam::process`] calls it after
/// each new keyframe; otherwise the caller schedules it (between scans, or on a timer), so that
/// odometry is never held up. Either way the result is deterministic for a given input.
pub struct GraphSlam<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>> {
    config: GraphSlamConfig,
    odometry: R,
    loop_coarse: C,
    loop_refine: R,
    optimizer: O,
    /// Registers keyframes (and, LiDAR-only, every scan) against the local map.
    tracker: Tracker,
    graph: PoseGraph<Pose3>,
    keyframes: Vec<Keyframe<R::Source, C::Source>>,
    local_map: Option<LocalMap<R::Target>>,
    node_index: NodeIndex,
    pending_loops: Vec<LoopCandidate>,
    last_loop_attempt: Option<usize>,
    /// The last keyframe that queued a look-alike from place recognition.
    last_place_attempt: Option<usize>,
    /// Every accepted scan.
    scan_poses: Vec<ScanPose>,
    last_stamp: f64,
    /// The gyro orientation of the last scan taken (its stamp and `start_R_body`).
    last_gyro: Option<(f64, UnitQuaternion<f64>)>,
    /// The RMS error of the last scan's registration by the tracker (its sweep's own must beat
    /// it, [`GraphSlamConfig::sweep_min_gain`]).
    last_fit: Option<f64>,
    /// Stamp and `odom_T_lidar` of the last accepted scan: the velocity for deskewing.
    last_odometry: Option<StampedPose>,
    /// Place recognition over keyframe scans, when set: loops sought by appearance too.
    places: Option<Box<dyn PlaceRecognizer + Send>>,
    report: SlamReport,
}

impl<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>> GraphSlam<R, C, O> {
    /// An engine with its backends: `odometry` registers scans against the local map,
    /// `loop_coarse` checks loop candidates, `loop_refine` refines accepted loops (the same
    /// backend as odometry with a looser outlier threshold, thesis: 0.10 m).
    ///
    /// # Errors
    /// [`InvalidSlamConfig`] naming the first bad setting of `config`
    /// ([`GraphSlamConfig::validate`]).
    pub fn try_new(
        config: GraphSlamConfig,
        odometry: R,
        loop_coarse: C,
        loop_refine: R,
        optimizer: O,
    ) -> Result<Self, InvalidSlamConfig> {
        config.validate()?;
        Ok(Self {
            tracker: Tracker::new(config.tracker)?,
            config,
            odometry,
            loop_coarse,
            loop_refine,
            optimizer,
            graph: PoseGraph::new(),
            keyframes: Vec::new(),
            local_map: None,
            node_index: NodeIndex::default(),
            pending_loops: Vec::new(),
            last_loop_attempt: None,
            last_place_attempt: None,
            scan_poses: Vec::new(),
            last_stamp: f64::NEG_INFINITY,
            last_gyro: None,
            last_fit: None,
            last_odometry: None,
            places: None,
            report: SlamReport::default(),
        })
    }

    /// The engine seeking loops by appearance too: each keyframe's scan goes to `places`, and a
    /// keyframe with no old keyframe within [`GraphSlamConfig::loop_search_radius`] of its
    /// estimate asks `places` for one that looks alike, however far the estimate has drifted.
    /// The candidate is checked as any other (coarse and refined registration, from the old
    /// keyframe's pose turned by the heading the recognizer gives).
    #[must_use]
    pub fn with_place_recognizer(mut self, places: Box<dyn PlaceRecognizer + Send>) -> Self {
        self.places = Some(places);
        self
    }

    /// The settings.
    #[must_use]
    pub fn config(&self) -> &GraphSlamConfig {
        &self.config
    }

    /// The pose graph (keyframe `i` is node id `i`).
    #[must_use]
    pub fn graph(&self) -> &PoseGraph<Pose3> {
        &self.graph
    }

    /// The optimiser, e.g. for the weight it left each loop edge with
    /// ([`Optimizer::edge_weights`]).
    #[must_use]
    pub fn optimizer(&self) -> &O {
        &self.optimizer
    }

    /// Counts and timings so far.
    #[must_use]
    pub fn report(&self) -> &SlamReport {
        &self.report
    }

    /// The odometry's tracker: its reach and health (also in [`SlamReport::tracking`]).
    #[must_use]
    pub fn tracker(&self) -> &Tracker {
        &self.tracker
    }

    /// Number of keyframes.
    #[must_use]
    pub fn keyframe_count(&self) -> usize {
        self.keyframes.len()
    }

    fn keyframe_pose(&self, i: usize) -> Pose3 {
        self.graph.nodes()[i].pose
    }

    /// The latest LiDAR pose in the map frame (`map_T_lidar`), `None` before the first scan.
    #[must_use]
    pub fn current_lidar_pose(&self) -> Option<Pose3> {
        let s = self.scan_poses.last()?;
        Some(self.keyframe_pose(s.keyframe) * s.keyframe_t_lidar)
    }

    /// Optimised keyframe trajectory: stamp and `map_T_lidar` per keyframe.
    #[must_use]
    pub fn keyframe_trajectory(&self) -> Vec<StampedPose> {
        self.keyframes
            .iter()
            .enumerate()
            .map(|(i, k)| StampedPose {
                stamp: k.stamp,
                pose: self.keyframe_pose(i),
            })
            .collect()
    }

    /// Trajectory of every accepted scan, stamp and `map_T_lidar`: each scan rides on its
    /// keyframe, so loop closures correct it too.
    #[must_use]
    pub fn scan_trajectory(&self) -> Vec<StampedPose> {
        self.scan_poses
            .iter()
            .map(|s| StampedPose {
                stamp: s.stamp,
                pose: self.keyframe_pose(s.keyframe) * s.keyframe_t_lidar,
            })
            .collect()
    }

    /// Every keyframe's scan (voxel-filtered, in the LiDAR frame) with its optimised
    /// `map_T_lidar`: the rays an occupancy grid's free space comes from.
    pub fn keyframe_scans(&self) -> impl Iterator<Item = (Pose3, &PointCloud)> + '_ {
        self.keyframes
            .iter()
            .enumerate()
            .map(|(i, k)| (self.keyframe_pose(i), &k.cloud))
    }

    /// The map: every keyframe cloud at its optimised pose, voxel-filtered at `voxel_size`.
    ///
    /// # Errors
    /// [`CloudError::InvalidVoxelSize`] for a bad voxel size.
    pub fn map(&self, voxel_size: f32) -> Result<PointCloud, CloudError> {
        let mut all = PointCloud::new();
        for (i, k) in self.keyframes.iter().enumerate() {
            let mut c = k.cloud.transformed(&self.keyframe_pose(i));
            // Channels may differ between sensors' scans; the map keeps positions only.
            c = PointCloud::from_points(c.into_parts().0);
            all.extend_from(&c)?;
        }
        all.voxel_downsample(voxel_size)
    }

    fn record_scan_time(&mut self, started: Instant) {
        SlamReport::record(
            &mut self.report.scan_ms,
            started.elapsed().as_secs_f64() * 1e3,
        );
    }

    fn skip(&mut self, reason: SkipReason, started: Instant) -> ScanOutcome {
        match reason {
            SkipReason::OutOfOrderStamp => self.report.skipped_out_of_order += 1,
            SkipReason::NonFiniteOdometry => self.report.skipped_non_finite_odometry += 1,
            SkipReason::TooFewPoints => self.report.skipped_too_few_points += 1,
            SkipReason::PreparationFailed => self.report.skipped_preparation += 1,
            SkipReason::AwaitingVelocity => self.report.skipped_awaiting_velocity += 1,
            SkipReason::NonFinitePose => self.report.skipped_non_finite_pose += 1,
        }
        self.record_scan_time(started);
        ScanOutcome::Skipped(reason)
    }

    /// Feed one scan. Bad input (out-of-order stamps, non-finite odometry, empty or tiny scans) is
    /// skipped and counted in the report, never fatal.
    pub fn process(&mut self, scan: &ScanInput<'_>) -> ScanOutcome {
        let outcome = self.process_scan(scan);
        // The gyro pairs with the last scan whose pose was kept.
        if self.last_stamp.to_bits() == scan.stamp.to_bits() {
            self.last_gyro = scan
                .gyro_orientation
                .filter(|q| q.coords.iter().all(|v| v.is_finite()))
                .map(|q| (scan.stamp, q));
        }
        outcome
    }

    /// [`Self::process`] but for the gyro's bookkeeping.
    fn process_scan(&mut self, scan: &ScanInput<'_>) -> ScanOutcome {
        let started = Instant::now();
        self.report.scans += 1;
        if !scan.stamp.is_finite() || scan.stamp <= self.last_stamp {
            return self.skip(SkipReason::OutOfOrderStamp, started);
        }
        if scan.odom_t_body.is_some_and(|o| !pose3_is_finite(&o))
            || !pose3_is_finite(&scan.body_t_lidar)
        {
            return self.skip(SkipReason::NonFiniteOdometry, started);
        }
        let odom_t_lidar = scan.odom_t_body.map(|o| o * scan.body_t_lidar);
        // Only a sweep whose points have different times is skewed.
        let swept = self.config.deskew
            && scan.cloud.time().is_some_and(|t| {
                t.iter()
                    .any(|&x| x.to_bits() != t.first().map_or(0, |f| f.to_bits()))
            });
        // Constant velocity over the sweep, from the odometry since the previous scan.
        let odometry_velocity = if let Some(now) = odom_t_lidar {
            self.last_odometry
                .replace(StampedPose {
                    stamp: scan.stamp,
                    pose: now,
                })
                .and_then(|last| {
                    let dt = scan.stamp - last.stamp;
                    (swept && dt > 0.0 && dt <= 1.0)
                        .then(|| se3_log(&(last.pose.inverse() * now)) / dt)
                })
        } else {
            self.last_odometry = None;
            None
        };
        let Some(last) = self.keyframes.len().checked_sub(1) else {
            if swept && odom_t_lidar.is_some() && odometry_velocity.is_none() {
                self.last_stamp = scan.stamp;
                return self.skip(SkipReason::AwaitingVelocity, started);
            }
            // The first keyframe defines the map frame: the odometry frame at the first scan,
            // or without odometry the body frame there.
            let pose = odom_t_lidar.unwrap_or(scan.body_t_lidar);
            let prepared = match self.prepare(scan, odometry_velocity, started) {
                Ok(p) => p,
                Err(skipped) => return skipped,
            };
            return self.add_keyframe(scan, prepared, odom_t_lidar, pose, None, started);
        };
        match (odom_t_lidar, self.keyframes[last].odom_t_lidar) {
            (Some(now), Some(then)) => {
                self.odometry_step(scan, now, then, last, odometry_velocity, started)
            }
            _ => self.lidar_only_step(scan, odom_t_lidar, last, swept, started),
        }
    }

    /// A scan with odometry: predicted from the odometry since the last keyframe; registered
    /// only once it moved far enough for a new keyframe.
    fn odometry_step(
        &mut self,
        scan: &ScanInput<'_>,
        odom_t_lidar: Pose3,
        keyframe_odom_t_lidar: Pose3,
        last: usize,
        velocity: Option<Vector6<f64>>,
        started: Instant,
    ) -> ScanOutcome {
        let delta = keyframe_odom_t_lidar.inverse() * odom_t_lidar;
        let predicted = self.keyframe_pose(last) * delta;
        let moved = delta.translation.vector.norm() >= self.config.keyframe_distance
            || delta.rotation.angle() >= self.config.keyframe_rotation;
        if !moved {
            self.last_stamp = scan.stamp;
            self.scan_poses.push(ScanPose {
                stamp: scan.stamp,
                keyframe: last,
                keyframe_t_lidar: delta,
                sweep: None,
            });
            self.record_scan_time(started);
            return ScanOutcome::Tracked { registered: false };
        }
        let prior = self.motion_prior(scan.stamp);
        let suspect = prior.is_some_and(|(p, _)| {
            (p.inverse() * predicted).translation.vector.norm()
                > self.config.tracker.arbitration_distance
        });
        // A suspect odometry step would deskew with its jump as the velocity: take the
        // extrapolation's instead.
        let velocity = if suspect {
            velocity.and(prior.and_then(|(_, v)| v))
        } else {
            velocity
        };
        let prepared = match self.prepare(scan, velocity, started) {
            Ok(p) => p,
            Err(skipped) => return skipped,
        };
        // The extrapolation arbitrates only a suspect odometry step, so that clean input runs
        // exactly as without the check.
        let mut guesses = vec![predicted];
        guesses.extend(prior.filter(|_| suspect).map(|(guess, _)| guess));
        let (pose, reg_info) = self.register(&prepared, &guesses);
        self.add_keyframe(
            scan,
            prepared,
            Some(odom_t_lidar),
            pose,
            reg_info.as_ref(),
            started,
        )
    }

    /// A scan without odometry: registered against the local map from the constant-velocity
    /// extrapolation, deskewed with that velocity; a keyframe once it moved far enough.
    fn lidar_only_step(
        &mut self,
        scan: &ScanInput<'_>,
        odom_t_lidar: Option<Pose3>,
        last: usize,
        swept: bool,
        started: Instant,
    ) -> ScanOutcome {
        let (predicted, velocity) = self
            .motion_prior(scan.stamp)
            .unwrap_or_else(|| (self.keyframe_pose(last), None));
        let (predicted, velocity) = self.gyro_prior(scan, predicted, velocity);
        let prepared = match self.prepare(scan, velocity.filter(|_| swept), started) {
            Ok(p) => p,
            Err(skipped) => return skipped,
        };
        // A swept scan is registered with its own motion, then deskewed anew with it for the
        // map: at 2 Hz a hand's shake is faster than the scans, and the velocity between two
        // scans says little about the 0.1 s of one sweep.
        let (mut pose, mut reg_info) = self.register(&prepared, &[predicted]);
        let mut prepared = prepared;
        if swept
            && self.config.sweep_motion
            && reg_info.is_some()
            && let Some((at, information, correction)) = self.sweep_motion(&prepared, &pose)
        {
            // The second scan has no velocity yet: its sweep's own motion is all there is.
            let v = velocity.unwrap_or_else(Vector6::zeros);
            prepared = self.redeskew(scan, prepared, v + correction);
            pose = at;
            reg_info = Some(information);
        }
        let mut delta = self.keyframe_pose(last).inverse() * pose;
        delta.rotation.renormalize();
        let moved = delta.translation.vector.norm() >= self.config.keyframe_distance
            || delta.rotation.angle() >= self.config.keyframe_rotation;
        if moved || !pose3_is_finite(&delta) {
            return self.add_keyframe(
                scan,
                prepared,
                odom_t_lidar,
                pose,
                reg_info.as_ref(),
                started,
            );
        }
        self.last_stamp = scan.stamp;
        self.scan_poses.push(ScanPose {
            stamp: scan.stamp,
            keyframe: last,
            keyframe_t_lidar: delta,
            sweep: prepared.sweep,
        });
        self.record_scan_time(started);
        ScanOutcome::Tracked {
            registered: reg_info.is_some(),
        }
    }

    fn information(
        kind: EdgeInformation,
        reg_info: Option<&Matrix6<f64>>,
        pose: &Pose3,
    ) -> Matrix6<f64> {
        // Registration information is for a left perturbation of map_T_lidar; the edge error
        // perturbs the relative pose on the right: Omega' = Ad(X)^T Omega Ad(X).
        let in_edge_frame = |info: &Matrix6<f64>, scale: f64| {
            let ad = se3_adjoint(pose);
            let m = ad.transpose() * info * ad * scale;
            (m + m.transpose()) * 0.5
        };
        let fallback = || fixed_information(0.05, 1f64.to_radians());
        match (kind, reg_info) {
            (EdgeInformation::FromRegistration { scale }, Some(info)) => {
                let m = in_edge_frame(info, scale);
                if Pose3::information_is_valid(&m) {
                    m
                } else {
                    fallback()
                }
            }
            (
                EdgeInformation::Fixed {
                    translation_sigma,
                    rotation_sigma,
                },
                _,
            )
            | (
                EdgeInformation::FixedAndRegistration {
                    translation_sigma,
                    rotation_sigma,
                    ..
                },
                None,
            ) => fixed_information(translation_sigma, rotation_sigma),
            (
                EdgeInformation::FixedAndRegistration {
                    translation_sigma,
                    rotation_sigma,
                    scale,
                },
                Some(info),
            ) => {
                let fixed = fixed_information(translation_sigma, rotation_sigma);
                combined_information(&fixed, &in_edge_frame(info, scale)).unwrap_or(fixed)
            }
            (EdgeInformation::FromRegistration { .. }, None) => fallback(),
        }
    }

    /// Builds the local map if there is none (at the start, and after a loop closure moved the
    /// keyframes): in place when the backend supports it, else whole.
    fn ensure_local_map(&mut self) -> bool {
        if self.local_map.is_some() {
            return true;
        }
        let n = self.keyframes.len();
        let first = n.saturating_sub(self.config.local_map_keyframes);
        let keyed = u32::try_from(n).is_ok();
        if let (Some(mut target), true) = (self.odometry.empty_map(), keyed) {
            for i in first..n {
                let pose = self.keyframe_pose(i);
                #[allow(clippy::cast_possible_truncation)]
                self.odometry
                    .add_to_map(&mut target, i as u32, &self.keyframes[i].source, &pose);
            }
            self.local_map = Some(LocalMap {
                target,
                in_place: true,
            });
        } else {
            let parts: Vec<(&R::Source, Pose3)> = (first..n)
                .map(|i| (&self.keyframes[i].source, self.keyframe_pose(i)))
                .collect();
            self.local_map = self
                .odometry
                .target_from_sources(&parts)
                .ok()
                .map(|target| LocalMap {
                    target,
                    in_place: false,
                });
        }
        self.local_map.is_some()
    }

    /// Adds keyframe `index` (the newest) to an in-place local map and drops the one that left
    /// the window; a map built whole is dropped, to be rebuilt when next needed.
    fn slide_local_map(&mut self, index: usize) {
        let window = self.config.local_map_keyframes;
        let pose = self.keyframe_pose(index);
        match (&mut self.local_map, u32::try_from(index)) {
            (
                Some(LocalMap {
                    target,
                    in_place: true,
                }),
                Ok(key),
            ) => {
                self.odometry
                    .add_to_map(target, key, &self.keyframes[index].source, &pose);
                if let Some(old) = index.checked_sub(window) {
                    #[allow(clippy::cast_possible_truncation)]
                    self.odometry.remove_from_map(target, old as u32);
                }
            }
            _ => self.local_map = None,
        }
    }

    /// Add node `id` at `pose` with its odometry edge `(step, information)` from the previous
    /// node, or fixed as the gauge without one. Checked first with the graph's own predicates,
    /// so that a refusal leaves the graph unchanged.
    fn insert_node(
        &mut self,
        id: u64,
        pose: Pose3,
        edge: Option<&(Pose3, Matrix6<f64>)>,
    ) -> Result<(), OptimizeError> {
        if !pose3_is_finite(&pose)
            || edge.is_some_and(|(step, info)| {
                !pose3_is_finite(step) || !Pose3::information_is_valid(info)
            })
        {
            return Err(OptimizeError::NonFinite {
                what: crate::error::GraphValue::NodePose { id },
            });
        }
        self.graph.add_node(id, pose)?;
        match (edge, id.checked_sub(1)) {
            (Some(&(step, info)), Some(prev)) => {
                self.graph.add_edge(prev, id, step, info, None)?;
            }
            _ => self.graph.fix(id)?,
        }
        Ok(())
    }

    /// The pose of a scan and its registration's information: registered against the local
    /// map from `guesses` (the prediction first) by the tracker; the prediction, counted as a
    /// fallback, when it cannot be (no map, or the registration is not taken). An alternative
    /// guess that wins counts as an odometry fault.
    fn register(
        &mut self,
        prepared: &Prepared<R::Source>,
        guesses: &[Pose3],
    ) -> (Pose3, Option<Matrix6<f64>>) {
        let has_map = self.ensure_local_map();
        let target = self
            .local_map
            .as_ref()
            .filter(|_| has_map)
            .map(|m| &m.target);
        let outcome = self.tracker.track(
            &self.odometry,
            &prepared.source,
            target,
            guesses,
            prepared.extent,
        );
        self.report.tracking = *self.tracker.health();
        if outcome.tracked() && outcome.guess > 0 {
            self.report.odometry_faults += 1;
        }
        // Scan poses are chained on each other without odometry: keep their quaternions unit,
        // or rounding compounds scan after scan.
        let mut pose = outcome.pose;
        pose.rotation.renormalize();
        self.last_fit = outcome.alignment.as_ref().map(|a| a.rmse);
        (pose, outcome.alignment.map(|a| a.information))
    }

    /// The scan registered again from `pose` (its registration) together with its sweep's own
    /// motion ([`Registrator::align_sweep`](crate::Registrator::align_sweep)): the pose at the
    /// sweep's start, its information, and the correction to the velocity it was deskewed with.
    /// `None` when the backend cannot, or the result is not taken (too few inliers, a non-finite
    /// pose, too small a gain over the scan's registration: `GraphSlamConfig::sweep_min_gain`).
    fn sweep_motion(
        &self,
        prepared: &Prepared<R::Source>,
        pose: &Pose3,
    ) -> Option<(Pose3, Matrix6<f64>, Vector6<f64>)> {
        let map = &self.local_map.as_ref()?.target;
        let sweep = self
            .odometry
            .align_sweep(
                prepared.coarse.as_ref().unwrap_or(&prepared.cloud),
                map,
                pose,
            )?
            .ok()?;
        let a = sweep.alignment;
        let gain = self.config.sweep_min_gain;
        let better = self
            .last_fit
            .is_none_or(|rmse| a.rmse <= rmse * (1.0 - gain));
        (pose3_is_finite(&a.pose)
            && a.inlier_ratio >= self.config.tracker.min_inlier_ratio
            && better)
            .then_some((a.pose, a.information, sweep.velocity_correction))
    }

    /// `prepared` deskewed anew with `velocity` (the one its sweep was registered with), and
    /// prepared again for the map; as it was when the correction is implausible (beyond 10 rad/s
    /// or 10 m/s) or the scan cannot be prepared.
    fn redeskew(
        &self,
        scan: &ScanInput<'_>,
        prepared: Prepared<R::Source>,
        velocity: Vector6<f64>,
    ) -> Prepared<R::Source> {
        let plausible = velocity.fixed_rows::<3>(0).norm() <= 10.0
            && velocity.fixed_rows::<3>(3).norm() <= 10.0;
        let base = prepared.thinned.as_ref().unwrap_or(scan.cloud);
        let again = plausible
            .then(|| deskew(base, &velocity))
            .flatten()
            .and_then(|mut cloud| {
                cloud.remove_non_finite();
                let coarse = self.coarse(&cloud, prepared.thinned.is_some());
                let source = self
                    .odometry
                    .prepare_source(coarse.as_ref().unwrap_or(&cloud))
                    .ok()?;
                Some((cloud, coarse, source))
            });
        match again {
            Some((cloud, coarse, source)) => Prepared {
                sweep: Sweep::of(base, velocity),
                cloud,
                coarse,
                source,
                ..prepared
            },
            None => prepared,
        }
    }

    /// `predicted` and `velocity` with their rotation taken from the gyro when this scan and the
    /// last one both have a gyro orientation: the last scan's orientation turned by the body's
    /// rotation between the two (in the LiDAR frame), the angular velocity that rotation over
    /// the time between them; translation as predicted.
    fn gyro_prior(
        &mut self,
        scan: &ScanInput<'_>,
        predicted: Pose3,
        velocity: Option<Vector6<f64>>,
    ) -> (Pose3, Option<Vector6<f64>>) {
        let (Some((then, g0)), Some(g1), Some(last)) = (
            self.last_gyro,
            scan.gyro_orientation,
            self.scan_poses.last(),
        ) else {
            return (predicted, velocity);
        };
        let dt = scan.stamp - then;
        if dt.is_nan() || dt <= 0.0 || !g1.coords.iter().all(|v| v.is_finite()) {
            return (predicted, velocity);
        }
        let mount = scan.body_t_lidar.rotation;
        let turn = mount.inverse() * g0.inverse() * g1 * mount;
        let x1 = self.keyframe_pose(last.keyframe) * last.keyframe_t_lidar;
        let mut rotation = x1.rotation * turn;
        rotation.renormalize();
        self.report.gyro_predictions += 1;
        let velocity = velocity.map(|mut v| {
            v.fixed_rows_mut::<3>(3)
                .copy_from(&(turn.scaled_axis() / dt));
            v
        });
        (Pose3::from_parts(predicted.translation, rotation), velocity)
    }

    /// The LiDAR pose at `stamp` extrapolated at constant velocity from the last two accepted
    /// scans, with that velocity (LiDAR-frame twist per second); the last scan's pose held, and
    /// no velocity, when there is only one or the scans are more than a second apart. `None`
    /// before the first scan. Read from the scans' keyframes, so a loop closure that moved them
    /// moves the extrapolation too.
    fn motion_prior(&self, stamp: f64) -> Option<(Pose3, Option<Vector6<f64>>)> {
        // Each scan's pose in the middle of its sweep: registering a deskewed sweep fixes its
        // middle whatever velocity it was deskewed with, while its start moves with that
        // velocity's error. A velocity taken from the starts would feed that error back into
        // the next deskew, and scan after scan it grows (LiDAR-only, 5 Hz, 12 cm a sweep).
        let middle = |s: &ScanPose| {
            let x = self.keyframe_pose(s.keyframe) * s.keyframe_t_lidar;
            s.sweep.map_or((s.stamp, x), |w| {
                (s.stamp + w.middle, x * se3_exp(&(w.velocity * w.middle)))
            })
        };
        let (last, earlier) = self.scan_poses.split_last()?;
        let x1 = self.keyframe_pose(last.keyframe) * last.keyframe_t_lidar;
        let (t1, m1) = middle(last);
        let velocity = earlier.last().and_then(|prev| {
            let (t0, m0) = middle(prev);
            let (dt0, dt) = (t1 - t0, stamp - t1);
            (dt0 > 0.0 && dt0 <= 1.0 && dt > 0.0 && dt <= 1.0)
                .then(|| se3_log(&(m0.inverse() * m1)) / dt0)
        });
        let pose = velocity.map_or(x1, |v| m1 * se3_exp(&(v * (stamp - t1))));
        Some((pose, velocity))
    }

    /// `cloud` (deskewed, at the map's voxel when `thinned`) at the odometry's source voxel,
    /// when the scan was thinned for it.
    fn coarse(&self, cloud: &PointCloud, thinned: bool) -> Option<PointCloud> {
        let voxel = self.odometry.source_voxel().filter(|_| thinned)?;
        cloud.voxel_downsample(voxel).ok()
    }

    /// A scan made ready: deskewed with `velocity` (when given), non-finite points dropped,
    /// prepared for the odometry; the skip outcome (counted) when too few points are left or
    /// the registrator refuses it.
    fn prepare(
        &mut self,
        scan: &ScanInput<'_>,
        velocity: Option<Vector6<f64>>,
        started: Instant,
    ) -> Result<Prepared<R::Source>, ScanOutcome> {
        // A backend that only thins the scan by voxel gets it thinned once, to the map's voxel,
        // before anything else: deskewing, registering and keeping a dense scan then cost what
        // its voxels cost, not what its points cost (an OS1-128 sweep: 131,072 points).
        let voxel = self.config.map_voxel_size;
        let (thinned, far) = match self.odometry.source_voxel().filter(|&v| v >= voxel) {
            // A garbled return beyond any voxel key is dropped and counted, not allowed to
            // fail the thinning of the whole scan.
            Some(_) => scan
                .cloud
                .voxel_downsample_keyable(voxel)
                .map_or((None, 0), |(thinned, far)| (Some(thinned), far)),
            None => (None, 0),
        };
        let base = thinned.as_ref().unwrap_or(scan.cloud);
        let deskewed = velocity.and_then(|v| deskew(base, &v).map(|c| (c, v)));
        let sweep = deskewed.as_ref().and_then(|(_, v)| Sweep::of(base, *v));
        let mut cloud = deskewed.map_or_else(|| base.clone(), |(c, _)| c);
        let dropped = match thinned {
            Some(_) => {
                far + scan
                    .cloud
                    .points()
                    .iter()
                    .filter(|p| !p.iter().all(|v| v.is_finite()))
                    .count()
            }
            None => cloud.remove_non_finite(),
        };
        if cloud.len() < self.config.min_scan_points {
            return Err(self.skip(SkipReason::TooFewPoints, started));
        }
        let coarse = self.coarse(&cloud, thinned.is_some());
        let Ok(source) = self
            .odometry
            .prepare_source(coarse.as_ref().unwrap_or(&cloud))
        else {
            return Err(self.skip(SkipReason::PreparationFailed, started));
        };
        self.report.dropped_points += dropped;
        Ok(Prepared {
            extent: scan_extent(&cloud),
            cloud,
            thinned,
            coarse,
            sweep,
            source,
        })
    }

    /// Adds `prepared` as a keyframe at `pose` (with the registration's information `reg_info`
    /// for its odometry edge), queues its loop candidate and runs a loop-closure step when
    /// inline.
    fn add_keyframe(
        &mut self,
        scan: &ScanInput<'_>,
        prepared: Prepared<R::Source>,
        odom_t_lidar: Option<Pose3>,
        pose: Pose3,
        reg_info: Option<&Matrix6<f64>>,
        started: Instant,
    ) -> ScanOutcome {
        let Prepared {
            cloud,
            thinned,
            coarse: thinned_source,
            source,
            sweep,
            ..
        } = prepared;
        // The map keeps the scan at its voxel; the loop check and place recognition read that
        // thinned scan too (a dense scan's 130,000 points voxelised once, not three times).
        let cloud = if thinned.is_some() {
            cloud
        } else {
            cloud
                .voxel_downsample(self.config.map_voxel_size)
                .unwrap_or(cloud)
        };
        // The loop check's source from the scan already thinned to its voxel when the odometry
        // thins to the same one (an OS1-128 keyframe's 41,000 points not voxelised again).
        let same_voxel = self
            .loop_coarse
            .source_voxel()
            .is_some_and(|v| Some(v) == self.odometry.source_voxel());
        let loop_cloud = thinned_source.filter(|_| same_voxel);
        let Ok(coarse) = self
            .loop_coarse
            .prepare_source(loop_cloud.as_ref().unwrap_or(&cloud))
        else {
            return self.skip(SkipReason::PreparationFailed, started);
        };
        let index = self.keyframes.len();
        let id = index as u64;
        let edge = if index == 0 {
            None
        } else {
            let step = self.keyframe_pose(index - 1).inverse() * pose;
            let info = Self::information(self.config.odometry_information, reg_info, &pose);
            Some((step, info))
        };
        if self.insert_node(id, pose, edge.as_ref()).is_err() {
            return self.skip(SkipReason::NonFinitePose, started);
        }
        // Appearance first (before this keyframe joins the recognizer); a scan the recognizer
        // refuses is counted, and the keyframe goes on without a place match.
        let look_alikes = match self
            .places
            .as_mut()
            .map(|p| p.candidates_then_add(index, &cloud))
        {
            Some(Ok(found)) => found,
            Some(Err(_)) => {
                self.report.place_refusals += 1;
                Vec::new()
            }
            None => Vec::new(),
        };
        let walked = match index {
            0 => 0.0,
            _ => {
                self.keyframes[index - 1].walked
                    + (pose.translation.vector - self.keyframe_pose(index - 1).translation.vector)
                        .norm()
            }
        };
        self.keyframes.push(Keyframe {
            walked,
            stamp: scan.stamp,
            odom_t_lidar,
            source: self.odometry.keyframe_source(source),
            coarse: self.loop_coarse.keyframe_source(coarse),
            cloud,
        });
        self.report.keyframes += 1;
        self.slide_local_map(index);
        self.last_stamp = scan.stamp;
        self.scan_poses.push(ScanPose {
            stamp: scan.stamp,
            keyframe: index,
            keyframe_t_lidar: Pose3::identity(),
            sweep,
        });

        self.queue_loop_candidate(index, &pose, &look_alikes);
        self.node_index.insert(index, &pose);
        self.record_scan_time(started);
        if self.config.inline_loop_closure {
            self.loop_closure_step();
        }
        ScanOutcome::Keyframe {
            id,
            registered: reg_info.is_some(),
        }
    }

    /// Queue a loop candidate for keyframe `index` at `pose`: the oldest keyframe near it outside
    /// the local window, or else the best look-alike place recognition found. The two kinds are
    /// throttled apart ([`GraphSlamConfig::loop_min_keyframe_gap`] each), so that look-alikes
    /// refused one after another (a corridor of identical rooms) never keep a loop by position
    /// from being tried.
    fn queue_loop_candidate(&mut self, index: usize, pose: &Pose3, look_alikes: &[PlaceMatch]) {
        let window = self.config.local_map_keyframes;
        if index <= window {
            return;
        }
        let gap = self.config.loop_min_keyframe_gap;
        let may_try = |last: Option<usize>| last.is_none_or(|l| index >= l + gap);
        let near = may_try(self.last_loop_attempt)
            .then(|| {
                self.node_index
                    .oldest_within(pose, self.config.loop_search_radius, index - window)
            })
            .flatten();
        let candidate = match near {
            Some(old) => {
                self.last_loop_attempt = Some(index);
                Some((old, None))
            }
            // Only the best look-alike: the next best of a place whose best is recent is
            // rarely the same place.
            None if may_try(self.last_place_attempt) => look_alikes
                .first()
                .filter(|m| m.keyframe < index - window)
                .map(|m| {
                    self.last_place_attempt = Some(index);
                    let turn = Pose3::from_parts(
                        nalgebra::Translation3::identity(),
                        nalgebra::UnitQuaternion::from_euler_angles(0.0, 0.0, m.yaw),
                    );
                    (m.keyframe, Some(self.keyframe_pose(m.keyframe) * turn))
                }),
            None => None,
        };
        if let Some((old, guess)) = candidate {
            self.report.place_candidates += usize::from(guess.is_some());
            self.pending_loops.push(LoopCandidate {
                old,
                new: index,
                guess,
            });
        }
    }

    /// How far (metres) a loop from keyframe `old` to `new` may move `new`: the loop search
    /// radius plus [`GraphSlamConfig::loop_max_drift_rate`] of the distance walked between them.
    fn drift_allowance(&self, old: usize, new: usize) -> f64 {
        let walked = (self.keyframes[new].walked - self.keyframes[old].walked).abs();
        self.config.loop_search_radius + self.config.loop_max_drift_rate * walked
    }

    /// Try the oldest queued loop candidate: coarse alignment of the new keyframe to the
    /// candidate's neighbourhood, acceptance on its mean squared error, refinement, a new edge and
    /// one optimisation. Bounded: at most one candidate per call.
    pub fn loop_closure_step(&mut self) -> LoopOutcome {
        if self.pending_loops.is_empty() {
            return LoopOutcome::Idle;
        }
        let started = Instant::now();
        let candidate = self.pending_loops.remove(0);
        self.report.loops_attempted += 1;
        let outcome = self.try_loop(&candidate);
        SlamReport::record(
            &mut self.report.loop_ms,
            started.elapsed().as_secs_f64() * 1e3,
        );
        outcome
    }

    fn try_loop(&mut self, candidate: &LoopCandidate) -> LoopOutcome {
        let (cand, new) = (candidate.old, candidate.new);
        let rejected = LoopOutcome::Rejected {
            from: cand as u64,
            to: new as u64,
        };
        let lo = cand.saturating_sub(self.config.loop_neighbours);
        // Keep the neighbourhood disjoint from the new keyframe's own recent window.
        let hi = (cand + self.config.loop_neighbours)
            .min(new.saturating_sub(self.config.local_map_keyframes));
        let coarse_parts: Vec<(&C::Source, Pose3)> = (lo..=hi.max(cand))
            .map(|i| (&self.keyframes[i].coarse, self.keyframe_pose(i)))
            .collect();
        let refine_parts: Vec<(&R::Source, Pose3)> = (lo..=hi.max(cand))
            .map(|i| (&self.keyframes[i].source, self.keyframe_pose(i)))
            .collect();
        let initial = candidate.guess.unwrap_or_else(|| self.keyframe_pose(new));
        let Ok(coarse_target) = self.loop_coarse.target_from_sources(&coarse_parts) else {
            return rejected;
        };
        let Ok(coarse) =
            self.loop_coarse
                .align(&self.keyframes[new].coarse, &coarse_target, &initial)
        else {
            return rejected;
        };
        let mse = coarse.rmse * coarse.rmse;
        if !coarse.converged
            || !pose3_is_finite(&coarse.pose)
            || mse > self.config.loop_max_mean_squared_error
        {
            return rejected;
        }
        let Ok(refine_target) = self.loop_refine.target_from_sources(&refine_parts) else {
            return rejected;
        };
        let Ok(refined) =
            self.loop_refine
                .align(&self.keyframes[new].source, &refine_target, &coarse.pose)
        else {
            return rejected;
        };
        let shift = (refined.pose.translation.vector - coarse.pose.translation.vector).norm();
        if !refined.converged
            || !pose3_is_finite(&refined.pose)
            || shift > self.config.loop_max_refine_shift
        {
            return rejected;
        }
        // The correction this loop makes to the new keyframe, against the drift the walk since
        // the candidate could have gathered.
        let correction =
            (refined.pose.translation.vector - self.keyframe_pose(new).translation.vector).norm();
        if correction > self.drift_allowance(cand, new) {
            self.report.loops_beyond_drift += 1;
            return rejected;
        }
        let cand_pose = self.keyframe_pose(cand);
        let info = Self::information(
            self.config.loop_information,
            Some(&refined.information),
            &refined.pose,
        );
        if self
            .graph
            .add_edge(
                cand as u64,
                new as u64,
                cand_pose.inverse() * refined.pose,
                info,
                self.config.loop_kernel,
            )
            .is_err()
        {
            return rejected;
        }
        if self.optimizer.optimize(&mut self.graph).is_err() {
            self.report.optimizer_failures += 1;
        }
        if let Some(weights) = self.optimizer.edge_weights() {
            // Odometry edges join consecutive keyframes; every other edge is a loop.
            let nodes = self.graph.nodes();
            self.report.loops_weighted_out = self
                .graph
                .edges()
                .iter()
                .zip(weights)
                .filter(|(e, w)| nodes[e.from].id.abs_diff(nodes[e.to].id) != 1 && **w < 0.5)
                .count();
        }
        self.report.loops_closed += 1;
        self.report.place_loops_closed += usize::from(candidate.guess.is_some());
        // The keyframes moved: rebuild the local map now, within this step, so that the next
        // scan's odometry does not pay for it.
        self.local_map = None;
        self.ensure_local_map();
        let poses: Vec<Pose3> = self.graph.nodes().iter().map(|n| n.pose).collect();
        self.node_index.rebuild(poses.iter());
        LoopOutcome::Closed {
            from: cand as u64,
            to: new as u64,
            mean_squared_error: mse,
        }
    }
}
