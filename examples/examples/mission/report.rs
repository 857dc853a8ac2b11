//! `summary.json` and every output file of the run.

use std::path::Path;

use anyhow::{Context, Result};
use serde::Serialize;
use slam_core::PointCloud;
use slam_core::io::{PlyEncoding, StampedPose, write_ply, write_tum};
use spot_nav_examples::out;
use spot_nav_examples::picture::{self, Overlay};

/// The mapping lap's figures (`summary.json`'s `mapping`, with `--lap`).
#[derive(Clone, Debug, Serialize)]
pub(crate) struct MappingSummary {
    pub(crate) scans: usize,
    pub(crate) keyframes: usize,
    pub(crate) loops_closed: usize,
    pub(crate) lap_length_m: f64,
    pub(crate) ate_m: f64,
    pub(crate) loop_end_point_error_m: f64,
    pub(crate) segment_drift_percent: Option<f64>,
    pub(crate) mean_ms_per_scan: f64,
    pub(crate) seconds: f64,
}

/// The exploration's figures (`summary.json`'s `exploration`).
#[derive(Clone, Debug, Serialize)]
pub(crate) struct ExplorationSummary {
    /// `complete` (no reachable frontier left) or `gave_up` (the scan budget ran out).
    pub(crate) outcome: &'static str,
    /// `information-gain`, `greedy` or `tour`.
    pub(crate) frontier_rule: String,
    /// Where the robot started (world frame, metres).
    pub(crate) start: [f64; 2],
    /// Share of the reachable floor (free at the navigator's inflation, connected to the
    /// start, on the simulator's floor plan) that the final grid knows free.
    pub(crate) coverage: f64,
    pub(crate) reachable_floor_m2: f64,
    /// Walked by the ground truth.
    pub(crate) walked_m: f64,
    /// Walked by the engine's estimate.
    pub(crate) estimated_walked_m: f64,
    pub(crate) scans: usize,
    pub(crate) keyframes: usize,
    pub(crate) loops_closed: usize,
    /// Of the body trajectory (optimised, every scan) after the best rigid alignment.
    pub(crate) ate_m: f64,
    /// Frontier decisions (a map rendered, a frontier picked, a navigator made).
    pub(crate) decisions: usize,
    pub(crate) decision_ms_mean: f64,
    pub(crate) decision_ms_max: f64,
    /// Decisions whose map was rendered afresh from every keyframe kept (the first, after a
    /// loop closure moved the keyframes, when the map grew by half); the others added the new
    /// keyframes only.
    pub(crate) full_renders: usize,
    /// The engine and the navigator on one scan, the decisions apart.
    pub(crate) cycle_ms_mean: f64,
    /// Why each frontier given up was (`no_path`, `blocked`, `lost`,
    /// `still_unknown_from_goal`).
    pub(crate) frontiers_given_up: Vec<&'static str>,
    /// Frontiers left with no reachable goal at the last decision.
    pub(crate) frontiers_unreachable: usize,
    /// Cells of every frontier on the final map (unreachable ones included).
    pub(crate) frontier_cells_left: usize,
    pub(crate) collisions: usize,
    pub(crate) seconds: f64,
}

/// One leg's figures (`summary.json`'s `goals`).
#[derive(Clone, Debug, Serialize)]
pub(crate) struct LegSummary {
    /// The goal in the map frame (metres).
    pub(crate) goal: [f64; 2],
    /// `arrived`, `no_path`, `blocked`, `lost` or `gave_up`.
    pub(crate) outcome: &'static str,
    /// Arrived and within 0.10 m of the goal by the ground truth.
    pub(crate) reached: bool,
    pub(crate) final_error_m: f64,
    pub(crate) collisions: usize,
    pub(crate) cycles: usize,
    pub(crate) walked_m: f64,
    /// Length of the shortest way on the building's true floor plan at the navigator's
    /// inflation and cells (`spot_adapter::sim::shortest_length`); `None` when there is none.
    pub(crate) shortest_m: Option<f64>,
    pub(crate) localisation_error_max_m: f64,
    /// Plans made on the leg (the first, blocked paths, the periodic ones).
    pub(crate) plans: usize,
    /// Times the robot was stuck and backed off.
    pub(crate) recoveries: usize,
    pub(crate) cycle_ms_mean: f64,
    pub(crate) cycle_ms_p99: f64,
    pub(crate) cycle_ms_max: f64,
}

/// `summary.json`.
#[derive(Clone, Debug, Serialize)]
pub(crate) struct Summary {
    pub(crate) seed: u64,
    pub(crate) registration: String,
    pub(crate) planner: String,
    pub(crate) kidnap: Option<[f64; 2]>,
    /// `explore` or `lap`.
    pub(crate) mode: &'static str,
    /// `office` or `small`.
    pub(crate) building: String,
    /// The lap's figures (`--lap` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(crate) mapping: Option<MappingSummary>,
    /// The exploration's figures (not with `--lap`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(crate) exploration: Option<ExplorationSummary>,
    /// Plan-view footprints of the dropped boxes in the map frame: min and max corners.
    pub(crate) obstacles: Vec<[[f64; 2]; 2]>,
    pub(crate) goals: Vec<LegSummary>,
    pub(crate) reached: usize,
    pub(crate) collisions: usize,
}

/// Every output file in `dir`.
pub(crate) fn write_outputs(
    dir: &Path,
    map: &PointCloud,
    occupancy: &gridmap::OccupancyGrid,
    inflated: &slam_core::BitGrid,
    overlay: &Overlay,
    trajectories: &(Vec<StampedPose>, Vec<StampedPose>),
    summary: &Summary,
) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    write_ply(dir.join("map.ply"), map, PlyEncoding::BinaryLittleEndian)?;
    picture::write_png(&dir.join("grid.png"), occupancy, inflated, overlay)?;
    gridmap::write_ros_map(occupancy, dir.join("map.yaml"))?;
    write_tum(dir.join("estimate.tum"), &trajectories.0)?;
    write_tum(dir.join("ground_truth.tum"), &trajectories.1)?;
    let json = serde_json::to_string_pretty(summary)?;
    std::fs::write(dir.join("summary.json"), json + "\n")
        .with_context(|| format!("writing {}/summary.json", dir.display()))?;
    out!(
        "wrote       {0}/map.ply, grid.png, map.yaml + map.pgm, estimate.tum, ground_truth.tum, summary.json",
        dir.display()
    )?;
    Ok(())
}
