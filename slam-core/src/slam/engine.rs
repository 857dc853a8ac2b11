//! `GraphSlam`: the engine's state and its per-scan stages (predict, prepare, track, keyframe
//! decision, keyframe with local map and loop search, loop closure with optimisation), each
//! stage in its own file of this module.

use std::time::Instant;

use nalgebra::{Matrix6, UnitQuaternion};

use super::cloud_store::{KeyframeCloudError, KeyframeClouds, Stash};
use super::config::GraphSlamConfig;
use super::gravity::level_on_gravity;
use super::information::{edge_information, with_tilt};
use super::keyframes::{Keyframe, Link, ScanPose};
use super::local_map::{LocalMap, LocalWindow};
use super::loop_closure::LoopQueue;
use super::node_index::NodeIndex;
use super::prediction::{Prediction, TurnBasis};
use super::report::{ScanOutcome, SkipReason, SlamReport};
use super::revisit::Reference;
use super::scan_preparation::Prepared;
use crate::cloud::PointCloud;
use crate::error::{InvalidSetting, OptimizeError};
use crate::geometry::{Pose3, pose3_is_finite};
use crate::io::StampedPose;
use crate::pose_graph::{GraphPose, PoseGraph};
use crate::tracking::{Tracker, TurnPersistence};
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

/// A scan's gyro orientation (`start_R_body`) with the scan's stamp.
#[derive(Clone, Copy, Debug)]
pub(super) struct GyroReading {
    pub(super) stamp: f64,
    pub(super) orientation: UnitQuaternion<f64>,
}

/// Graph-SLAM over any [`MapRegistrator`] (odometry and loop refinement), a second one for coarse
/// loop checks (the thesis uses point-to-point ICP), and any [`Optimizer`].
///
/// Loop closure runs as a bounded step: each call of [`GraphSlam::loop_closure_step`] tries at
/// most one queued candidate, optimises at most once and then rebuilds the local map. With
/// [`GraphSlamConfig::inline_loop_closure`] (the default) [`GraphSlam::process`] calls it after
/// each new keyframe; otherwise the caller schedules it (between scans, or on a timer), so that
/// odometry is never held up. Either way the result is deterministic for a given input.
///
/// The pose graph only grows: a keyframe appends a node with its odometry edge, a loop appends
/// an edge, only the first node is fixed (when it is added), and nothing but the optimiser
/// moves a pose. An incremental optimiser ([`IncrementalOptimizer`], such as posegraph's
/// `IncrementalSmoother`) therefore keeps its factorisation from one loop closure to the next.
///
/// [`IncrementalOptimizer`]: crate::IncrementalOptimizer
pub struct GraphSlam<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>> {
    pub(super) config: GraphSlamConfig,
    pub(super) odometry: R,
    pub(super) loop_coarse: C,
    pub(super) loop_refine: R,
    pub(super) optimizer: O,
    /// Registers keyframes (and, LiDAR-only, every scan) against the local map.
    pub(super) tracker: Tracker,
    pub(super) graph: PoseGraph<Pose3>,
    pub(super) keyframes: Vec<Keyframe<R::Source, C::Source>>,
    /// The keyframes' map clouds, in memory or in the store's file.
    pub(super) clouds: KeyframeClouds,
    pub(super) local_map: Option<LocalMap<R::Target>>,
    /// The keyframes the local map is made of.
    pub(super) window: LocalWindow,
    /// On a revisit, the last scan that rode on an old keyframe: the next scans' reference.
    pub(super) anchor: Option<Reference>,
    /// The first keyframe made since the last revisit: those from it on are being laid down
    /// now, and are not ridden on.
    pub(super) chain_start: usize,
    /// The loop edges' indices in the graph's edges.
    pub(super) loop_edges: Vec<usize>,
    pub(super) node_index: NodeIndex,
    /// Loop candidates waiting for a loop-closure step.
    pub(super) loops: LoopQueue,
    /// Every accepted scan.
    pub(super) scan_poses: Vec<ScanPose>,
    pub(super) last_stamp: f64,
    /// How much of the last turn LiDAR-only predictions repeat.
    pub(super) turns: TurnPersistence,
    /// What the current scan's LiDAR-only prediction was extrapolated from, to score `turns`.
    pub(super) turn_basis: Option<TurnBasis>,
    /// The gyro orientation of the last scan taken.
    pub(super) last_gyro: Option<GyroReading>,
    /// Stamp and `odom_T_lidar` of the last accepted scan: the velocity for deskewing.
    pub(super) last_odometry: Option<StampedPose>,
    /// Place recognition over keyframe scans, when set: loops sought by appearance too.
    pub(super) places: Option<Box<dyn PlaceRecognizer + Send>>,
    pub(super) report: SlamReport,
    /// The last keyframe that kept its whole scan
    /// ([`GraphSlamConfig::keyframe_scan_spacing`]).
    pub(super) last_whole_scan: Option<usize>,
    /// Whether the odometry backend was set up for the sensor
    /// ([`MapRegistrator::fit_to_scan`], with the first scan).
    pub(super) fitted_to_sensor: bool,
}

/// The settings, the backends and how far the map has grown; not the keyframes, their clouds
/// and the graph.
impl<R, C, O> std::fmt::Debug for GraphSlam<R, C, O>
where
    R: MapRegistrator + std::fmt::Debug,
    C: MapRegistrator + std::fmt::Debug,
    O: Optimizer<Pose3> + std::fmt::Debug,
{
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GraphSlam")
            .field("config", &self.config)
            .field("odometry", &self.odometry)
            .field("loop_check", &self.loop_coarse)
            .field("loop_refine", &self.loop_refine)
            .field("optimizer", &self.optimizer)
            .field("place_recognition", &self.places.is_some())
            .field("scans", &self.report.scans)
            .field("keyframes", &self.keyframes.len())
            .field("edges", &self.graph.edges().len())
            .finish_non_exhaustive()
    }
}

impl<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>> GraphSlam<R, C, O> {
    /// An engine with its backends: `odometry` registers scans against the local map,
    /// `loop_coarse` checks loop candidates, `loop_refine` refines accepted loops (the same
    /// backend as odometry with a looser outlier threshold, thesis: 0.10 m).
    ///
    /// # Errors
    /// [`InvalidSetting`] naming the first bad setting of `config`
    /// ([`GraphSlamConfig::validate`]).
    pub fn try_new(
        config: GraphSlamConfig,
        odometry: R,
        loop_coarse: C,
        loop_refine: R,
        optimizer: O,
    ) -> Result<Self, InvalidSetting> {
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
            clouds: KeyframeClouds::default(),
            local_map: None,
            window: LocalWindow::default(),
            anchor: None,
            chain_start: 0,
            loop_edges: Vec::new(),
            node_index: NodeIndex::default(),
            loops: LoopQueue::default(),
            scan_poses: Vec::new(),
            last_stamp: f64::NEG_INFINITY,
            turns: TurnPersistence::default(),
            turn_basis: None,
            last_gyro: None,
            last_odometry: None,
            places: None,
            report: SlamReport::default(),
            last_whole_scan: None,
            fitted_to_sensor: false,
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

    /// The engine keeping only the newest `resident` keyframes' map clouds in memory and the
    /// older ones in a file it makes in `dir` (and removes when dropped), so that a long walk's
    /// memory grows by the keyframes' poses and registration points only (about 100 KB a
    /// keyframe with the point-to-plane pipeline, against 240 KB with every cloud held).
    /// [`GraphSlam::keyframe_scans`] and [`GraphSlam::map`] read the older clouds back; the
    /// tracking and the loop checks never need them. Clouds already kept move to the store.
    /// A cloud the file refuses stays in memory and is counted
    /// ([`SlamReport::keyframe_store_failures`]).
    ///
    /// # Errors
    /// [`KeyframeCloudError::Store`] when the file cannot be made in `dir`, or a cloud already
    /// kept cannot be moved to it.
    pub fn with_keyframe_store(
        mut self,
        dir: &std::path::Path,
        resident: usize,
    ) -> Result<Self, KeyframeCloudError> {
        let mut store = KeyframeClouds::in_folder(dir, resident)?;
        for i in 0..self.clouds.len() {
            if let Some(cloud) = self.clouds.get(i) {
                store.push(cloud?.into_owned())?;
            }
        }
        self.clouds = store;
        self.stash_old_points();
        Ok(self)
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

    /// The loop-closure edges' indices in [`PoseGraph::edges`]; every other edge is an
    /// odometry edge (from the previous keyframe, or on a revisit from the old keyframe the walk
    /// rode on, so node ids alone do not tell the two apart).
    #[must_use]
    pub fn loop_edges(&self) -> &[usize] {
        &self.loop_edges
    }

    /// The optimiser, e.g. for the weight it left each loop edge with
    /// ([`Optimizer::edge_weights`]).
    #[must_use]
    pub fn optimizer(&self) -> &O {
        &self.optimizer
    }

    /// The odometry's registrator (scans against the local map), set up for the sensor once the
    /// first scan came ([`MapRegistrator::fit_to_scan`]).
    #[must_use]
    pub fn registrator(&self) -> &R {
        &self.odometry
    }

    /// The registrator that checks loop candidates (coarse).
    #[must_use]
    pub fn loop_check_registrator(&self) -> &C {
        &self.loop_coarse
    }

    /// The registrator that refines accepted loops.
    #[must_use]
    pub fn loop_refine_registrator(&self) -> &R {
        &self.loop_refine
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
                .map(|orientation| GyroReading {
                    stamp: scan.stamp,
                    orientation,
                });
        }
        outcome
    }

    /// [`Self::process`] but for the gyro's bookkeeping: the stages of one scan.
    fn process_scan(&mut self, scan: &ScanInput<'_>) -> ScanOutcome {
        let started = Instant::now();
        self.report.scans += 1;
        if let Err(reason) = self.check_input(scan) {
            return self.skip(reason, started);
        }
        let odom_t_lidar = scan.odom_t_body.map(|o| o * scan.body_t_lidar);
        // Only a sweep whose points have different times is skewed.
        let swept = self.config.deskew
            && scan.cloud.time().is_some_and(|t| {
                t.iter()
                    .any(|&x| x.to_bits() != t.first().map_or(0, |f| f.to_bits()))
            });
        // 1. Predict: from the odometry, or from the constant velocity (and the gyro).
        let (guesses, velocity, lidar_only) = match self.predict(scan, odom_t_lidar, swept) {
            Err(reason) => return self.skip(reason, started),
            Ok(Prediction::First { pose, velocity }) => {
                if !self.fitted_to_sensor {
                    self.odometry.fit_to_scan(scan.cloud.len());
                    self.fitted_to_sensor = true;
                }
                return match self.prepare(scan, velocity) {
                    Ok(prepared) => {
                        self.add_keyframe(scan, prepared, odom_t_lidar, pose, None, started)
                    }
                    Err(reason) => self.skip(reason, started),
                };
            }
            Ok(Prediction::Short {
                keyframe,
                keyframe_t_lidar,
            }) => return self.ride(scan, keyframe, keyframe_t_lidar, None, false, started),
            Ok(Prediction::Odometry { guesses, velocity }) => (guesses, velocity, None),
            Ok(Prediction::LidarOnly {
                guess,
                velocity,
                reference,
            }) => (vec![guess], velocity, Some(reference)),
        };
        // 2. Prepare: thin, deskew with the predicted velocity.
        let prepared = match self.prepare(scan, velocity) {
            Ok(p) => p,
            Err(reason) => return self.skip(reason, started),
        };
        // 3. Track: register against the local map; LiDAR-only, with the sweep's own motion.
        let mut tracked = self.track(
            scan,
            prepared,
            &guesses,
            velocity,
            swept && lidar_only.is_some(),
        );
        if self.config.odometry_gravity
            && let Some(odom_t_body) = scan.odom_t_body
        {
            tracked.pose = level_on_gravity(&tracked.pose, &odom_t_body, &scan.body_t_lidar);
        }
        if let Some(basis) = self.turn_basis.take()
            && tracked.information.is_some()
        {
            basis.score(&mut self.turns, &tracked.pose, tracked.prepared.extent);
        }
        // 4. Keyframe decision: an odometry step was long enough already; LiDAR-only, the
        //    registered pose decides.
        if let Some(reference) = lidar_only {
            let mut delta = self.reference_pose(&reference).inverse() * tracked.pose;
            delta.rotation.renormalize();
            let moved = delta.translation.vector.norm() >= self.config.keyframe_distance
                || delta.rotation.angle() >= self.config.keyframe_rotation;
            let mut keyframe_t_lidar =
                self.keyframe_pose(reference.keyframe).inverse() * tracked.pose;
            keyframe_t_lidar.rotation.renormalize();
            if !moved && pose3_is_finite(&keyframe_t_lidar) {
                let sweep = tracked.prepared.sweep;
                let registered = tracked.information.is_some();
                return self.ride(
                    scan,
                    reference.keyframe,
                    keyframe_t_lidar,
                    sweep,
                    registered,
                    started,
                );
            }
        }
        // 5. Revisit: where the map already has a keyframe, the scan rides on it.
        if tracked.information.is_some()
            && let Some(old) = self.revisited_keyframe(&tracked.pose, tracked.inlier_ratio)
        {
            let mut keyframe_t_lidar = self.keyframe_pose(old).inverse() * tracked.pose;
            keyframe_t_lidar.rotation.renormalize();
            if pose3_is_finite(&keyframe_t_lidar) {
                self.revisit(old, keyframe_t_lidar, odom_t_lidar);
                let sweep = tracked.prepared.sweep;
                return self.ride(scan, old, keyframe_t_lidar, sweep, true, started);
            }
        }
        // 6. Keyframe: a node, the local map slid, a loop candidate queued, a loop step.
        self.add_keyframe(
            scan,
            tracked.prepared,
            odom_t_lidar,
            tracked.pose,
            tracked
                .information
                .as_ref()
                .map(|info| (info, tracked.inlier_ratio)),
            started,
        )
    }

    /// Why `scan` cannot be used at all: a stamp out of order or not finite, or a non-finite
    /// odometry or calibration pose.
    fn check_input(&self, scan: &ScanInput<'_>) -> Result<(), SkipReason> {
        if !scan.stamp.is_finite() || scan.stamp <= self.last_stamp {
            return Err(SkipReason::OutOfOrderStamp);
        }
        if scan.odom_t_body.is_some_and(|o| !pose3_is_finite(&o))
            || !pose3_is_finite(&scan.body_t_lidar)
        {
            return Err(SkipReason::NonFiniteOdometry);
        }
        Ok(())
    }

    /// `scan` taken without a new keyframe: it rides on `keyframe` at `keyframe_t_lidar`.
    fn ride(
        &mut self,
        scan: &ScanInput<'_>,
        keyframe: usize,
        keyframe_t_lidar: Pose3,
        sweep: Option<super::keyframes::Sweep>,
        registered: bool,
        started: Instant,
    ) -> ScanOutcome {
        self.last_stamp = scan.stamp;
        self.scan_poses.push(ScanPose {
            stamp: scan.stamp,
            keyframe,
            keyframe_t_lidar,
            sweep,
        });
        self.record_scan_time(started);
        ScanOutcome::Tracked { registered }
    }

    /// Add node `id` at `pose` with its odometry edge `(from, step, information)`, or fixed as
    /// the gauge without one. Checked first with the graph's own predicates, so that a refusal
    /// leaves the graph unchanged.
    fn insert_node(
        &mut self,
        id: u64,
        pose: Pose3,
        edge: Option<&(u64, Pose3, Matrix6<f64>)>,
    ) -> Result<(), OptimizeError> {
        if !pose3_is_finite(&pose)
            || edge.is_some_and(|(_, step, info)| {
                !pose3_is_finite(step) || !Pose3::information_is_valid(info)
            })
        {
            return Err(OptimizeError::NonFinite {
                what: crate::error::GraphValue::NodePose { id },
            });
        }
        self.graph.add_node(id, pose)?;
        match edge {
            Some(&(from, step, info)) => {
                self.graph.add_edge(from, id, step, info, None)?;
            }
            None => self.graph.fix(id)?,
        }
        Ok(())
    }

    /// The odometry edge from keyframe `from` to a new keyframe at `pose` (with its
    /// registration's information, and its odometry when it had some).
    fn odometry_edge(
        &self,
        from: usize,
        pose: &Pose3,
        reg_info: Option<&Matrix6<f64>>,
        odom_t_lidar: Option<Pose3>,
    ) -> (u64, Pose3, Matrix6<f64>) {
        let step = self.keyframe_pose(from).inverse() * pose;
        let mut info = edge_information(self.config.odometry_information, reg_info, pose);
        // Both ends levelled on the odometry's gravity: their relative tilt is the IMU's.
        if self.config.odometry_gravity
            && odom_t_lidar.is_some()
            && self.keyframes[from].odom_t_lidar.is_some()
        {
            info = with_tilt(info, self.config.gravity_tilt_sigma);
        }
        (from as u64, step, info)
    }

    /// Keyframe `index` (scan `cloud`, thinned) joins the local map and the place recognizer;
    /// the earlier keyframes it looks like. The recognizer runs on a worker of the thread pool
    /// while the local map slides on this thread (its index is then built on the other core
    /// meanwhile); neither reads what the other writes. A scan the recognizer refuses is
    /// counted, and the keyframe goes on without a place match.
    fn slide_and_recognize(&mut self, index: usize, cloud: &PointCloud) -> Vec<PlaceMatch> {
        let mut places = self.places.take();
        let mut recognized = None;
        rayon::in_place_scope(|s| {
            if let Some(p) = places.as_mut() {
                let recognized = &mut recognized;
                s.spawn(move |_| *recognized = Some(p.candidates_then_add(index, cloud)));
            }
            self.visit_keyframe(index);
        });
        self.places = places;
        match recognized {
            Some(Ok(found)) => found,
            Some(Err(_)) => {
                self.report.place_refusals += 1;
                Vec::new()
            }
            None => Vec::new(),
        }
    }

    /// Adds `prepared` as a keyframe at `pose` (with its `registration`'s information for its
    /// odometry edge, and the share of the scan it matched), queues its loop candidate and runs a loop-closure step when
    /// inline.
    pub(super) fn add_keyframe(
        &mut self,
        scan: &ScanInput<'_>,
        prepared: Prepared<R::Source>,
        odom_t_lidar: Option<Pose3>,
        pose: Pose3,
        registration: Option<(&Matrix6<f64>, f64)>,
        started: Instant,
    ) -> ScanOutcome {
        let reg_info = registration.map(|(info, _)| info);
        // Unknown (0: no revisit counts as a drop) for the first keyframe and a fallback.
        let matched = registration.map_or(0.0, |(_, ratio)| ratio);
        let Prepared {
            cloud,
            thinned,
            coarse: cloud_source,
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
        // Positions and intensities only: a voxel's ring and time mean nothing once the scan is
        // deskewed and thinned, and they were a third of what the keyframe kept of it.
        let cloud = cloud.without_ring_and_time();
        // The loop check's source from the scan already thinned to its voxel when the odometry
        // thins to the same one (an OS1-128 keyframe's 41,000 points not voxelised again).
        let same_voxel = self
            .loop_coarse
            .source_voxel()
            .is_some_and(|v| Some(v) == self.odometry.source_voxel());
        let loop_cloud = cloud_source.as_ref().filter(|_| same_voxel);
        let Ok(coarse) = self
            .loop_coarse
            .prepare_source(loop_cloud.unwrap_or(&cloud))
        else {
            return self.skip(SkipReason::PreparationFailed, started);
        };
        // A dense scan within the spacing of the last whole one keeps the points its
        // registration used instead of its whole scan (place recognition still reads it).
        let kept = cloud_source
            .filter(|_| self.spaces_whole_scans(scan) && !self.whole_scan_due(&pose))
            .map(PointCloud::without_ring_and_time);
        let index = self.keyframes.len();
        let id = index as u64;
        // The odometry edge comes from the reference: the last keyframe, or on a revisit the old
        // keyframe the walk rode on.
        let parent = self.reference().map(|r| r.keyframe);
        let edge = parent.map(|from| self.odometry_edge(from, &pose, reg_info, odom_t_lidar));
        if self.insert_node(id, pose, edge.as_ref()).is_err() {
            return self.skip(SkipReason::NonFinitePose, started);
        }
        let walked = parent.map_or(0.0, |from| {
            self.keyframes[from].walked
                + (pose.translation.vector - self.keyframe_pose(from).translation.vector).norm()
        });
        self.keyframes.push(Keyframe {
            walked,
            stamp: scan.stamp,
            odom_t_lidar,
            source: Stash::Held(self.odometry.keyframe_source(source)),
            coarse: Stash::Held(self.loop_coarse.keyframe_source(coarse)),
            matched,
            links: parent
                .map(|keyframe| Link {
                    keyframe,
                    loop_edge: None,
                })
                .into_iter()
                .collect(),
        });
        if let Some(from) = parent {
            self.keyframes[from].links.push(Link {
                keyframe: index,
                loop_edge: None,
            });
        }
        self.report.keyframes += 1;
        self.anchor = None;
        if kept.is_none() {
            self.last_whole_scan = Some(index);
            self.report.whole_scans += 1;
        }
        let look_alikes = self.slide_and_recognize(index, &cloud);
        if self.clouds.push(kept.unwrap_or(cloud)).is_err() {
            // Kept in memory instead; counted, the walk goes on.
            self.report.keyframe_store_failures += 1;
        }
        self.stash_old_points();
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
}
