//! What the engine did: counts, skipped input and timings.

/// Why a scan was skipped (bad input is counted, never fatal).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub enum SkipReason {
    /// The stamp is not finite or not later than the previous scan's.
    OutOfOrderStamp,
    /// The odometry or calibration pose has a non-finite value.
    NonFiniteOdometry,
    /// Too few finite points.
    TooFewPoints,
    /// The registrator could not prepare the scan (for example no features).
    PreparationFailed,
    /// The first scan whose points have different times waits for a second one: deskewing needs the
    /// velocity, and an unskewed first keyframe would anchor the map (and every loop closure
    /// back to it) on a distorted scan.
    AwaitingVelocity,
    /// The keyframe's pose, or its step from the previous keyframe, is not finite although
    /// every input number is (odometry so large that composing it overflows).
    NonFinitePose,
}

use crate::tracking::TrackingHealth;

/// What happened to one scan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ScanOutcome {
    /// The scan became keyframe `id`, registered against the local map.
    Keyframe {
        /// Node id in the pose graph.
        id: u64,
        /// Whether the registration was used (false: the odometry prediction was kept).
        registered: bool,
    },
    /// Not far enough from the last keyframe for a new one: the pose rides on the last
    /// keyframe.
    Tracked {
        /// Whether the scan was registered (without odometry; false: the odometry's or the
        /// constant-velocity prediction was kept).
        registered: bool,
    },
    /// The scan was skipped.
    Skipped(SkipReason),
}

/// What one loop-closure step did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LoopOutcome {
    /// No candidate was waiting.
    Idle,
    /// A loop between two keyframes was accepted and the graph optimised.
    Closed {
        /// The older keyframe.
        from: u64,
        /// The newer keyframe.
        to: u64,
        /// Mean squared error of the coarse alignment (m^2).
        mean_squared_error: f64,
    },
    /// The candidate was rejected.
    Rejected {
        /// The older keyframe.
        from: u64,
        /// The newer keyframe.
        to: u64,
        /// Why.
        reason: LoopRejection,
    },
}

/// Why a loop candidate was not closed (the checks in the order a candidate meets them).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub enum LoopRejection {
    /// The coarse check's target (the old keyframe's neighbourhood) could not be built.
    CoarseTarget,
    /// The coarse alignment returned an error.
    CoarseAlignment,
    /// The coarse alignment did not converge, or ended at a non-finite pose.
    CoarseNotConverged,
    /// The coarse alignment's mean squared error is above
    /// [`GraphSlamConfig::loop_max_mean_squared_error`](super::GraphSlamConfig).
    CoarseMismatch,
    /// The refinement's target could not be built.
    RefineTarget,
    /// The refinement returned an error.
    RefineAlignment,
    /// The refinement did not converge, or ended at a non-finite pose.
    RefineNotConverged,
    /// The refinement moved the coarse pose further than
    /// [`GraphSlamConfig::loop_max_refine_shift`](super::GraphSlamConfig).
    RefineShift,
    /// The loop would move the new keyframe further than the walk since the old one could have
    /// drifted ([`GraphSlamConfig::loop_max_drift_rate`](super::GraphSlamConfig)): a look-alike
    /// place.
    BeyondDrift,
    /// The loop would move the new keyframe up or down further than the walk since the old one
    /// could have drifted in height
    /// ([`GraphSlamConfig::loop_max_height_drift_rate`](super::GraphSlamConfig)): a floor that
    /// looks like another.
    BeyondHeightDrift,
    /// The pose graph refused the edge (a non-finite measurement or information).
    EdgeRefused,
}

impl LoopRejection {
    /// Every reason, in the order a candidate meets the checks.
    pub const ALL: [Self; 11] = [
        Self::CoarseTarget,
        Self::CoarseAlignment,
        Self::CoarseNotConverged,
        Self::CoarseMismatch,
        Self::RefineTarget,
        Self::RefineAlignment,
        Self::RefineNotConverged,
        Self::RefineShift,
        Self::BeyondDrift,
        Self::BeyondHeightDrift,
        Self::EdgeRefused,
    ];

    /// A short name for reports (`beyond_drift`, ...).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::CoarseTarget => "coarse_target",
            Self::CoarseAlignment => "coarse_alignment",
            Self::CoarseNotConverged => "coarse_not_converged",
            Self::CoarseMismatch => "coarse_mismatch",
            Self::RefineTarget => "refine_target",
            Self::RefineAlignment => "refine_alignment",
            Self::RefineNotConverged => "refine_not_converged",
            Self::RefineShift => "refine_shift",
            Self::BeyondDrift => "beyond_drift",
            Self::BeyondHeightDrift => "beyond_height_drift",
            Self::EdgeRefused => "edge_refused",
        }
    }
}

/// Loop candidates rejected, counted by [`LoopRejection`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct LoopRejections {
    counts: [usize; LoopRejection::ALL.len()],
}

impl LoopRejections {
    /// Counts one rejection.
    pub fn add(&mut self, reason: LoopRejection) {
        self.counts[reason as usize] += 1;
    }

    /// Rejections for `reason`.
    #[must_use]
    pub fn get(&self, reason: LoopRejection) -> usize {
        self.counts[reason as usize]
    }

    /// Rejections for any reason.
    #[must_use]
    pub fn total(&self) -> usize {
        self.counts.iter().sum()
    }

    /// The reasons that occurred, with their counts, in [`LoopRejection::ALL`]'s order.
    #[must_use]
    pub fn nonzero(&self) -> Vec<(LoopRejection, usize)> {
        LoopRejection::ALL
            .iter()
            .map(|&r| (r, self.get(r)))
            .filter(|&(_, n)| n > 0)
            .collect()
    }
}

/// Running totals of a [`GraphSlam`](super::GraphSlam).
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SlamReport {
    /// Scans given to `process`.
    pub scans: usize,
    /// Keyframes created.
    pub keyframes: usize,
    /// Keyframes that kept their whole scan at the map's voxel: all of them but those of dense
    /// scans within [`GraphSlamConfig::keyframe_scan_spacing`](super::GraphSlamConfig) of the
    /// last one that did.
    #[cfg_attr(feature = "serde", serde(default))]
    pub whole_scans: usize,
    /// Skipped scans: out-of-order stamps.
    pub skipped_out_of_order: usize,
    /// Skipped scans: non-finite odometry.
    pub skipped_non_finite_odometry: usize,
    /// Skipped scans: too few points.
    pub skipped_too_few_points: usize,
    /// Skipped scans: preparation failed.
    pub skipped_preparation: usize,
    /// Skipped scans: a first timed scan waiting for the velocity to deskew it.
    pub skipped_awaiting_velocity: usize,
    /// Non-finite points dropped from otherwise usable scans, and finite ones too far out for
    /// the map's voxel keys (2^62 voxels from the sensor: garbled returns, not measurements).
    pub dropped_points: usize,
    /// How the odometry's registrations went: scans tracked, recovered on a second try, fallbacks
    /// to the prediction by reason, losses of track (see [`TrackingHealth`]).
    pub tracking: TrackingHealth,
    /// Keyframes whose odometry step the registration contradicted: the step ended more than
    /// [`TrackerConfig::arbitration_distance`](crate::tracking::TrackerConfig) from the
    /// constant-velocity extrapolation, and the scan registered from the extrapolation fitted
    /// better than from the odometry's guess (or only it registered), so that pose was kept.
    pub odometry_faults: usize,
    /// LiDAR-only scans whose predicted orientation came from the gyro
    /// ([`ScanInput::gyro_orientation`](crate::ScanInput::gyro_orientation)) instead of the
    /// constant velocity.
    pub gyro_predictions: usize,
    /// LiDAR-only scans predicted from the last step's motion (without a gyro), by the share of
    /// its turn the prediction repeated: none (heading held), half, all (constant velocity);
    /// see [`TurnPersistence`](crate::tracking::TurnPersistence).
    pub turn_shares: [usize; 3],
    /// Skipped scans: a non-finite keyframe pose ([`SkipReason::NonFinitePose`]).
    pub skipped_non_finite_pose: usize,
    /// Registered scans that rode on a keyframe already in the map instead of making a new one
    /// ([`GraphSlamConfig::revisit_radius`](super::GraphSlamConfig::revisit_radius)).
    pub revisits: usize,
    /// Loop candidates tried.
    pub loops_attempted: usize,
    /// Loops accepted.
    pub loops_closed: usize,
    /// Loop candidates that came from place recognition (none found by position).
    pub place_candidates: usize,
    /// Loops accepted among those.
    pub place_loops_closed: usize,
    /// Keyframe scans the place recognizer refused (too few points in its range).
    pub place_refusals: usize,
    /// Loop candidates rejected, by reason (look-alike places refused as beyond the drift a
    /// walk could gather are [`LoopRejection::BeyondDrift`]).
    pub loop_rejections: LoopRejections,
    /// Local maps the odometry's backend could not build from the keyframes (the scan then fell
    /// back to its prediction, counted in [`SlamReport::tracking`] as having no target).
    pub local_map_failures: usize,
    /// Keyframe clouds the keyframe store's file refused (kept in memory instead; see
    /// [`GraphSlam::with_keyframe_store`](crate::GraphSlam::with_keyframe_store)).
    pub keyframe_store_failures: usize,
    /// Loop edges the optimiser weighted out in its last run (an optimiser that decides
    /// outliers, see [`Optimizer::edge_weights`](crate::Optimizer::edge_weights); 0 with one
    /// that keeps every edge): accepted by the geometric check, yet inconsistent with the rest
    /// of the graph, so they do not bend the map.
    pub loops_weighted_out: usize,
    /// Optimiser runs that returned an error (the graph was kept as it was).
    pub optimizer_failures: usize,
    /// Milliseconds of each `process` call (odometry path), in order: the most recent ones, at
    /// most [`SlamReport::TIMES_KEPT`] (the oldest half is dropped when full, so a long run's
    /// memory stays bounded).
    pub scan_ms: Vec<f64>,
    /// Milliseconds of each loop-closure step that had a candidate (bounded as `scan_ms`).
    pub loop_ms: Vec<f64>,
}

impl SlamReport {
    /// Scans whose registration was not taken (the prediction kept), for any reason.
    #[must_use]
    pub fn fallbacks(&self) -> usize {
        self.tracking.fallbacks.total()
    }

    /// Most timings kept in [`SlamReport::scan_ms`] and [`SlamReport::loop_ms`]: 65,536 (3.6 h of
    /// scans at 5 Hz). The statistics below are over the kept ones.
    pub const TIMES_KEPT: usize = 1 << 16;

    /// Append `ms` to `times`, first dropping the oldest half when [`SlamReport::TIMES_KEPT`]
    /// are kept (amortised O(1)).
    pub(crate) fn record(times: &mut Vec<f64>, ms: f64) {
        if times.len() >= Self::TIMES_KEPT {
            times.drain(..Self::TIMES_KEPT / 2);
        }
        times.push(ms);
    }

    /// Mean of [`SlamReport::scan_ms`].
    #[must_use]
    pub fn mean_scan_ms(&self) -> f64 {
        if self.scan_ms.is_empty() {
            0.0
        } else {
            self.scan_ms.iter().sum::<f64>() / self.scan_ms.len() as f64
        }
    }

    /// Maximum of [`SlamReport::scan_ms`].
    #[must_use]
    pub fn max_scan_ms(&self) -> f64 {
        self.scan_ms.iter().copied().fold(0.0, f64::max)
    }

    /// The `q` quantile (0 to 1, nearest rank) of [`SlamReport::scan_ms`]; 0 without scans.
    #[must_use]
    pub fn scan_ms_quantile(&self, q: f64) -> f64 {
        let mut sorted = self.scan_ms.clone();
        sorted.sort_by(f64::total_cmp);
        let rank = (q.clamp(0.0, 1.0) * sorted.len() as f64) as usize;
        sorted
            .get(rank.min(sorted.len().saturating_sub(1)))
            .copied()
            .unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::SlamReport;

    #[test]
    fn timings_stay_bounded_and_keep_the_latest() {
        let mut times = Vec::new();
        let n = 3 * SlamReport::TIMES_KEPT + 17;
        for i in 0..n {
            SlamReport::record(&mut times, i as f64);
            assert!(times.len() <= SlamReport::TIMES_KEPT);
        }
        // The kept ones are the latest, in order.
        let expected: Vec<f64> = (n - times.len()..n).map(|i| i as f64).collect();
        assert_eq!(times, expected);
        assert!(times.len() >= SlamReport::TIMES_KEPT / 2);
    }
}
