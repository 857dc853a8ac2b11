//! The tracker: register a scan from its predictions, coarse to fine, check the result, and
//! fall back with a reason.

use nalgebra::{Translation3, UnitQuaternion, Vector3};

use super::health::{FallbackReason, TrackingHealth};
use super::reach::{AdaptiveReach, ReachConfig, point_displacement};
use crate::error::{InvalidSetting, RegistrationError};
use crate::geometry::{Pose3, pose3_is_finite};
use crate::traits::registrator::{Alignment, Reach, Registrator};

/// Settings of a [`Tracker`]. Lengths in metres, angles in radians.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct TrackerConfig {
    /// The adaptive reach of the coarse stage.
    pub reach: ReachConfig,
    /// The coarse stage's robust kernel as a share of its reach, 1/3: wide enough that the
    /// pairs of a turned scan still pull, narrow enough that the wrong surfaces do not.
    pub coarse_kernel: f64,
    /// A registration that matched less than this share of the scan's points is not taken,
    /// 0.3 (a scan registered where it belongs matches most of what the target saw too).
    pub min_inlier_ratio: f64,
    /// Nor one that moved the prediction farther than this, 2 m ...
    pub max_translation_correction: f64,
    /// ... or turned it more than this, 1.05 rad (60°).
    pub max_rotation_correction: f64,
    /// When the caller gives other guesses than its prediction (an odometry step it doubts), a
    /// registration from one of them is taken instead of the prediction's only when the two
    /// ended farther apart than this (0.5 m) and it matched a larger share of the scan (a lower
    /// RMS error on a tie).
    pub arbitration_distance: f64,
    /// Whether a scan that registers from no guess is tried again, at the widest reach and at
    /// the headings below, true. Off for a caller with a search of its own.
    pub retry: bool,
    /// A registration that matched less than this share of what registrations have typically
    /// matched lately (a running mean of the shares taken) is suspect, 0.75, and tried again as
    /// a failed one is, the best fit kept: a turned scan can converge to a wrong pose that still
    /// matches a third of its points (measured: 0.3-0.45 there, 0.75-0.97 where right).
    pub suspect_ratio: f64,
    /// Headings either side of the prediction tried when no guess registers (radians; 0.35 rad,
    /// 20°, so guesses at ±20°, ±40° and ±60° with the default `retry_turns` of 3): a sudden
    /// turn that no reach recovers from the prediction is recovered from the nearest of these.
    pub retry_turn_step: f64,
    /// Headings tried on each side, 3 (0 turns the heading retries off).
    pub retry_turns: usize,
    /// Whether a retry first tries the predicted position with the turn the refused
    /// registration found, true: at a sudden turn the wide stages mostly find the turn but
    /// slide the scan metres along a corridor (on the simulated hand-held walk the retries then
    /// take 2-60 ms instead of 10-100 ms).
    pub retry_found_turn: bool,
    /// Fallbacks in a row after which tracking counts as lost, 3.
    pub lost_after: usize,
    /// When a registration ends farther than this from the prediction's position (metres,
    /// 0.05), the fine stage is run once more from the prediction's position with the
    /// registered rotation, and that result is kept when it matched at least as much of the
    /// scan with no larger RMS error. The wide stages fix the rotation well but can carry the
    /// position into a neighbouring basin along a corridor: on simulated hand-held walks the
    /// staged result sat 0.2 m short of the truth while the fine stage started from the
    /// predicted position stayed at the truth with a better fit. The Graph-SLAM engine checks a
    /// sweep's own motion the same way (`GraphSlamConfig::sweep_motion`). 0 turns it off.
    pub recheck_distance: f64,
    /// A recheck first runs as the last wide stage does (the reach's minimum, the coarse
    /// kernel, the wide stages' few points); when that ends within this of the registration it
    /// checks (metres, 0.02, and a fifth of it in radians), the registration stands: the two
    /// starts lie in one basin. Otherwise the recheck goes on from there as a whole fine stage.
    /// On the simulated hand-held walk three in four rechecks end in the basin they check, after
    /// 5-50 full iterations; the wide stage's answer is a few millimetres from the fine one.
    /// 0 runs every recheck whole from its start.
    pub recheck_basin: f64,
}

impl Default for TrackerConfig {
    fn default() -> Self {
        Self {
            reach: ReachConfig::default(),
            coarse_kernel: 1.0 / 3.0,
            min_inlier_ratio: 0.3,
            max_translation_correction: 2.0,
            max_rotation_correction: 60f64.to_radians(),
            arbitration_distance: 0.5,
            retry: true,
            suspect_ratio: 0.75,
            retry_turn_step: 20f64.to_radians(),
            retry_turns: 3,
            retry_found_turn: true,
            lost_after: 3,
            recheck_distance: 0.05,
            recheck_basin: 0.05,
        }
    }
}

impl TrackerConfig {
    /// Every setting in range: the reach's ([`ReachConfig::validate`]); the coarse kernel and
    /// the inlier ratio in (0, 1]; the correction limits, the arbitration distance and the turn
    /// step finite and positive; the recheck's distance and basin finite and not negative;
    /// `lost_after` at least 1.
    ///
    /// # Errors
    /// [`InvalidSetting`] naming the first bad setting.
    pub fn validate(&self) -> Result<(), InvalidSetting> {
        self.reach.validate()?;
        for (setting, v) in [
            ("TrackerConfig::coarse_kernel", self.coarse_kernel),
            ("TrackerConfig::min_inlier_ratio", self.min_inlier_ratio),
            ("TrackerConfig::suspect_ratio", self.suspect_ratio),
        ] {
            InvalidSetting::check(v > 0.0 && v <= 1.0, setting, v, "within (0, 1]")?;
        }
        for (setting, v) in [
            (
                "TrackerConfig::max_translation_correction",
                self.max_translation_correction,
            ),
            (
                "TrackerConfig::max_rotation_correction",
                self.max_rotation_correction,
            ),
            (
                "TrackerConfig::arbitration_distance",
                self.arbitration_distance,
            ),
            ("TrackerConfig::retry_turn_step", self.retry_turn_step),
        ] {
            InvalidSetting::check(v.is_finite() && v > 0.0, setting, v, "finite and positive")?;
        }
        for (setting, v) in [
            ("TrackerConfig::recheck_distance", self.recheck_distance),
            ("TrackerConfig::recheck_basin", self.recheck_basin),
        ] {
            InvalidSetting::check(
                v.is_finite() && v >= 0.0,
                setting,
                v,
                "finite and not negative (0 turns it off)",
            )?;
        }
        InvalidSetting::check(
            self.lost_after >= 1,
            "TrackerConfig::lost_after",
            self.lost_after as f64,
            "at least 1",
        )
    }
}

/// What [`Tracker::track`] decided for one scan.
#[derive(Clone, Debug, PartialEq)]
pub struct TrackOutcome {
    /// The registered pose, or the prediction (the first guess) on a fallback.
    pub pose: Pose3,
    /// The registration taken; `None` on a fallback.
    pub alignment: Option<Alignment>,
    /// On a fallback, the prediction's registration that a check refused (too few inliers, too
    /// large a correction), for diagnosis; `None` when it never got that far, or when tracked.
    pub refused: Option<Alignment>,
    /// Why the prediction was kept; `None` when the scan was tracked.
    pub fallback: Option<FallbackReason>,
    /// Which guess the pose was registered from (0: the prediction).
    pub guess: usize,
    /// Whether it took a second try (another guess, the widest reach, or a turned heading).
    pub recovered: bool,
}

impl TrackOutcome {
    /// Whether the scan was registered and taken.
    #[must_use]
    pub fn tracked(&self) -> bool {
        self.fallback.is_none()
    }
}

/// How much larger a share of the scan a retry must match to replace a registration that was
/// taken but suspect.
const CLEARLY_MORE: f64 = 0.05;

/// A registration from one guess, or why it was refused (with the alignment a check refused).
type Attempt = Result<Alignment, (FallbackReason, Option<Box<Alignment>>)>;

/// Predict, register coarse to fine with an adaptive reach, check, fall back with a reason.
///
/// Generic over any [`Registrator`]: its configured alignment is the fine stage; the coarse
/// stage is [`Registrator::align_within`] at the reach three RMS prediction errors give
/// ([`AdaptiveReach`]), run only while that reach exceeds [`ReachConfig::min`].
///
/// ```
/// use nalgebra::{Matrix6, Point3};
/// use slam_core::tracking::{Tracker, TrackerConfig};
/// use slam_core::{Alignment, PointCloud, Pose3, Reach, Registrator, RegistrationError};
///
/// /// A registrator that always finds `answer`.
/// struct Oracle { answer: Pose3 }
/// impl Registrator for Oracle {
///     type Source = ();
///     type Target = ();
///     fn prepare_source(&self, _: &PointCloud) -> Result<(), RegistrationError> { Ok(()) }
///     fn prepare_target(&self, _: &PointCloud) -> Result<(), RegistrationError> { Ok(()) }
///     fn align(&self, _: &(), _: &(), _: &Pose3) -> Result<Alignment, RegistrationError> {
///         Ok(Alignment { pose: self.answer, converged: true, iterations: 1, inliers: 90,
///             inlier_ratio: 0.9, rmse: 0.01, information: Matrix6::identity(),
///             min_eigenvalue_ratio: 1.0 })
///     }
///     fn align_within(&self, s: &(), t: &(), g: &Pose3, _: &Reach)
///         -> Result<Alignment, RegistrationError> { self.align(s, t, g) }
/// }
///
/// let mut tracker = Tracker::new(TrackerConfig::default())?;
/// let answer = Pose3::translation(1.0, 0.0, 0.0);
/// let prediction = Pose3::translation(0.9, 0.0, 0.0);
/// let outcome = tracker.track(&Oracle { answer }, &(), Some(&()), &[prediction], 10.0);
/// assert!(outcome.tracked());
/// assert_eq!(outcome.pose, answer);
/// assert_eq!(tracker.health().tracked, 1);
/// # Ok::<(), slam_core::InvalidSetting>(())
/// ```
#[derive(Clone, Debug)]
pub struct Tracker {
    config: TrackerConfig,
    reach: AdaptiveReach,
    health: TrackingHealth,
    /// Running mean of the matched shares of the registrations taken (`None` before one).
    typical_inlier_ratio: Option<f64>,
}

/// The reason a registration error gives for falling back.
fn reason_of(error: &RegistrationError) -> FallbackReason {
    match error {
        RegistrationError::TooFewCorrespondences { .. } => FallbackReason::TooFewCorrespondences,
        RegistrationError::Degenerate { .. } | RegistrationError::RigidFit(_) => {
            FallbackReason::Degenerate
        }
        _ => FallbackReason::RegistrationError,
    }
}

/// `guess` turned by `angle` about the vertical through its position.
fn turned(guess: &Pose3, angle: f64) -> Pose3 {
    let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), angle);
    Pose3::from_parts(
        Translation3::from(guess.translation.vector),
        turn * guess.rotation,
    )
}

/// Whether `a` fits better than `b`: a larger matched share, a lower RMS error on a tie.
fn fits_better(a: &Alignment, b: &Alignment) -> bool {
    match a.inlier_ratio.total_cmp(&b.inlier_ratio) {
        std::cmp::Ordering::Greater => true,
        std::cmp::Ordering::Equal => a.rmse < b.rmse,
        std::cmp::Ordering::Less => false,
    }
}

impl Tracker {
    /// A tracker with `config`.
    ///
    /// # Errors
    /// [`InvalidSetting`] naming the first bad setting ([`TrackerConfig::validate`]).
    pub fn new(config: TrackerConfig) -> Result<Self, InvalidSetting> {
        config.validate()?;
        Ok(Self {
            reach: AdaptiveReach::new(config.reach)?,
            config,
            health: TrackingHealth::default(),
            typical_inlier_ratio: None,
        })
    }

    /// The settings.
    #[must_use]
    pub fn config(&self) -> &TrackerConfig {
        &self.config
    }

    /// The counts so far.
    #[must_use]
    pub fn health(&self) -> &TrackingHealth {
        &self.health
    }

    /// The coarse stage's reach for the next scan (metres).
    #[must_use]
    pub fn reach(&self) -> f64 {
        self.reach.current()
    }

    /// Whether the last [`TrackerConfig::lost_after`] scans or more all fell back.
    #[must_use]
    pub fn is_lost(&self) -> bool {
        self.health.consecutive_fallbacks >= self.config.lost_after
    }

    /// Forgets the recent prediction errors (the reach starts over at
    /// [`ReachConfig::initial`]), e.g. after a relocalisation.
    pub fn reset_reach(&mut self) {
        self.reach.reset();
    }

    /// Registers `source` against `target` from `guesses` and decides its pose.
    ///
    /// `guesses[0]` is the prediction (the robot's odometry, a gyro, or a constant-velocity
    /// extrapolation); any others are alternatives the caller doubts it against (each is
    /// registered too, see [`TrackerConfig::arbitration_distance`]). `extent` is how far the
    /// scan reaches (metres, [`scan_extent`](super::scan_extent)): the range at which a rotation
    /// error is measured. When no guess registers, the prediction is tried once more at the
    /// widest reach and turned either side ([`TrackerConfig::retry_turns`]); when that fails
    /// too, the prediction is kept and the reason counted. `target` `None` (no map yet) is
    /// counted as [`FallbackReason::NoTarget`].
    ///
    /// # Panics
    /// Never; an empty `guesses` is a fallback at the identity with
    /// [`FallbackReason::RegistrationError`].
    pub fn track<R: Registrator>(
        &mut self,
        registrator: &R,
        source: &R::Source,
        target: Option<&R::Target>,
        guesses: &[Pose3],
        extent: f64,
    ) -> TrackOutcome {
        let Some(&prediction) = guesses.first() else {
            return self.fall_back(Pose3::identity(), FallbackReason::RegistrationError);
        };
        let Some(target) = target else {
            return self.fall_back(prediction, FallbackReason::NoTarget);
        };
        let extent = if extent.is_finite() && extent > 0.0 {
            extent
        } else {
            0.0
        };
        let reach = self.reach.current();
        self.health.last_reach = if reach > self.config.reach.min {
            reach
        } else {
            0.0
        };
        let attempts: Vec<Attempt> = guesses
            .iter()
            .map(|g| self.attempt(registrator, source, target, g, reach))
            .collect();
        let chosen = self.arbitrate(&attempts);
        let (index, alignment, recovered) = match chosen {
            Some((i, a)) if self.suspect(&a) => {
                // A retry replaces a registration that was taken only when it matches clearly
                // more: along a corridor a pose slid by a few centimetres can match a little
                // more by chance.
                match self.retry(registrator, source, target, &prediction, None) {
                    Some(b) if b.inlier_ratio > a.inlier_ratio + CLEARLY_MORE => (0, b, true),
                    _ => (i, a, false),
                }
            }
            Some((i, a)) => (i, a, false),
            None => {
                let (first, refused) = attempts
                    .into_iter()
                    .next()
                    .and_then(Result::err)
                    .unwrap_or((FallbackReason::RegistrationError, None));
                let retried = self
                    .config
                    .retry
                    .then(|| {
                        let turn = refused
                            .as_ref()
                            .filter(|_| self.config.retry_found_turn)
                            .map(|a| a.pose.rotation);
                        self.retry(registrator, source, target, &prediction, turn)
                    })
                    .flatten();
                if let Some(a) = retried {
                    (0, a, true)
                } else {
                    self.reach.record(f64::INFINITY);
                    let mut outcome = self.fall_back(prediction, first);
                    outcome.refused = refused.map(|a| *a);
                    return outcome;
                }
            }
        };
        let error = point_displacement(&(prediction.inverse() * alignment.pose), extent);
        self.reach.record(error);
        self.typical_inlier_ratio = Some(match self.typical_inlier_ratio {
            Some(m) => 0.9 * m + 0.1 * alignment.inlier_ratio,
            None => alignment.inlier_ratio,
        });
        self.health.tracked += 1;
        self.health.recovered += usize::from(recovered);
        self.health.consecutive_fallbacks = 0;
        TrackOutcome {
            pose: alignment.pose,
            alignment: Some(alignment),
            refused: None,
            fallback: None,
            guess: index,
            recovered,
        }
    }

    /// Whether `a` matched much less of its scan than registrations lately have (when retries
    /// are on).
    fn suspect(&self, a: &Alignment) -> bool {
        self.config.retry
            && self
                .typical_inlier_ratio
                .is_some_and(|m| a.inlier_ratio < self.config.suspect_ratio * m)
    }

    /// The prediction kept, with `reason` counted.
    fn fall_back(&mut self, prediction: Pose3, reason: FallbackReason) -> TrackOutcome {
        self.health.fallbacks.add(reason);
        self.health.consecutive_fallbacks += 1;
        if self.health.consecutive_fallbacks == self.config.lost_after {
            self.health.losses += 1;
        }
        TrackOutcome {
            pose: prediction,
            alignment: None,
            refused: None,
            fallback: Some(reason),
            guess: 0,
            recovered: false,
        }
    }

    /// The prediction's registration unless another guess's ended more than the arbitration
    /// distance away and fits better (the best such); the best other when the prediction's
    /// failed.
    fn arbitrate(&self, attempts: &[Attempt]) -> Option<(usize, Alignment)> {
        let mut best: Option<(usize, &Alignment)> = None;
        for (i, a) in attempts.iter().enumerate() {
            let Ok(a) = a else { continue };
            best = match best {
                None => Some((i, a)),
                Some((j, b)) => {
                    let apart = (a.pose.translation.vector - b.pose.translation.vector).norm();
                    if apart > self.config.arbitration_distance && fits_better(a, b) {
                        Some((i, a))
                    } else {
                        Some((j, b))
                    }
                }
            };
        }
        best.map(|(i, a)| (i, a.clone()))
    }

    /// The best registration of the prediction at the initial and the widest reach and turned
    /// either side, if any is taken: first, when given, the predicted position with `turn` (the
    /// rotation a refused registration found); then the prediction, then the headings nearest
    /// it on both sides, farther ones only while the best so far is suspect (most sudden turns
    /// are found by the first tries; each costs a whole coarse-to-fine registration).
    ///
    /// The prediction at both reaches, the initial one when the widest gave nothing or a suspect
    /// fit: a wide reach pulls in a scan turned far from its guess, but in a corridor its far
    /// pairs can also slide a scan that was nearly right metres along it (measured on a
    /// simulated hand-held walk: 5.4 m, refused as too large a correction, after which only a
    /// wrong 56° turn registered); the initial reach finds that scan.
    fn retry<R: Registrator>(
        &self,
        registrator: &R,
        source: &R::Source,
        target: &R::Target,
        prediction: &Pose3,
        turn: Option<nalgebra::UnitQuaternion<f64>>,
    ) -> Option<Alignment> {
        let widest = self.config.reach.max;
        let narrow = self.config.reach.initial.min(widest);
        let step = self.config.retry_turn_step;
        let mut best: Option<Alignment> = None;
        // A registration refused for sliding metres at a sudden turn has mostly found the turn:
        // from the predicted position with that turn, at the initial reach, it is often right,
        // and then only the prediction at the widest reach is tried beside it (the better fit
        // kept) before the turned headings (the hand-held walk's retries 10-100 ms -> 2-60 ms).
        if let Some(rotation) = turn {
            let guess = Pose3::from_parts(prediction.translation, rotation);
            if pose3_is_finite(&guess) {
                best = self
                    .attempt(registrator, source, target, &guess, narrow)
                    .ok();
            }
        }
        for k in 0..=self.config.retry_turns {
            let a = k as f64 * step;
            let tries: &[(f64, f64)] = if k == 0 {
                &[(0.0, widest), (0.0, narrow)]
            } else {
                &[(a, widest), (-a, widest)]
            };
            for &(angle, reach) in tries {
                if k == 0 && reach < widest && best.as_ref().is_some_and(|b| !self.suspect(b)) {
                    break;
                }
                let guess = turned(prediction, angle);
                if let Ok(a) = self.attempt(registrator, source, target, &guess, reach)
                    && best.as_ref().is_none_or(|b| fits_better(&a, b))
                {
                    best = Some(a);
                }
            }
            if best.as_ref().is_some_and(|b| !self.suspect(b)) {
                break;
            }
        }
        best
    }

    /// Coarse (when the reach is above its minimum) then fine registration from `guess`,
    /// checked.
    fn attempt<R: Registrator>(
        &self,
        registrator: &R,
        source: &R::Source,
        target: &R::Target,
        guess: &Pose3,
        reach: f64,
    ) -> Attempt {
        // Coarse to fine: the reach halves stage by stage down to the smallest, so that a
        // guess far off is pulled in by far pairs first and each narrower kernel starts inside
        // its own basin (one wide stage straight into the fine one left 0.2 m slips along
        // corridors after sudden turns).
        let mut start = *guess;
        let mut r = reach;
        while r > self.config.reach.min {
            let stage = Reach {
                distance: r,
                kernel: r * self.config.coarse_kernel,
            };
            start = registrator
                .align_within(source, target, &start, &stage)
                .map_err(|e| (reason_of(&e), None))?
                .pose;
            r *= 0.5;
        }
        if !pose3_is_finite(&start) {
            return Err((FallbackReason::NonFinitePose, None));
        }
        let a = registrator
            .align(source, target, &start)
            .map_err(|e| (reason_of(&e), None))?;
        if !pose3_is_finite(&a.pose) {
            return Err((FallbackReason::NonFinitePose, None));
        }
        let a = self.recheck(registrator, source, target, guess, a);
        if a.inlier_ratio < self.config.min_inlier_ratio {
            return Err((FallbackReason::TooFewInliers, Some(Box::new(a))));
        }
        let correction = guess.inverse() * a.pose;
        if correction.translation.vector.norm() > self.config.max_translation_correction
            || correction.rotation.angle() > self.config.max_rotation_correction
        {
            return Err((FallbackReason::CorrectionTooLarge, Some(Box::new(a))));
        }
        Ok(a)
    }
}

impl Tracker {
    /// `a`, or the fine stage from `guess`'s position with `a`'s rotation when `a` ended more
    /// than [`TrackerConfig::recheck_distance`] from that position and the other fits at least
    /// as well on both counts (matched share and RMS error).
    fn recheck<R: Registrator>(
        &self,
        registrator: &R,
        source: &R::Source,
        target: &R::Target,
        guess: &Pose3,
        a: Alignment,
    ) -> Alignment {
        let Some(start) = self.config.recheck_start(guess, &a.pose) else {
            return a;
        };
        let start = if self.config.recheck_basin > 0.0 {
            let stage = Reach {
                distance: self.config.reach.min,
                kernel: self.config.reach.min * self.config.coarse_kernel,
            };
            match registrator.align_within(source, target, &start, &stage) {
                Ok(c) if self.config.in_basin(&c.pose, &a.pose) => return a,
                Ok(c) if pose3_is_finite(&c.pose) => c.pose,
                // Not settled cheaply: the whole fine stage from the start decides.
                _ => start,
            }
        } else {
            start
        };
        match registrator.align(source, target, &start) {
            Ok(b) if replaces(&b, &a) => b,
            _ => a,
        }
    }
}

impl TrackerConfig {
    /// Where to register again when `found` ended more than [`Self::recheck_distance`] from
    /// `prediction`'s position: that position with `found`'s rotation; `None` when it ended
    /// within it, or the recheck is off.
    #[must_use]
    pub fn recheck_start(&self, prediction: &Pose3, found: &Pose3) -> Option<Pose3> {
        let moved = (found.translation.vector - prediction.translation.vector).norm();
        (self.recheck_distance > 0.0 && moved > self.recheck_distance)
            .then(|| Pose3::from_parts(prediction.translation, found.rotation))
    }

    /// Whether a recheck's cheap first pass ended at `cheap` in the basin of `found`
    /// ([`Self::recheck_basin`]); never when the basin is 0.
    #[must_use]
    pub fn in_basin(&self, cheap: &Pose3, found: &Pose3) -> bool {
        let apart = (cheap.translation.vector - found.translation.vector).norm();
        let turned = (cheap.rotation.inverse() * found.rotation).angle();
        self.recheck_basin > 0.0
            && apart <= self.recheck_basin
            && turned <= 0.2 * self.recheck_basin
    }
}

/// Whether the recheck's registration `other` replaces `found`: a finite pose that matched at
/// least as much of the scan with no larger RMS error.
pub(crate) fn replaces(other: &Alignment, found: &Alignment) -> bool {
    pose3_is_finite(&other.pose)
        && other.inlier_ratio >= found.inlier_ratio
        && other.rmse <= found.rmse
}

#[cfg(test)]
#[path = "tracker_tests.rs"]
mod tests;
