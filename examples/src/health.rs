//! Tracking health of a SLAM run, from the engine's report and the LiDAR-only odometry's own
//! count: scans that fell back to a prediction (tracking lost there), odometry faults, optimiser
//! failures and skipped scans, each by reason where the report gives one.
//! [`print_tracking_health`] is the one place that prints them, and warns when more than
//! [`LOST_SHARE`] of the scans fell back.
//!
//! A reason counter added to `SlamReport` is one line in [`engine_fallback_reasons`],
//! [`fault_reasons`] or [`skip_reasons`]: the printed lines and `summary.json` follow.

use std::collections::BTreeMap;

use anyhow::Result;
use serde::Serialize;
use slam_core::SlamReport;

use crate::out;

/// Share of the scans that may fall back before the run is said to have lost tracking: 5 %.
pub const LOST_SHARE: f64 = 0.05;

/// What the engine's fallbacks are counted under while the report gives no finer reason.
const REJECTED: &str = "registration rejected";

/// What the LiDAR-only odometry's fallbacks are counted under.
const SCAN_TO_SCAN: &str = "scan-to-scan registration failed or diverged";

/// The engine's odometry fallbacks by reason, as the report breaks them down (none yet: every
/// fallback is counted under "registration rejected" by [`TrackingHealth::new`]). Add a line
/// per reason counter of `SlamReport`, e.g. `("no convergence", report.fallbacks_diverged),`.
#[must_use]
pub fn engine_fallback_reasons(report: &SlamReport) -> Vec<(&'static str, usize)> {
    let _ = report;
    vec![
        // ("no convergence", report.fallbacks_diverged),
    ]
}

/// The engine's odometry faults by reason (none yet: see [`engine_fallback_reasons`]).
#[must_use]
pub fn fault_reasons(report: &SlamReport) -> Vec<(&'static str, usize)> {
    let _ = report;
    vec![
        // ("step contradicted by registration", report.faults_contradicted),
    ]
}

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

/// `reasons` whose count is not zero, with what they leave of `total` under `rest`.
fn by_reason(
    reasons: Vec<(&'static str, usize)>,
    total: usize,
    rest: &str,
) -> BTreeMap<String, usize> {
    let mut map: BTreeMap<String, usize> = reasons
        .into_iter()
        .filter(|&(_, n)| n > 0)
        .map(|(reason, n)| (reason.to_owned(), n))
        .collect();
    let listed: usize = map.values().sum();
    if total > listed {
        *map.entry(rest.to_owned()).or_default() += total - listed;
    }
    map
}

/// The tracking health of a run (also written to `summary.json` as `tracking`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TrackingHealth {
    /// Scans given to the engine.
    pub scans: usize,
    /// Keyframes where the engine's registration was rejected and the prediction kept.
    pub engine_fallbacks: usize,
    /// Scans where the LiDAR-only scan-to-scan odometry kept its constant-velocity guess
    /// (`None` when the run had odometry).
    pub scan_to_scan_fallbacks: Option<usize>,
    /// Both kinds of fallback by reason.
    pub fallbacks_by_reason: BTreeMap<String, usize>,
    /// `(engine + scan-to-scan fallbacks) / scans` (0 to 1, may pass 1 when both fall back on
    /// the same scans).
    pub fallback_share: f64,
    /// Whether the share passed [`LOST_SHARE`]: tracking was lost on too many scans.
    pub lost: bool,
    /// Odometry steps the registration contradicted (the robot's odometry was wrong there).
    pub odometry_faults: usize,
    /// Odometry faults by reason.
    pub faults_by_reason: BTreeMap<String, usize>,
    /// Optimiser runs that failed (the graph was kept as it was).
    pub optimizer_failures: usize,
    /// Skipped scans.
    pub skipped: usize,
    /// Skipped scans by reason (reasons with none left out).
    pub skipped_by_reason: BTreeMap<String, usize>,
}

impl TrackingHealth {
    /// The health of a run from the engine's `report` and the scan-to-scan odometry's count of
    /// fallbacks (when it ran).
    #[must_use]
    pub fn new(report: &SlamReport, scan_to_scan_fallbacks: Option<usize>) -> Self {
        let mut fallbacks_by_reason = by_reason(
            engine_fallback_reasons(report),
            report.odometry_fallbacks,
            REJECTED,
        );
        if let Some(n) = scan_to_scan_fallbacks.filter(|&n| n > 0) {
            fallbacks_by_reason.insert(SCAN_TO_SCAN.to_owned(), n);
        }
        let fallbacks = report.odometry_fallbacks + scan_to_scan_fallbacks.unwrap_or(0);
        let fallback_share = if report.scans == 0 {
            0.0
        } else {
            fallbacks as f64 / report.scans as f64
        };
        let skips = skip_reasons(report);
        let skipped = skips.iter().map(|&(_, n)| n).sum();
        Self {
            scans: report.scans,
            engine_fallbacks: report.odometry_fallbacks,
            scan_to_scan_fallbacks,
            fallbacks_by_reason,
            fallback_share,
            lost: fallback_share > LOST_SHARE,
            odometry_faults: report.odometry_faults,
            faults_by_reason: by_reason(fault_reasons(report), report.odometry_faults, "other"),
            optimizer_failures: report.optimizer_failures,
            skipped,
            skipped_by_reason: by_reason(skips, skipped, "other"),
        }
    }

    /// Engine and scan-to-scan fallbacks together.
    #[must_use]
    pub fn fallbacks(&self) -> usize {
        self.engine_fallbacks + self.scan_to_scan_fallbacks.unwrap_or(0)
    }

    /// The `warning:` line when tracking was lost on more than [`LOST_SHARE`] of the scans.
    #[must_use]
    pub fn warning(&self) -> Option<String> {
        self.lost.then(|| {
            format!(
                "warning: tracking was lost on {:.1} % of the scans ({} of {}, more than {:.0} %: {}): on those scans the pose is a prediction, not a registration, so the trajectory and the map are not to be trusted there",
                100.0 * self.fallback_share,
                self.fallbacks(),
                self.scans,
                100.0 * LOST_SHARE,
                listed(&self.fallbacks_by_reason)
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

/// Prints the run's tracking health from the engine's `report` (and the scan-to-scan
/// odometry's fallbacks, when it ran): a `tracking` and a `skipped` line on stdout, and on
/// stderr a `warning:` when more than [`LOST_SHARE`] of the scans fell back. Returns what it
/// printed, for `summary.json`.
///
/// # Errors
/// [`StdoutClosed`](crate::StdoutClosed) when stdout was closed.
pub fn print_tracking_health(
    report: &SlamReport,
    scan_to_scan_fallbacks: Option<usize>,
) -> Result<TrackingHealth> {
    let health = TrackingHealth::new(report, scan_to_scan_fallbacks);
    let scan_to_scan = health
        .scan_to_scan_fallbacks
        .map_or_else(String::new, |n| format!(" + {n} scan-to-scan"));
    out!(
        "tracking    {} of {} scans fell back ({:.1} %: {} engine{scan_to_scan}; {}); {} odometry faults ({}); {} optimiser failures",
        health.fallbacks(),
        health.scans,
        100.0 * health.fallback_share,
        health.engine_fallbacks,
        listed(&health.fallbacks_by_reason),
        health.odometry_faults,
        listed(&health.faults_by_reason),
        health.optimizer_failures
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

    #[test]
    fn fallbacks_add_up_and_pass_the_share() {
        let report = SlamReport {
            scans: 200,
            odometry_fallbacks: 4,
            skipped_too_few_points: 2,
            ..SlamReport::default()
        };
        let h = TrackingHealth::new(&report, Some(7));
        assert_eq!(h.fallbacks(), 11);
        assert!((h.fallback_share - 0.055).abs() < 1e-12 && h.lost);
        assert_eq!(h.fallbacks_by_reason[REJECTED], 4);
        assert_eq!(h.fallbacks_by_reason[SCAN_TO_SCAN], 7);
        assert_eq!((h.skipped, h.skipped_by_reason["too few points"]), (2, 2));
        let warning = h.warning().unwrap();
        assert!(
            warning.starts_with("warning: tracking was lost on 5.5 % of the scans (11 of 200")
                && warning.contains("4 registration rejected")
                && warning.contains("not to be trusted"),
            "{warning}"
        );
        // 10 of 200 is 5 %: not more than the share.
        let h = TrackingHealth::new(&report, Some(6));
        assert!(!h.lost && h.warning().is_none());
        let h = TrackingHealth::new(&SlamReport::default(), None);
        assert!(!h.lost && h.fallbacks_by_reason.is_empty() && h.skipped_by_reason.is_empty());
    }
}
