//! Tracking health of a SLAM run, from the engine's report: scans that fell back to a
//! prediction (by reason), scans recovered on a second try, losses of track, odometry faults,
//! optimiser failures and skipped scans by reason. [`print_tracking_health`] is the one place
//! that prints them, and warns when more than [`LOST_SHARE`] of the scans fell back or tracking
//! was lost.

use std::collections::BTreeMap;

use anyhow::Result;
use serde::Serialize;
use slam_core::SlamReport;

use crate::out;

/// Share of the scans that may fall back before the run is said to have lost tracking: 5 %.
pub const LOST_SHARE: f64 = 0.05;

/// Skipped scans by reason, one line per `SkipReason`.
#[must_use]
pub fn skip_reasons(report: &SlamReport) -> Vec<(&'static str, usize)> {
    vec![
        ("out-of-order stamp", report.skipped_out_of_order),
        ("non-finite odometry", report.skipped_non_finite_odometry),
        ("too few points", report.skipped_too_few_points),
        ("preparation failed", report.skipped_preparation),
        ("awaiting velocity", report.skipped_awaiting_velocity),
        ("non-finite pose", report.skipped_non_finite_pose),
    ]
}

/// `reasons` whose count is not zero.
fn by_reason(reasons: Vec<(&'static str, usize)>) -> BTreeMap<String, usize> {
    reasons
        .into_iter()
        .filter(|&(_, n)| n > 0)
        .map(|(reason, n)| (reason.to_owned(), n))
        .collect()
}

/// The tracking health of a run (also written to `summary.json` as `tracking`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HealthSummary {
    /// Scans given to the engine.
    pub scans: usize,
    /// Scans registered and taken by the odometry's tracker.
    pub tracked: usize,
    /// Of those, scans taken only on a second try (the widest reach or a turned heading).
    pub recovered: usize,
    /// Scans whose registration was not taken: the prediction (odometry or constant velocity)
    /// was kept.
    pub fallbacks: usize,
    /// The fallbacks by reason (`FallbackReason::name`).
    pub fallbacks_by_reason: BTreeMap<String, usize>,
    /// `fallbacks / scans` (0 to 1).
    pub fallback_share: f64,
    /// Times the tracker fell back on several scans in a row (tracking lost).
    pub losses: usize,
    /// Whether the share passed [`LOST_SHARE`] or tracking was lost: the map is not to be
    /// trusted everywhere.
    pub lost: bool,
    /// Odometry steps the registration contradicted (the robot's odometry was wrong there).
    pub odometry_faults: usize,
    /// LiDAR-only scans whose turn since the last one the gyro predicted.
    pub gyro_predictions: usize,
    /// LiDAR-only scans predicted without a gyro, by how much of the last step's turn the
    /// prediction repeated (`held`, `half`, `all`).
    pub turn_shares: BTreeMap<String, usize>,
    /// Optimiser runs that failed (the graph was kept as it was).
    pub optimizer_failures: usize,
    /// Local maps the odometry's backend could not build (those scans fell back with
    /// `no_target`).
    pub local_map_failures: usize,
    /// Skipped scans.
    pub skipped: usize,
    /// Skipped scans by reason (reasons with none left out).
    pub skipped_by_reason: BTreeMap<String, usize>,
}

impl HealthSummary {
    /// The health of a run from the engine's `report`.
    #[must_use]
    pub fn new(report: &SlamReport) -> Self {
        let tracking = &report.tracking;
        let fallbacks = tracking.fallbacks.total();
        let fallback_share = if report.scans == 0 {
            0.0
        } else {
            fallbacks as f64 / report.scans as f64
        };
        let skips = skip_reasons(report);
        let skipped = skips.iter().map(|&(_, n)| n).sum();
        Self {
            scans: report.scans,
            tracked: tracking.tracked,
            recovered: tracking.recovered,
            fallbacks,
            fallbacks_by_reason: tracking
                .fallbacks
                .nonzero()
                .into_iter()
                .map(|(reason, n)| (reason.name().to_owned(), n))
                .collect(),
            fallback_share,
            losses: tracking.losses,
            lost: fallback_share > LOST_SHARE || tracking.losses > 0,
            odometry_faults: report.odometry_faults,
            gyro_predictions: report.gyro_predictions,
            turn_shares: ["held", "half", "all"]
                .into_iter()
                .zip(report.turn_shares)
                .map(|(share, n)| (share.to_owned(), n))
                .collect(),
            optimizer_failures: report.optimizer_failures,
            local_map_failures: report.local_map_failures,
            skipped,
            skipped_by_reason: by_reason(skips),
        }
    }

    /// The `warning:` line when tracking was lost, or more than [`LOST_SHARE`] of the scans fell
    /// back.
    #[must_use]
    pub fn warning(&self) -> Option<String> {
        self.lost.then(|| {
            format!(
                "warning: tracking failed on {:.1} % of the scans ({} of {}: {}) and was lost {} times: on those scans the pose is a prediction, not a registration, so the trajectory and the map are not to be trusted there",
                100.0 * self.fallback_share,
                self.fallbacks,
                self.scans,
                listed(&self.fallbacks_by_reason),
                self.losses,
            )
        })
    }
}

/// `count reason, count reason` of a map, or `none`.
fn listed(map: &BTreeMap<String, usize>) -> String {
    if map.is_empty() {
        return "none".to_owned();
    }
    map.iter()
        .map(|(reason, n)| format!("{n} {reason}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Prints the run's tracking health from the engine's `report`: a `tracking` and a `skipped`
/// line on stdout, and on stderr a `warning:` when tracking was lost or more than
/// [`LOST_SHARE`] of the scans fell back. Returns what it printed, for `summary.json`.
///
/// # Errors
/// [`StdoutClosed`](crate::StdoutClosed) when stdout was closed.
pub fn print_tracking_health(report: &SlamReport) -> Result<HealthSummary> {
    let health = HealthSummary::new(report);
    let [held, half, all] = report.turn_shares;
    out!(
        "tracking    {} of {} scans fell back ({:.1} %: {}), {} recovered on a second try, lost {} times; {} odometry faults; {} turns predicted by the gyro; last turn repeated {}/{}/{} times (held/half/all); {} optimiser failures; {} local maps not built",
        health.fallbacks,
        health.scans,
        100.0 * health.fallback_share,
        listed(&health.fallbacks_by_reason),
        health.recovered,
        health.losses,
        health.odometry_faults,
        health.gyro_predictions,
        held,
        half,
        all,
        health.optimizer_failures,
        health.local_map_failures
    )?;
    out!(
        "skipped     {} scans ({})",
        health.skipped,
        listed(&health.skipped_by_reason)
    )?;
    if let Some(warning) = health.warning() {
        eprintln!("{warning}");
    }
    Ok(health)
}

#[cfg(test)]
mod tests {
    use super::*;
    use slam_core::tracking::FallbackReason;

    #[test]
    fn fallbacks_add_up_and_pass_the_share() {
        let mut report = SlamReport {
            scans: 200,
            skipped_too_few_points: 2,
            ..SlamReport::default()
        };
        for _ in 0..7 {
            report.tracking.fallbacks.add(FallbackReason::TooFewInliers);
        }
        for _ in 0..4 {
            report.tracking.fallbacks.add(FallbackReason::NoTarget);
        }
        let h = HealthSummary::new(&report);
        assert_eq!(h.fallbacks, 11);
        assert!((h.fallback_share - 0.055).abs() < 1e-12 && h.lost);
        assert_eq!(h.fallbacks_by_reason["too_few_inliers"], 7);
        assert_eq!(h.fallbacks_by_reason["no_target"], 4);
        assert_eq!((h.skipped, h.skipped_by_reason["too few points"]), (2, 2));
        let warning = h.warning().unwrap();
        assert!(
            warning.starts_with("warning: tracking failed on 5.5 % of the scans (11 of 200")
                && warning.contains("7 too_few_inliers")
                && warning.contains("not to be trusted"),
            "{warning}"
        );
        // 10 of 200 is 5 %: not more than the share ...
        report.tracking.fallbacks.no_target = 3;
        let h = HealthSummary::new(&report);
        assert!(!h.lost && h.warning().is_none());
        // ... unless tracking was lost.
        report.tracking.losses = 1;
        assert!(HealthSummary::new(&report).lost);
        let h = HealthSummary::new(&SlamReport::default());
        assert!(!h.lost && h.fallbacks_by_reason.is_empty() && h.skipped_by_reason.is_empty());
    }
}
