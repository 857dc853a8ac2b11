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
}

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
    /// Not far enough from the last keyframe: the pose was predicted from odometry.
    Tracked,
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
    },
}

/// Running totals of a [`GraphSlam`](super::GraphSlam).
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SlamReport {
    /// Scans given to `process`.
    pub scans: usize,
    /// Keyframes created.
    pub keyframes: usize,
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
    /// Non-finite points dropped from otherwise usable scans.
    pub dropped_points: usize,
    /// Keyframes where the registration was rejected and odometry kept.
    pub odometry_fallbacks: usize,
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
    /// Optimiser runs that returned an error (the graph was kept as it was).
    pub optimizer_failures: usize,
    /// Milliseconds of each `process` call (odometry path), in order.
    pub scan_ms: Vec<f64>,
    /// Milliseconds of each loop-closure step that had a candidate.
    pub loop_ms: Vec<f64>,
}

impl SlamReport {
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
        #[allow(
            clippy::cast_possible_truncation,
            clippy::cast_sign_loss,
            clippy::cast_precision_loss
        )]
        let rank = (q.clamp(0.0, 1.0) * sorted.len() as f64) as usize;
        sorted
            .get(rank.min(sorted.len().saturating_sub(1)))
            .copied()
            .unwrap_or(0.0)
    }
}
