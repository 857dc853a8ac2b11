//! Why a scan was not tracked, and the counts a run's health is judged by.

/// Why a tracker fell back to its prediction instead of the registered pose.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub enum FallbackReason {
    /// There was nothing to register against (no local map yet, or it could not be built).
    NoTarget,
    /// Too few scan points found a partner within reach.
    TooFewCorrespondences,
    /// The correspondences did not determine a pose (singular or non-finite system).
    Degenerate,
    /// The backend refused the alignment for another reason (a bad setting or guess).
    RegistrationError,
    /// The alignment ended at a non-finite pose.
    NonFinitePose,
    /// Too small a share of the scan was matched at the end
    /// ([`TrackerConfig::min_inlier_ratio`](super::TrackerConfig::min_inlier_ratio)).
    TooFewInliers,
    /// The alignment moved the prediction farther than any recent prediction error explains
    /// ([`TrackerConfig::max_translation_correction`](super::TrackerConfig), and its rotation).
    CorrectionTooLarge,
}

impl FallbackReason {
    /// Every reason, in the order [`FallbackCounts`] lists them.
    pub const ALL: [Self; 7] = [
        Self::NoTarget,
        Self::TooFewCorrespondences,
        Self::Degenerate,
        Self::RegistrationError,
        Self::NonFinitePose,
        Self::TooFewInliers,
        Self::CorrectionTooLarge,
    ];

    /// A short name, as a summary file gives it (`too_few_inliers`).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::NoTarget => "no_target",
            Self::TooFewCorrespondences => "too_few_correspondences",
            Self::Degenerate => "degenerate",
            Self::RegistrationError => "registration_error",
            Self::NonFinitePose => "non_finite_pose",
            Self::TooFewInliers => "too_few_inliers",
            Self::CorrectionTooLarge => "correction_too_large",
        }
    }
}

impl std::fmt::Display for FallbackReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::NoTarget => "nothing to register against",
            Self::TooFewCorrespondences => "too few correspondences within reach",
            Self::Degenerate => "a degenerate alignment",
            Self::RegistrationError => "the registration refused the scan",
            Self::NonFinitePose => "a non-finite pose",
            Self::TooFewInliers => "too small a share of the scan matched",
            Self::CorrectionTooLarge => "a correction larger than the motion explains",
        })
    }
}

/// Fallbacks counted by reason.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FallbackCounts {
    /// [`FallbackReason::NoTarget`].
    pub no_target: usize,
    /// [`FallbackReason::TooFewCorrespondences`].
    pub too_few_correspondences: usize,
    /// [`FallbackReason::Degenerate`].
    pub degenerate: usize,
    /// [`FallbackReason::RegistrationError`].
    pub registration_error: usize,
    /// [`FallbackReason::NonFinitePose`].
    pub non_finite_pose: usize,
    /// [`FallbackReason::TooFewInliers`].
    pub too_few_inliers: usize,
    /// [`FallbackReason::CorrectionTooLarge`].
    pub correction_too_large: usize,
}

impl FallbackCounts {
    fn slot(&mut self, reason: FallbackReason) -> &mut usize {
        match reason {
            FallbackReason::NoTarget => &mut self.no_target,
            FallbackReason::TooFewCorrespondences => &mut self.too_few_correspondences,
            FallbackReason::Degenerate => &mut self.degenerate,
            FallbackReason::RegistrationError => &mut self.registration_error,
            FallbackReason::NonFinitePose => &mut self.non_finite_pose,
            FallbackReason::TooFewInliers => &mut self.too_few_inliers,
            FallbackReason::CorrectionTooLarge => &mut self.correction_too_large,
        }
    }

    /// Counts one fallback for `reason`.
    pub fn add(&mut self, reason: FallbackReason) {
        *self.slot(reason) += 1;
    }

    /// The count for `reason`.
    #[must_use]
    pub fn get(&self, reason: FallbackReason) -> usize {
        let mut copy = *self;
        *copy.slot(reason)
    }

    /// Fallbacks in all.
    #[must_use]
    pub fn total(&self) -> usize {
        FallbackReason::ALL.iter().map(|&r| self.get(r)).sum()
    }

    /// The reasons with a count, most frequent first.
    #[must_use]
    pub fn nonzero(&self) -> Vec<(FallbackReason, usize)> {
        let mut v: Vec<_> = FallbackReason::ALL
            .iter()
            .map(|&r| (r, self.get(r)))
            .filter(|&(_, n)| n > 0)
            .collect();
        v.sort_by_key(|&(_, n)| std::cmp::Reverse(n));
        v
    }
}

/// How tracking has gone: scans tracked, fallbacks by reason, losses of track.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct TrackingHealth {
    /// Scans registered and taken.
    pub tracked: usize,
    /// Of those, scans taken only on a second try (another guess, or the widest reach): the
    /// prediction alone would have lost them.
    pub recovered: usize,
    /// Scans that fell back to the prediction, by reason.
    pub fallbacks: FallbackCounts,
    /// Fallbacks in a row, up to now.
    pub consecutive_fallbacks: usize,
    /// Times tracking was lost: [`TrackerConfig::lost_after`](super::TrackerConfig::lost_after)
    /// fallbacks in a row (counted once per run of them).
    pub losses: usize,
    /// The reach of the last scan's coarse stage (metres; 0 when it had none).
    pub last_reach: f64,
}

impl TrackingHealth {
    /// The share of scans that fell back (0 to 1; 0 before any scan).
    #[must_use]
    pub fn fallback_ratio(&self) -> f64 {
        let fell = self.fallbacks.total();
        let all = fell + self.tracked;
        if all == 0 {
            0.0
        } else {
            fell as f64 / all as f64
        }
    }
}
