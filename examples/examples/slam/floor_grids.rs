//! A walk over several floors: a grid per floor from the keyframes at its height, and the
//! stairs the walk took between them as links of those grids (`spot_adapter::nav::stairs_links`).

use std::path::Path;

use anyhow::{Context, Result};
use gridmap::{FloorLevels, UnknownCells, inflate};
use nalgebra::Vector2;
use slam_core::io::StampedPose;
use slam_core::{BitGrid, Cell, GraphSlam, MapRegistrator, Optimizer, Pose3};
use spot_adapter::nav::{NavigationMap, NavigationMapConfig, StairsLink, stairs_links};
use spot_nav_examples::summary::StairsSummary;
use spot_nav_examples::{Mapping, out};

/// One floor's grid: the map from its keyframes and the planning grid inflated from it.
struct FloorGrid {
    navigation: NavigationMap,
    inflated: BitGrid,
}

/// A grid per floor (`None` where the floor's keyframes gave none) and the stairs between them.
pub(crate) struct FloorGrids {
    floors: FloorLevels,
    grids: Vec<Option<FloorGrid>>,
    /// The stairs, each with its foot's and top's cell centres (metres, the map frame).
    links: Vec<(StairsLink, Vector2<f64>, Vector2<f64>)>,
}

impl FloorGrids {
    /// Each floor's grid from the keyframes at its height (those between floors, on the stairs,
    /// are in none), obstacles inflated by `inflation` metres, and the stairs the walk through
    /// `poses` (the scans' LiDAR poses `floors` was split from) took; printed.
    pub(crate) fn build<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
        slam: &GraphSlam<R, C, O>,
        lidar_height: f64,
        floors: &FloorLevels,
        poses: &[StampedPose],
        inflation: f64,
    ) -> Result<Self> {
        let scans: Vec<_> = slam.keyframe_scans().collect();
        let mut grids = Vec::new();
        for k in 0..floors.levels().len() {
            let on_floor: Vec<(Pose3, &slam_core::PointCloud)> = scans
                .iter()
                .filter(|(pose, _)| floors.floor_at(pose.translation.z) == Some(k))
                .copied()
                .collect();
            let config = NavigationMapConfig::default();
            grids.push(
                match NavigationMap::from_scans(&on_floor, lidar_height, &config) {
                    Ok(navigation) => {
                        let planning = navigation.occupancy().to_planning_grid(UnknownCells::Free);
                        let inflated = inflate(&planning, inflation)?;
                        Some(FloorGrid {
                            navigation,
                            inflated,
                        })
                    }
                    Err(e) => {
                        eprintln!("note: no grid for floor {k} ({e:#})");
                        None
                    }
                },
            );
        }
        let every: Option<Vec<&BitGrid>> = grids
            .iter()
            .map(|g| g.as_ref().map(|g| &g.inflated))
            .collect();
        // Each link with its ends' cell centres (metres), read off the grids it was found on.
        let links = match every {
            Some(planning) => {
                let positions: Vec<_> = poses
                    .iter()
                    .map(|p| nalgebra::Point3::from(p.pose.translation.vector))
                    .collect();
                stairs_links(&positions, floors, &planning)
                    .context("finding the stairs between the floors")?
                    .into_iter()
                    .map(|l| {
                        let foot = planning[l.foot.floor].cell_center(l.foot.cell);
                        let top = planning[l.top.floor].cell_center(l.top.cell);
                        (l, foot, top)
                    })
                    .collect()
            }
            None => Vec::new(),
        };
        Ok(Self {
            floors: floors.clone(),
            grids,
            links,
        })
    }

    /// The stairs as `summary.json` gives them (metres, the map frame); printed.
    pub(crate) fn stairs(&self) -> Result<Vec<StairsSummary>> {
        let stairs: Vec<StairsSummary> = self
            .links
            .iter()
            .map(|(l, foot, top)| StairsSummary {
                lower_floor: l.foot.floor,
                upper_floor: l.top.floor,
                foot_m: [foot.x, foot.y],
                top_m: [top.x, top.y],
                length_m: l.length,
            })
            .collect();
        let each: Vec<String> = stairs
            .iter()
            .map(|s| {
                format!(
                    "floor {} ({:.1}, {:.1}) to floor {} ({:.1}, {:.1}), {:.1} m",
                    s.lower_floor,
                    s.foot_m[0],
                    s.foot_m[1],
                    s.upper_floor,
                    s.top_m[0],
                    s.top_m[1],
                    s.length_m
                )
            })
            .collect();
        out!(
            "stairs      {} flight(s) between the floors' grids: {}",
            stairs.len(),
            if self.grids.iter().any(Option::is_none) {
                "not found (a floor has no grid)".to_string()
            } else if each.is_empty() {
                "none (no change of floor has a free cell at both ends)".to_string()
            } else {
                each.join("; ")
            }
        )?;
        Ok(stairs)
    }

    /// A picture and a ROS map per floor in `dir` (`grid_floor{k}.png`, `map_floor{k}.yaml` +
    /// `.pgm`) with the walk on it and the stairs' ends marked.
    pub(crate) fn write(&self, mapping: &Mapping, dir: &Path) -> Result<()> {
        let mut written = Vec::new();
        for (k, grid) in self.grids.iter().enumerate() {
            let Some(grid) = grid else { continue };
            let walked: Vec<Cell> = mapping
                .estimate
                .iter()
                .enumerate()
                .filter(|(i, _)| self.floors.floor_of(*i) == Some(k))
                .filter_map(|(_, p)| {
                    let t = p.pose.translation.vector;
                    grid.inflated.cell_at(Vector2::new(t.x, t.y))
                })
                .collect();
            let ends: Vec<Cell> = self
                .links
                .iter()
                .flat_map(|(l, _, _)| [l.foot, l.top])
                .filter(|end| end.floor == k)
                .map(|end| end.cell)
                .collect();
            let occupancy = grid.navigation.occupancy();
            let png = dir.join(format!("grid_floor{k}.png"));
            gridmap::write_png(&png, occupancy, Some(&grid.inflated), &walked, &ends)?;
            gridmap::write_ros_map(occupancy, dir.join(format!("map_floor{k}.yaml")))?;
            written.push(format!("grid_floor{k}.png, map_floor{k}.yaml + .pgm"));
        }
        out!(
            "wrote       {}: map.ply, map.pcd, trajectory.tum, graph.g2o, {}, summary.json",
            dir.display(),
            written.join(", ")
        )?;
        Ok(())
    }
}
