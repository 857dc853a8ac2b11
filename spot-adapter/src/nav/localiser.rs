//! Localisation against a map that knows when it is lost: each scan corrects the odometry's
//! prediction by registration; the health of those corrections is tracked, a correction larger
//! than the odometry can have drifted since the last one is taken once consecutive scans confirm
//! it, and after repeated failures a wide search over seeds around the estimate relocalises the
//! robot, or reports it lost.

use nalgebra::{Translation3, UnitQuaternion, Vector3};
use slam_core::tracking::{ReachConfig, Tracker, TrackerConfig, scan_extent};
use slam_core::{Pose3, Registrator, level_on_gravity};

use crate::nav::NavError;
use crate::robot::Sample;

/// Settings of the localiser. Lengths in metres, angles in radians.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct LocaliserConfig {
    /// A correction that moves the odometry's prediction farther than this is never taken from
    /// one scan, 0.3 m (a wrong match or a genuine recovery, which the next scans must
    /// confirm) ...
    pub max_correction: f64,
    /// ... or turns it more than this, 0.1 rad (5.7°).
    pub max_correction_angle: f64,
    /// Nor one that moves the prediction farther than the odometry can have drifted since the
    /// last correction taken: this (0.05 m, a registration's scatter and a step's drift) plus
    /// [`Self::odometry_drift`] times the distance walked since. Odometry drifts millimetres
    /// between two scans, so a one-scan jump of 0.17 m is a registration that slid into a wrong
    /// minimum (a 0.1 m map beside a box, building 6).
    pub correction_floor: f64,
    /// Drift of the odometry per metre walked that a correction may undo, 0.05 (Spot's is about
    /// 2 %: two and a half times that).
    pub odometry_drift: f64,
    /// How each scan is registered against the map (the tracker the SLAM engine's odometry
    /// uses too), with [`LocaliserConfig::tracker_defaults`]: a registration counts only with at
    /// least half of the scan's points matched (`min_inlier_ratio` 0.5); a coarse stage at a
    /// wider reach only once the odometry's predictions have been off by more than 17 cm
    /// (a third of the smallest reach, 0.5 m); no retries (the wide search below is the
    /// localiser's own). A correction larger than the odometry's drift (see
    /// [`Self::correction_floor`]) is taken only when the registration converged too; one within
    /// the drift is taken unconverged: beside a box a fine map's registration can swap pairs
    /// back and forth within millimetres of the truth for all its iterations.
    pub tracker: TrackerConfig,
    /// Consecutive scans whose large corrections agree (within 5 cm and 0.02 rad, once carried
    /// by the odometry) before the correction is taken, 3.
    pub confirm_after: usize,
    /// Consecutive failed or unconfirmed scans after which the robot is lost and a wide search
    /// runs, 5 (one second at 5 Hz).
    pub lost_after: usize,
    /// The wide search tries seeds this far around the estimate in x and y, 1.0 m, ...
    pub search_radius: f64,
    /// ... spaced this far apart, 0.5 m, ...
    pub search_step: f64,
    /// ... at headings this far either side of the estimate's, 0.52 rad (30°), ...
    pub search_angle: f64,
    /// ... spaced this far apart, 0.175 rad (10°).
    pub search_angle_step: f64,
    /// The best seed's registration must match at least this share of the scan, 0.6.
    pub relocalise_min_inlier_ratio: f64,
    /// Wide searches (one per scan) before the robot is reported lost, 3.
    pub max_searches: usize,
    /// While the robot is farther than [`Self::full_scan_within`] from its goal, the scan is
    /// thinned to this voxel (metres) before the registrator's own thinning, 0.35 m (0 turns
    /// it off). Walking needs centimetres, and half the points halve registration, a cycle's
    /// largest part; the full scan (0.25 m in the localiser of `pipelines`) registers the
    /// arrival, where a 0.35 m scan can end a degree off.
    pub walking_scan_voxel: f64,
    /// ... within this distance of the goal (metres) every scan is registered in full, 1.5 m.
    pub full_scan_within: f64,
    /// Each correction keeps the odometry's roll and pitch (its heading and position come from
    /// the scan), true: Spot's odometry frame has z up from its IMU, and so has a map made from
    /// it ([`GraphSlamConfig::odometry_gravity`](slam_core::GraphSlamConfig::odometry_gravity)),
    /// while a registration with thinned walking scans tilts up to a degree. Turn it off for a
    /// map whose z axis is not up (one made LiDAR-only from a tilted first scan).
    pub odometry_gravity: bool,
}

impl Default for LocaliserConfig {
    fn default() -> Self {
        Self {
            max_correction: 0.3,
            max_correction_angle: 0.1,
            correction_floor: 0.05,
            odometry_drift: 0.05,
            tracker: Self::tracker_defaults(),
            confirm_after: 3,
            lost_after: 5,
            search_radius: 1.0,
            search_step: 0.5,
            search_angle: 30f64.to_radians(),
            search_angle_step: 10f64.to_radians(),
            relocalise_min_inlier_ratio: 0.6,
            max_searches: 3,
            walking_scan_voxel: 0.35,
            full_scan_within: 1.5,
            odometry_gravity: true,
        }
    }
}

impl LocaliserConfig {
    /// The tracker settings of [`LocaliserConfig::default`] (see [`LocaliserConfig::tracker`]).
    #[must_use]
    pub fn tracker_defaults() -> TrackerConfig {
        TrackerConfig {
            reach: ReachConfig {
                initial: 0.5,
                ..ReachConfig::default()
            },
            min_inlier_ratio: 0.5,
            // The localiser decides on large corrections itself (confirmation, wide search).
            max_translation_correction: 1e3,
            max_rotation_correction: std::f64::consts::PI,
            retry: false,
            // Against a fixed map from the robot's odometry the correction is centimetres; the
            // localiser checks a large one itself.
            recheck_distance: 0.0,
            ..TrackerConfig::default()
        }
    }

    /// Every setting finite and positive, the ratios at most 1, the counts at least 1; the
    /// walking voxel 0 (off) or 1 cm to 10 m, the full-scan distance finite and not negative.
    ///
    /// # Errors
    /// [`NavError::InvalidConfig`] naming the first bad setting.
    pub fn validate(&self) -> Result<(), NavError> {
        for (setting, value) in [
            ("max_correction", self.max_correction),
            ("max_correction_angle", self.max_correction_angle),
            ("correction_floor", self.correction_floor),
            ("odometry_drift", self.odometry_drift),
            ("search_radius", self.search_radius),
            ("search_step", self.search_step),
            ("search_angle", self.search_angle),
            ("search_angle_step", self.search_angle_step),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(NavError::invalid(setting, value, "finite and positive"));
            }
        }
        let voxel = self.walking_scan_voxel;
        if !(voxel == 0.0 || (0.01..=10.0).contains(&voxel)) {
            return Err(NavError::invalid(
                "walking_scan_voxel",
                voxel,
                "0 (off) or from 0.01 to 10",
            ));
        }
        if !(self.full_scan_within.is_finite() && self.full_scan_within >= 0.0) {
            return Err(NavError::invalid(
                "full_scan_within",
                self.full_scan_within,
                "finite and not negative",
            ));
        }
        let ratio = self.relocalise_min_inlier_ratio;
        if !(ratio > 0.0 && ratio <= 1.0) {
            return Err(NavError::invalid(
                "relocalise_min_inlier_ratio",
                ratio,
                "within (0, 1]",
            ));
        }
        self.tracker.validate()?;
        for (setting, value) in [
            ("confirm_after", self.confirm_after),
            ("lost_after", self.lost_after),
            ("max_searches", self.max_searches),
        ] {
            if value == 0 {
                return Err(NavError::invalid(setting, 0.0, "at least 1"));
            }
        }
        // The search's seed count grows with the square of radius / step: keep it bounded.
        let per_axis = (2.0 * self.search_radius / self.search_step).floor() + 1.0;
        let headings = (2.0 * self.search_angle / self.search_angle_step).floor() + 1.0;
        if per_axis * per_axis * headings > 2000.0 {
            return Err(NavError::invalid(
                "search_step",
                self.search_step,
                "large enough for at most 2000 seeds",
            ));
        }
        Ok(())
    }
}

/// How localisation went this cycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum LocalisationStatus {
    /// The scan corrected the estimate.
    Corrected,
    /// The scan did not correct it (failed, poor, or an unconfirmed jump): the odometry's
    /// prediction stands.
    Predicted,
    /// A wide search found the robot again.
    Relocalised,
    /// A wide search failed; the robot should stand still while the next scans are searched.
    Searching,
    /// Every allowed wide search failed: the robot does not know where it is.
    Lost,
}

/// The health of localisation, for monitoring and the navigator's decisions.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LocalisationHealth {
    /// Whether the last registration converged.
    pub converged: bool,
    /// Share of the last scan's points the registration matched.
    pub inlier_ratio: f64,
    /// Smallest over largest eigenvalue of the last registration's information: near zero in a
    /// degenerate view.
    pub min_eigenvalue_ratio: f64,
    /// Consecutive scans that did not correct the estimate.
    pub consecutive_failures: usize,
    /// Scans that did not correct the estimate, in all.
    pub failures: usize,
    /// Large corrections taken after confirmation, in all.
    pub confirmed_jumps: usize,
    /// Wide searches that found the robot, in all.
    pub relocalisations: usize,
    /// Wide searches run since the robot was last localised.
    pub searches: usize,
}

/// A large correction waiting for confirmation: the corrected pose and the odometry then.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    map_t_body: Pose3,
    odom_t_body: Pose3,
    count: usize,
}

impl Candidate {
    /// Whether `corrected` (at odometry `odom_t_body`) agrees with this candidate carried along
    /// by the odometry since.
    fn agrees(&self, corrected: &Pose3, odom_t_body: &Pose3) -> bool {
        let carried = self.map_t_body * (self.odom_t_body.inverse() * odom_t_body);
        let d = carried.inverse() * corrected;
        d.translation.vector.norm() <= 0.05 && d.rotation.angle() <= 0.02
    }
}

/// The localiser: the estimate `map_T_body`, the map prepared once, the health.
pub(crate) struct Localiser<R: Registrator> {
    config: LocaliserConfig,
    registrator: R,
    tracker: Tracker,
    map: R::Target,
    map_t_body: Pose3,
    last_odom_t_body: Option<Pose3>,
    /// Distance walked by the odometry since the last correction taken (metres).
    walked_since_correction: f64,
    candidate: Option<Candidate>,
    health: LocalisationHealth,
}

impl<R: Registrator> Localiser<R> {
    /// # Errors
    /// [`NavError::InvalidConfig`] for bad tracker settings.
    pub(crate) fn new(
        registrator: R,
        map: R::Target,
        map_t_body: Pose3,
        config: LocaliserConfig,
    ) -> Result<Self, NavError> {
        let tracker = Tracker::new(config.tracker)?;
        Ok(Self {
            config,
            registrator,
            tracker,
            map,
            map_t_body,
            last_odom_t_body: None,
            walked_since_correction: 0.0,
            candidate: None,
            health: LocalisationHealth::default(),
        })
    }

    /// Takes `odom_t_body` as the odometry at the instant of the current estimate, so that the
    /// next update carries the estimate along the odometry's motion since.
    pub(crate) fn set_odometry(&mut self, odom_t_body: Pose3) {
        self.last_odom_t_body = Some(odom_t_body);
    }

    /// The registrator it localises with.
    pub(crate) fn registrator(&self) -> &R {
        &self.registrator
    }

    pub(crate) fn pose(&self) -> Pose3 {
        self.map_t_body
    }

    pub(crate) fn health(&self) -> LocalisationHealth {
        self.health
    }

    /// Predict from the odometry, correct by registering `sample`'s scan (thinned to
    /// [`LocaliserConfig::walking_scan_voxel`] when `walking`), track the health, and search
    /// wide when the robot seems lost.
    pub(crate) fn update(&mut self, sample: &Sample, walking: bool) -> LocalisationStatus {
        if let Some(last) = self.last_odom_t_body.replace(sample.odom_t_body) {
            let step = last.inverse() * sample.odom_t_body;
            self.walked_since_correction += step.translation.vector.norm();
            self.map_t_body *= step;
        }
        let voxel = self.config.walking_scan_voxel;
        let thinned = (walking && voxel > 0.0)
            .then(|| sample.cloud.voxel_downsample(voxel as f32).ok())
            .flatten();
        let Ok(source) = self
            .registrator
            .prepare_source(thinned.as_ref().unwrap_or(&sample.cloud))
        else {
            return self.failed();
        };
        let guess = self.map_t_body * sample.body_t_lidar;
        let extent = scan_extent(&sample.cloud);
        let outcome = self.tracker.track(
            &self.registrator,
            &source,
            Some(&self.map),
            &[guess],
            extent,
        );
        match outcome.alignment.as_ref().or(outcome.refused.as_ref()) {
            Some(a) => {
                self.health.converged = a.converged;
                self.health.inlier_ratio = a.inlier_ratio;
                self.health.min_eigenvalue_ratio = a.min_eigenvalue_ratio;
            }
            None => self.health.converged = false,
        }
        let Some((corrected, converged)) = outcome
            .alignment
            .map(|a| (a.pose * sample.body_t_lidar.inverse(), a.converged))
        else {
            return self.failed_with(sample, &source);
        };
        let jump = self.map_t_body.inverse() * corrected;
        let drifted = self.config.correction_floor
            + self.config.odometry_drift * self.walked_since_correction;
        let small = jump.translation.vector.norm() <= drifted.min(self.config.max_correction)
            && jump.rotation.angle() <= self.config.max_correction_angle;
        if small {
            return self.accept(corrected, LocalisationStatus::Corrected);
        }
        if !converged {
            return self.failed_with(sample, &source);
        }
        // A large correction: taken once consecutive scans agree on it.
        let count = match self.candidate {
            Some(c) if c.agrees(&corrected, &sample.odom_t_body) => c.count + 1,
            _ => 1,
        };
        self.candidate = Some(Candidate {
            map_t_body: corrected,
            odom_t_body: sample.odom_t_body,
            count,
        });
        if count >= self.config.confirm_after {
            self.health.confirmed_jumps += 1;
            return self.accept(corrected, LocalisationStatus::Corrected);
        }
        self.failed_with(sample, &source)
    }

    fn accept(&mut self, pose: Pose3, status: LocalisationStatus) -> LocalisationStatus {
        self.map_t_body = match self.last_odom_t_body {
            Some(odom_t_body) if self.config.odometry_gravity => {
                level_on_gravity(&pose, &odom_t_body, &Pose3::identity())
            }
            _ => pose,
        };
        self.walked_since_correction = 0.0;
        self.candidate = None;
        self.health.consecutive_failures = 0;
        self.health.searches = 0;
        status
    }

    /// A scan that did not correct the estimate and whose source could not be prepared.
    fn failed(&mut self) -> LocalisationStatus {
        self.health.failures += 1;
        self.health.consecutive_failures += 1;
        if self.health.consecutive_failures >= self.config.lost_after {
            self.health.searches += 1;
            if self.health.searches >= self.config.max_searches {
                return LocalisationStatus::Lost;
            }
            return LocalisationStatus::Searching;
        }
        LocalisationStatus::Predicted
    }

    /// A scan that did not correct the estimate: after `lost_after` in a row, search wide.
    fn failed_with(&mut self, sample: &Sample, source: &R::Source) -> LocalisationStatus {
        self.health.failures += 1;
        self.health.consecutive_failures += 1;
        if self.health.consecutive_failures < self.config.lost_after {
            return LocalisationStatus::Predicted;
        }
        if let Some(found) = self.search(sample, source) {
            self.health.relocalisations += 1;
            return self.accept(found, LocalisationStatus::Relocalised);
        }
        self.health.searches += 1;
        if self.health.searches >= self.config.max_searches {
            LocalisationStatus::Lost
        } else {
            LocalisationStatus::Searching
        }
    }

    /// Search the seeds within `radius` of the estimate in x and y, `step` apart, at its
    /// heading, with `sample`'s full scan, and take the best-matching pose when it is good
    /// enough (see [`LocaliserConfig::relocalise_min_inlier_ratio`]). For an estimate known to
    /// be off by up to `radius` (dead reckoning over a flight of stairs), whose error can lie
    /// beyond a registration's reach: a registration started 0.15 m off in a stair room can
    /// settle 0.2 m off, where the flight's risers line up.
    pub(crate) fn search_near(&mut self, sample: &Sample, radius: f64, step: f64) -> bool {
        let Ok(source) = self.registrator.prepare_source(&sample.cloud) else {
            return false;
        };
        let found = self.search_with(sample, &source, (radius, step), (0.0, 1.0));
        if let Some(pose) = found {
            self.last_odom_t_body = Some(sample.odom_t_body);
            self.accept(pose, LocalisationStatus::Relocalised);
            true
        } else {
            false
        }
    }

    /// The best-matching body pose among seeds around the estimate, when it is good enough.
    fn search(&self, sample: &Sample, source: &R::Source) -> Option<Pose3> {
        let c = &self.config;
        self.search_with(
            sample,
            source,
            (c.search_radius, c.search_step),
            (c.search_angle, c.search_angle_step),
        )
    }

    /// [`Self::search`] over seeds within `radius` in x and y `step` apart and headings within
    /// `angle` `angle_step` apart.
    fn search_with(
        &self,
        sample: &Sample,
        source: &R::Source,
        (radius, step): (f64, f64),
        (angle, angle_step): (f64, f64),
    ) -> Option<Pose3> {
        let c = &self.config;
        let steps = |half: f64, step: f64| {
            let n = (half / step).floor() as i64;
            (-n..=n).map(move |k| k as f64 * step)
        };
        let mut best: Option<(f64, f64, Pose3)> = None;
        for dx in steps(radius, step) {
            for dy in steps(radius, step) {
                for da in steps(angle, angle_step) {
                    let t = self.map_t_body.translation.vector + Vector3::new(dx, dy, 0.0);
                    let seed = Pose3::from_parts(
                        Translation3::from(t),
                        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), da)
                            * self.map_t_body.rotation,
                    );
                    let Ok(a) =
                        self.registrator
                            .align(source, &self.map, &(seed * sample.body_t_lidar))
                    else {
                        continue;
                    };
                    if !a.converged || a.inlier_ratio < c.relocalise_min_inlier_ratio {
                        continue;
                    }
                    let better = best.as_ref().is_none_or(|&(ratio, rmse, _)| {
                        a.inlier_ratio > ratio + 1e-9
                            || ((a.inlier_ratio - ratio).abs() <= 1e-9 && a.rmse < rmse)
                    });
                    if better {
                        best = Some((
                            a.inlier_ratio,
                            a.rmse,
                            a.pose * sample.body_t_lidar.inverse(),
                        ));
                    }
                }
            }
        }
        best.map(|(_, _, pose)| pose)
    }
}
