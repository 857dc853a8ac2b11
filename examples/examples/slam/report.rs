//! The run's figures: evaluated, printed, and written with the map and grid to `--out`.

use std::path::Path;

use anyhow::{Context, Result};
use gridmap::{FloorLevels, FloorLevelsConfig, UnknownCells, inflate};
use nalgebra::Vector2;
use posegraph::g2o::{G2oGraph, write_g2o};
use slam_core::io::{PcdEncoding, PlyEncoding, StampedPose, write_pcd, write_ply, write_tum};
use slam_core::{GraphSlam, MapRegistrator, Optimizer, Pose3};
use spot_adapter::nav::{NavigationMap, NavigationMapConfig};
use spot_adapter::record::DroppedPoints;
use spot_nav_examples::health::skip_reasons;
use spot_nav_examples::summary::{
    Accuracy, FloorSummary, Loops, Points, SlamSummary, Times, write_summary,
};
use spot_nav_examples::{MappedScans, Mapping, evaluate, out, print_tracking_health, value_name};

use crate::args::Args;
use crate::floor_grids::FloorGrids;
use crate::{RunContext, Truth};

/// Obstacles in the grid picture are inflated by Spot's half width and a margin (metres).
const INFLATION: f64 = 0.30;

/// Evaluates the run against the ground truth (when known), prints its figures and writes the
/// outputs.
pub(crate) fn finish<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    slam: &GraphSlam<R, C, O>,
    run: &MappedScans,
    body_t_lidar: &Pose3,
    points: Option<DroppedPoints>,
    args: &Args,
    context: &RunContext<'_>,
) -> Result<()> {
    let truth = match context.truth {
        Truth::None => None,
        Truth::Stamped(poses) => Some(poses.to_vec()),
        Truth::File(file) => Some(file.stamped(&run.stamps)?),
    };
    let (evaluation, estimate) =
        evaluate(slam, body_t_lidar, truth.as_deref()).with_context(|| {
            format!(
                "evaluating {} scan poses against the ground truth ({})",
                slam.scan_trajectory().len(),
                context.input.ground_truth.as_deref().unwrap_or("none")
            )
        })?;
    let mapping = Mapping {
        estimate,
        evaluation,
        seconds: run.seconds,
    };
    let mut summary = report(slam, &mapping, points, args, context)?;
    if let (Some(truth), true) = (&truth, args.floors > 1) {
        print_floor_heights(&mapping.estimate, truth, args.floors)?;
    }
    let poses = slam.scan_trajectory();
    let floors = split_floors(&poses)?;
    summary.floors = print_floors(slam, &poses, &floors)?;
    // Several floors: a grid each, and the stairs between them as links of those grids.
    let floor_grids = if floors.levels().len() > 1 {
        let grids = FloorGrids::build(slam, args.lidar_height, &floors, &poses, INFLATION)?;
        summary.stairs = grids.stairs()?;
        for (k, floor) in summary.floors.iter_mut().enumerate() {
            floor.stairs_cells = grids.stairs_cells(k);
        }
        Some(grids)
    } else {
        None
    };
    if let Some(dir) = &args.out {
        write_outputs(
            slam,
            &mapping,
            dir,
            args.lidar_height,
            &summary,
            floor_grids.as_ref(),
        )?;
    }
    if let Some(path) = &args.summary {
        write_summary(path, &summary)?;
        out!("wrote       {}", path.display())?;
    }
    Ok(())
}

/// Prints the run's figures; returns them as `summary.json` holds them.
pub(crate) fn report<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    slam: &GraphSlam<R, C, O>,
    mapping: &Mapping,
    points: Option<DroppedPoints>,
    args: &Args,
    context: &RunContext<'_>,
) -> Result<SlamSummary> {
    let report = slam.report();
    let skipped: usize = skip_reasons(report).iter().map(|&(_, n)| n).sum();
    out!(
        "scans       {} ({} keyframes, {} with their whole scan for the map, {} riding on a keyframe already there, {skipped} skipped)",
        report.scans,
        report.keyframes,
        report.whole_scans,
        report.revisits
    )?;
    let loops = Loops::new(report);
    let rejected = if loops.rejected.is_empty() {
        "none".to_string()
    } else {
        loops
            .rejected
            .iter()
            .map(|(reason, n)| format!("{n} {reason}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    out!(
        "loops       {} closed of {} tried ({} by appearance; {} refused beyond the drift, {} weighted out by the back end; rejected: {rejected})",
        loops.closed,
        loops.tried,
        loops.by_appearance,
        loops.refused_beyond_drift,
        loops.weighted_out
    )?;
    let health = print_tracking_health(report)?;
    let time = Times::new(report, mapping.seconds);
    out!(
        "time        {:.2} ms mean, {:.2} ms p99, {:.2} ms max (scan {}) per scan (odometry path); loop steps max {:.1} ms; {:.1} s in all",
        time.scan_ms_mean,
        time.scan_ms_p99,
        time.scan_ms_max,
        time.slowest_scan,
        time.loop_ms_max,
        time.seconds
    )?;
    let points = points.map(|p| Points {
        no_return: p.no_return,
        non_finite: p.non_finite,
    });
    if let Some(p) = &points {
        out!(
            "points      {} no-return and {} non-finite points removed",
            p.no_return,
            p.non_finite
        )?;
    }
    let accuracy = mapping.evaluation.as_ref().map(Accuracy::new);
    if let Some(a) = &accuracy {
        print_accuracy(a)?;
    }
    Ok(SlamSummary {
        input: context.input.clone(),
        registration: value_name(&args.registration),
        tracker_map_voxel: slam.registrator().map_voxel(),
        scans: report.scans,
        keyframes: report.keyframes,
        whole_scans: report.whole_scans,
        revisits: report.revisits,
        loops,
        tracking: health,
        time,
        points,
        accuracy,
        floors: Vec::new(),
        stairs: Vec::new(),
    })
}

/// The walk's floors: its scans' LiDAR poses (the keyframes' frame) split by height.
fn split_floors(poses: &[StampedPose]) -> Result<FloorLevels> {
    let positions: Vec<_> = poses
        .iter()
        .map(|p| nalgebra::Point3::from(p.pose.translation.vector))
        .collect();
    FloorLevels::split(&positions, &FloorLevelsConfig::default())
        .context("splitting the walk into floors")
}

/// The floors as `summary.json` gives them; printed when there are several, with the walk's
/// changes of floor.
fn print_floors<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    slam: &GraphSlam<R, C, O>,
    poses: &[StampedPose],
    floors: &FloorLevels,
) -> Result<Vec<FloorSummary>> {
    let keyframe_floors: Vec<Option<usize>> = slam
        .keyframe_trajectory()
        .iter()
        .map(|k| floors.floor_at(k.pose.translation.z))
        .collect();
    let summaries: Vec<FloorSummary> = floors
        .levels()
        .iter()
        .enumerate()
        .map(|(k, level)| FloorSummary {
            height_m: level.height,
            walked_m: level.walked,
            scans: level.poses,
            keyframes: keyframe_floors.iter().filter(|f| **f == Some(k)).count(),
            stairs_cells: None,
        })
        .collect();
    if summaries.len() > 1 {
        let each: Vec<String> = summaries
            .iter()
            .enumerate()
            .map(|(k, f)| {
                format!(
                    "floor {k} at {:.2} m ({:.1} m walked, {} keyframes)",
                    f.height_m, f.walked_m, f.keyframes
                )
            })
            .collect();
        let changes: Vec<String> = floors
            .changes()
            .iter()
            .map(|c| {
                let at = |i: usize| {
                    poses
                        .get(i)
                        .map_or_else(nalgebra::Vector3::zeros, |p| p.pose.translation.vector)
                };
                let (from, to) = (at(c.left_at), at(c.arrived_at));
                let length: f64 = poses.get(c.left_at..=c.arrived_at).map_or(0.0, |run| {
                    run.windows(2)
                        .map(|w| {
                            (w[1].pose.translation.vector - w[0].pose.translation.vector).norm()
                        })
                        .sum()
                });
                format!(
                    "{}->{} from ({:.1}, {:.1}) to ({:.1}, {:.1}) over {length:.1} m",
                    c.from, c.to, from.x, from.y, to.x, to.y
                )
            })
            .collect();
        out!(
            "floors      {} by height: {}; the walk changed floor {} times: {}",
            summaries.len(),
            each.join(", "),
            changes.len(),
            changes.join(", ")
        )?;
    }
    Ok(summaries)
}

/// The height error on each floor of a tour over several floors: the estimate moved rigidly so
/// that its first pose is the truth's (as the height drift is measured), then its z against
/// the truth's at every pose standing on a floor (within 5 cm of a floor's height), mean and
/// largest per floor. The floors' heights come from the truth: its highest point is the top
/// floor.
fn print_floor_heights(
    estimate: &[StampedPose],
    truth: &[StampedPose],
    floors: usize,
) -> Result<()> {
    let (Some(e0), Some(t0)) = (estimate.first(), truth.first()) else {
        return Ok(());
    };
    let align = t0.pose * e0.pose.inverse();
    let z0 = t0.pose.translation.z;
    let top = truth
        .iter()
        .map(|p| p.pose.translation.z)
        .fold(z0, f64::max);
    let storey = (top - z0) / (floors - 1) as f64;
    let mut errors = vec![Vec::new(); floors];
    for e in estimate {
        // The simulator's samples carry the same stamps as its truth.
        let Some(t) = truth.iter().find(|t| (t.stamp - e.stamp).abs() < 1e-6) else {
            continue;
        };
        let dz = t.pose.translation.z - z0;
        let floor = (dz / storey).round();
        if (dz - floor * storey).abs() < 0.05 && floor >= 0.0 {
            let z = (align * e.pose).translation.z;
            errors[floor as usize].push(z - t.pose.translation.z);
        }
    }
    let lines: Vec<String> = errors
        .iter()
        .enumerate()
        .map(|(k, e)| {
            let mean = e.iter().sum::<f64>() / e.len().max(1) as f64;
            let worst = e.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            format!(
                "floor {k} {mean:+.3} m mean, {worst:.3} m max ({} poses)",
                e.len()
            )
        })
        .collect();
    out!(
        "floors      height error (first pose aligned): {}",
        lines.join("; ")
    )?;
    Ok(())
}

/// The accuracy lines: ATE and drifts, KITTI's RPE, each step's rotation error.
pub(crate) fn print_accuracy(a: &Accuracy) -> Result<()> {
    let drift = a.end_point_drift_percent.map_or_else(
        || "the truth did not move".to_owned(),
        |d| format!("{d:.3} % of {:.1} m", a.path_length_m),
    );
    let segments = a
        .segment_drift_percent
        .map_or_else(String::new, |s| format!(", segments (10-50 m) {s:.3} %"));
    out!(
        "accuracy    ATE {:.3} m (RMSE after SE(3) alignment, {} poses), end point {:.3} m ({drift}), height drift {:+.3} m, loop end-point error {:.3} m{segments}",
        a.ate_m,
        a.ate_pairs,
        a.end_point_error_m,
        a.height_drift_m,
        a.loop_end_point_error_m
    )?;
    match (a.rpe_percent, a.rpe_rotation_deg_per_100m) {
        (Some(t), Some(r)) => {
            let lengths = match (
                a.rpe_segment_lengths_m.first(),
                a.rpe_segment_lengths_m.last(),
            ) {
                (Some(first), Some(last)) if first < last => format!("{first}-{last} m"),
                (Some(first), _) => format!("{first} m"),
                _ => String::new(),
            };
            let which = if a.rpe_kitti_lengths {
                format!("KITTI's segments of {lengths}")
            } else {
                format!(
                    "the path, {:.1} m, is shorter than KITTI's 100 m segments: over {lengths} instead",
                    a.path_length_m
                )
            };
            out!(
                "rpe         {t:.3} % per 100 m, {r:.3} deg per 100 m ({which}; {} segments)",
                a.rpe_segments
            )?;
        }
        _ => out!(
            "rpe         none: the path ({:.3} m) is too short for any segment",
            a.path_length_m
        )?,
    }
    out!(
        "steps       {} of {} steps with more than 2 deg of rotation error against the truth, {} with more than 5 deg (largest {:.2} deg)",
        a.steps_over_2_deg,
        a.steps,
        a.steps_over_5_deg,
        a.step_rotation_error_max_deg
    )
}

/// `navigation`'s grid as a picture at `png` (obstacles inflated, the `walked` poses drawn) and
/// as a ROS map at `yaml`.
fn write_grid<'a>(
    navigation: &NavigationMap,
    walked: impl Iterator<Item = &'a StampedPose>,
    png: &Path,
    yaml: &Path,
) -> Result<()> {
    let grid = navigation.occupancy();
    let planning = grid.to_planning_grid(UnknownCells::Free);
    let inflated = inflate(&planning, INFLATION)?;
    let path: Vec<_> = walked
        .filter_map(|p| {
            let t = p.pose.translation.vector;
            planning.cell_at(Vector2::new(t.x, t.y))
        })
        .collect();
    gridmap::write_png(png, grid, Some(&inflated), &path, &[])?;
    gridmap::write_ros_map(grid, yaml)?;
    Ok(())
}

/// The map, trajectory, graph, grid and summary in `dir` (made here, after the run).
pub(crate) fn write_outputs<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    slam: &GraphSlam<R, C, O>,
    mapping: &Mapping,
    dir: &Path,
    lidar_height: f64,
    summary: &SlamSummary,
    floor_grids: Option<&FloorGrids>,
) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    write_summary(&dir.join("summary.json"), summary)?;
    let map = slam.map(0.05)?;
    write_ply(dir.join("map.ply"), &map, PlyEncoding::BinaryLittleEndian)?;
    write_pcd(dir.join("map.pcd"), &map, PcdEncoding::Binary)?;
    write_tum(dir.join("trajectory.tum"), &mapping.estimate)?;
    write_g2o(dir.join("graph.g2o"), &G2oGraph::Se3(slam.graph().clone()))?;
    let loaded = slam.keyframe_scans().collect::<Result<Vec<_>, _>>()?;
    let scans: Vec<(Pose3, &slam_core::PointCloud)> =
        loaded.iter().map(|(p, c)| (*p, c.as_ref())).collect();
    if let Some(grids) = floor_grids {
        return grids.write(mapping, dir);
    }
    match NavigationMap::from_scans(&scans, lidar_height, &NavigationMapConfig::default()) {
        Ok(navigation) => {
            write_grid(
                &navigation,
                mapping.estimate.iter(),
                &dir.join("grid.png"),
                &dir.join("map.yaml"),
            )?;
            out!(
                "wrote       {}: map.ply, map.pcd, trajectory.tum, graph.g2o, grid.png, map.yaml + map.pgm, summary.json",
                dir.display()
            )?;
        }
        Err(e) => {
            eprintln!("note: no grid ({e:#}); is --lidar-height {lidar_height} m right?");
            out!(
                "wrote       {}: map.ply, map.pcd, trajectory.tum, graph.g2o, summary.json",
                dir.display()
            )?;
        }
    }
    Ok(())
}
