//! `summary.json` of the `slam` example: what was run, what the engine did (scans, keyframes,
//! skips, loops, tracking health), its times and, with ground truth, its accuracy. The lines
//! the example prints are made from these same values, so the two agree.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, Result};
use serde::Serialize;

use slam_core::{LoopRejection, SlamReport};
use spot_adapter::eval::{KittiRpe, TrajectoryEvaluation};

use crate::health::HealthSummary;

/// Everything a `slam` run reports.
#[derive(Clone, Debug, Serialize)]
pub struct SlamSummary {
    /// What was mapped.
    pub input: Input,
    /// The registration backend (`p2plane` or `loam`).
    pub registration: String,
    /// Point-to-plane: the voxel (metres) the tracker's local map was kept at
    /// (`--tracker-map-voxel`, or the tracker's own for the sensor's density:
    /// `IcpConfig::target_voxel` after `MapRegistrator::fit_to_scan`); `None` for LOAM.
    pub tracker_map_voxel: Option<f32>,
    /// Scans given to the engine.
    pub scans: usize,
    /// Keyframes created.
    pub keyframes: usize,
    /// Keyframes that kept their whole scan for the map (`SlamReport::whole_scans`: every one,
    /// but for dense scans one a metre).
    pub whole_scans: usize,
    /// Registered scans that rode on a keyframe already in the map instead of making one
    /// (`SlamReport::revisits`).
    pub revisits: usize,
    /// Loop closure.
    pub loops: Loops,
    /// Fallbacks, faults and skipped scans, by reason.
    pub tracking: HealthSummary,
    /// Times.
    pub time: Times,
    /// Points the reader removed (`None` for the simulator).
    pub points: Option<Points>,
    /// Accuracy against the ground truth, when it is known.
    pub accuracy: Option<Accuracy>,
    /// The floors the walk stood on, lowest first (`gridmap::FloorLevels` over the scans'
    /// poses): one for a walk on one floor, none for a walk too short to cover 5 m on a level.
    pub floors: Vec<FloorSummary>,
    /// The stairs the walk took between the floors, as links of the floors' grids (empty on
    /// one floor).
    pub stairs: Vec<StairsSummary>,
}

/// A flight of stairs the walk took (`spot_adapter::nav::stairs_links`): where it was entered
/// on the lower floor and left on the upper one (the walk's last and first cells free on those
/// floors' grids), and the walk between.
#[derive(Clone, Debug, Serialize)]
pub struct StairsSummary {
    /// The floor of its foot (an index into `floors`).
    pub lower_floor: usize,
    /// The floor of its top.
    pub upper_floor: usize,
    /// Its foot's cell centre (metres, the map frame).
    pub foot_m: [f64; 2],
    /// Its top's cell centre.
    pub top_m: [f64; 2],
    /// The walk from foot to top (metres).
    pub length_m: f64,
}

/// One floor of the walk.
#[derive(Clone, Debug, Serialize)]
pub struct FloorSummary {
    /// The median height of the scans' poses on it (metres, the map frame).
    pub height_m: f64,
    /// How far the walk went on it (metres, horizontally).
    pub walked_m: f64,
    /// The scans taken on it.
    pub scans: usize,
    /// The keyframes at its height.
    pub keyframes: usize,
    /// Cells of its grid marked as stairs (the flights rising from it and its stairwells);
    /// `None` without a grid per floor.
    pub stairs_cells: Option<usize>,
}

/// What was mapped.
#[derive(Clone, Debug, Serialize)]
pub struct Input {
    /// `recording` or `simulator`.
    pub source: String,
    /// The recording's path.
    pub path: Option<String>,
    /// What the recording holds, as printed first (the simulator: building seed and options).
    pub description: String,
    /// Where the odometry came from: `recording`, `simulated legs` or `LiDAR-only`.
    pub odometry: String,
    /// Where the ground truth came from (`--ground-truth FILE (format, poses)`, the
    /// recording's, the simulator's), `None` without one.
    pub ground_truth: Option<String>,
}

/// Loop closure counts.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Loops {
    /// Candidates tried.
    pub tried: usize,
    /// Loops accepted.
    pub closed: usize,
    /// Candidates found by appearance (place recognition).
    pub appearance_candidates: usize,
    /// Loops accepted among those.
    pub by_appearance: usize,
    /// Loops refused because they would move the robot further than it can have drifted.
    pub refused_beyond_drift: usize,
    /// Candidates rejected, by reason (`coarse_mismatch`, `beyond_drift`, ...; the reasons that
    /// occurred).
    pub rejected: BTreeMap<&'static str, usize>,
    /// Loops the back end weighted out in its last run.
    pub weighted_out: usize,
    /// Keyframe scans the place recognizer refused (too few points in its range).
    pub place_refusals: usize,
}

impl Loops {
    /// The counts of `report`.
    #[must_use]
    pub fn new(report: &SlamReport) -> Self {
        Self {
            tried: report.loops_attempted,
            closed: report.loops_closed,
            appearance_candidates: report.place_candidates,
            by_appearance: report.place_loops_closed,
            refused_beyond_drift: report.loop_rejections.get(LoopRejection::BeyondDrift),
            rejected: report
                .loop_rejections
                .nonzero()
                .into_iter()
                .map(|(reason, n)| (reason.name(), n))
                .collect(),
            weighted_out: report.loops_weighted_out,
            place_refusals: report.place_refusals,
        }
    }
}

/// Times (milliseconds unless named otherwise).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Times {
    /// The engine's time a scan (its `process` call, the odometry path): mean.
    pub scan_ms_mean: f64,
    /// 99th percentile of the same.
    pub scan_ms_p99: f64,
    /// Largest.
    pub scan_ms_max: f64,
    /// The slowest scan (1-based).
    pub slowest_scan: usize,
    /// Loop-closure steps that had a candidate.
    pub loop_steps: usize,
    /// The slowest of them.
    pub loop_ms_max: f64,
    /// Wall-clock seconds of feeding the scans to the engine (reading or simulating them
    /// included; the evaluation and the outputs after it not).
    pub seconds: f64,
}

impl Times {
    /// The times of `report` and the run's wall-clock `seconds`.
    #[must_use]
    pub fn new(report: &SlamReport, seconds: f64) -> Self {
        let slowest_scan = report
            .scan_ms
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .map_or(0, |(i, _)| i + 1);
        Self {
            scan_ms_mean: report.mean_scan_ms(),
            scan_ms_p99: report.scan_ms_quantile(0.99),
            scan_ms_max: report.max_scan_ms(),
            slowest_scan,
            loop_steps: report.loop_ms.len(),
            loop_ms_max: report.loop_ms.iter().copied().fold(0.0, f64::max),
            seconds,
        }
    }
}

/// Points the reader removed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Points {
    /// No-return points (zeros, closer than `--min-range`).
    pub no_return: usize,
    /// Non-finite points.
    pub non_finite: usize,
}

/// Accuracy of the body trajectory against the ground truth (metres unless named otherwise).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Accuracy {
    /// Absolute trajectory error: translation RMSE after the best rigid (SE(3), Umeyama)
    /// alignment, as `evo_ape tum gt est -a`.
    pub ate_m: f64,
    /// Poses matched by stamp (within 0.01 s) and compared.
    pub ate_pairs: usize,
    /// The truth's path length over the matched poses.
    pub path_length_m: f64,
    /// Distance between where the estimate and the truth end, their first poses aligned.
    pub end_point_error_m: f64,
    /// The same in % of the path length (`None` for a path of length 0).
    pub end_point_drift_percent: Option<f64>,
    /// How much higher the estimate ends than the truth, their first poses aligned (signed).
    pub height_drift_m: f64,
    /// The estimate's gap between its first and last positions minus the truth's (for a run
    /// that returns to its start, the loop end-point error).
    pub loop_end_point_error_m: f64,
    /// Segment drift over 10 to 50 m (the indoor ladder, every 10th pose), in %.
    pub segment_drift_percent: Option<f64>,
    /// KITTI's RPE: the devkit's mean translation error over segment length, in % (`None`
    /// when the truth did not move).
    pub rpe_percent: Option<f64>,
    /// KITTI's mean rotation error over segment length, degrees per 100 m.
    pub rpe_rotation_deg_per_100m: Option<f64>,
    /// The segment lengths the RPE is over (KITTI's 100-800 m that fit, or that ladder scaled
    /// down by a power of ten for a path no longer than 100 m).
    pub rpe_segment_lengths_m: Vec<f64>,
    /// Whether those are KITTI's own lengths.
    pub rpe_kitti_lengths: bool,
    /// Segments the RPE is over.
    pub rpe_segments: usize,
    /// Steps between consecutive matched poses.
    pub steps: usize,
    /// Steps whose rotation error (against the truth's step) passes 2 degrees.
    pub steps_over_2_deg: usize,
    /// Steps whose rotation error passes 5 degrees.
    pub steps_over_5_deg: usize,
    /// The largest step rotation error (degrees).
    pub step_rotation_error_max_deg: f64,
}

impl Accuracy {
    /// The figures of an evaluation.
    #[must_use]
    pub fn new(e: &TrajectoryEvaluation) -> Self {
        let path = e.end_point.path_length;
        Self {
            ate_m: e.ate.rmse,
            ate_pairs: e.ate.pairs,
            path_length_m: path,
            end_point_error_m: e.end_point.end_point_error,
            end_point_drift_percent: (path > 0.0)
                .then(|| 100.0 * e.end_point.end_point_error / path),
            height_drift_m: e.height_drift,
            loop_end_point_error_m: e.loop_end_point_error,
            segment_drift_percent: e.segments.as_ref().map(|s| 100.0 * s.translation),
            rpe_percent: e.rpe.as_ref().map(|r| r.translation_percent),
            rpe_rotation_deg_per_100m: e.rpe.as_ref().map(|r| r.rotation_deg_per_100m),
            rpe_segment_lengths_m: e
                .rpe
                .as_ref()
                .map(|r| r.lengths.clone())
                .unwrap_or_default(),
            rpe_kitti_lengths: e.rpe.as_ref().is_some_and(KittiRpe::is_kitti_ladder),
            rpe_segments: e.rpe.as_ref().map_or(0, |r| r.segments),
            steps: e.step_rotation_errors.len(),
            steps_over_2_deg: e.steps_over(2.0),
            steps_over_5_deg: e.steps_over(5.0),
            step_rotation_error_max_deg: e.max_step_rotation_error_deg(),
        }
    }
}

/// Writes `summary` as pretty-printed JSON to `path`.
///
/// # Errors
/// When the file cannot be written (the error names it).
pub fn write_summary(path: &Path, summary: &SlamSummary) -> Result<()> {
    let json = serde_json::to_string_pretty(summary)?;
    std::fs::write(path, json + "\n").with_context(|| format!("writing {}", path.display()))
}
