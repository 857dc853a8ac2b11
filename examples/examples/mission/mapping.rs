//! The mapping lap: the building mapped by Graph-SLAM, with its figures.

use anyhow::{Context, Result};
use slam_core::{GraphSlam, MapRegistrator, Optimizer, PointCloud, Pose3};
use spot_adapter::nav::{NavigationMap, NavigationMapConfig};
use spot_adapter::sim::{SimulatedSpot, SimulationConfig};
use spot_nav_examples::{map_and_evaluate, out};

use crate::report::MappingSummary;

/// The map and where the robot ended, from one mapped lap.
pub(crate) struct Mapped {
    pub(crate) map: PointCloud,
    /// The occupancy (obstacles from the floor up, free from the beams, unknown elsewhere).
    pub(crate) navigation: NavigationMap,
    /// The engine's estimate of the body at the last scan (map frame).
    pub(crate) map_t_body: Pose3,
    pub(crate) summary: MappingSummary,
}

/// Walks one lap of `sim` through `slam`, prints the mapping figures, returns the map (its
/// occupancy made with `map_config`).
pub(crate) fn map_building<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    mut slam: GraphSlam<R, C, O>,
    sim: SimulatedSpot,
    map_config: &NavigationMapConfig,
) -> Result<Mapped> {
    let body_t_lidar = sim.body_t_lidar();
    let summary = map_walk(&mut slam, sim, "lap")?;
    let map_t_lidar = slam
        .current_lidar_pose()
        .context("the lap gave the engine no scan")?;
    let loaded = slam.keyframe_scans().collect::<Result<Vec<_>, _>>()?;
    let scans: Vec<(Pose3, &PointCloud)> = loaded.iter().map(|(p, c)| (*p, c.as_ref())).collect();
    let sim_config = SimulationConfig::default();
    let lidar_height = sim_config.spot.body_height + sim_config.spot.body_t_lidar.translation.z;
    let navigation = NavigationMap::from_scans(&scans, lidar_height, map_config)?;
    Ok(Mapped {
        map: slam.map(0.05)?,
        navigation,
        map_t_body: map_t_lidar * body_t_lidar.inverse(),
        summary,
    })
}

/// Walks `sim` (a `walk`: "lap", "tour") through `slam`, prints its mapping figures in one line
/// and returns them.
pub(crate) fn map_walk<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    slam: &mut GraphSlam<R, C, O>,
    sim: SimulatedSpot,
    walk: &str,
) -> Result<MappingSummary> {
    let body_t_lidar = sim.body_t_lidar();
    let truth = sim.ground_truth();
    let samples = sim.map(Ok::<_, std::convert::Infallible>);
    let mapping = map_and_evaluate(slam, samples, &body_t_lidar, Some(&truth), "mapping", false)?;
    let e = mapping
        .evaluation
        .with_context(|| format!("the {walk} has a ground truth"))?;
    let report = slam.report();
    out!(
        "mapping     {} scans, {} keyframes, {} loops closed; {:.1} m {walk}; ATE {:.3} m, loop end-point error {:.3} m; {:.2} ms mean per scan; {:.1} s",
        report.scans,
        report.keyframes,
        report.loops_closed,
        e.end_point.path_length,
        e.ate.rmse,
        e.loop_end_point_error,
        report.mean_scan_ms(),
        mapping.seconds
    )?;
    Ok(MappingSummary {
        scans: report.scans,
        keyframes: report.keyframes,
        loops_closed: report.loops_closed,
        lap_length_m: e.end_point.path_length,
        ate_m: e.ate.rmse,
        loop_end_point_error_m: e.loop_end_point_error,
        segment_drift_percent: e.segments.as_ref().map(|s| 100.0 * s.translation),
        mean_ms_per_scan: report.mean_scan_ms(),
        seconds: mapping.seconds,
    })
}
