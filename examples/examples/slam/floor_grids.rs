//! A walk over several floors: a grid per floor from the keyframes at its height, the flights
//! marked as stairs on them, and the stairs the walk took as links of those grids
//! (`spot_adapter::nav::FloorMaps`).

use std::path::Path;

use anyhow::{Context, Result};
use gridmap::FloorLevels;
use nalgebra::{Point3, Vector2};
use slam_core::io::StampedPose;
use slam_core::{Cell, GraphSlam, MapRegistrator, Optimizer};
use spot_adapter::nav::{FloorMaps, NavigationMapConfig, StairsLink};
use spot_nav_examples::summary::StairsSummary;
use spot_nav_examples::{Mapping, out};

/// A grid per floor and the stairs between them.
pub(crate) struct FloorGrids {
    maps: FloorMaps,
    /// Each floor's map cloud: the keyframes at its height, 5 cm voxels.
    clouds: Vec<slam_core::PointCloud>,
    /// The stairs, each with its foot's and top's cell centres (metres, the map frame).
    links: Vec<(StairsLink, Vector2<f64>, Vector2<f64>)>,
}

impl FloorGrids {
    /// Each floor's grid from the keyframes at its height (those between floors, on the stairs,
    /// are in none), the flights marked as stairs on both floors they join, obstacles inflated
    /// by `inflation` metres, and the stairs the walk through `poses` (the scans' LiDAR poses
    /// `floors` was split from) took; printed.
    pub(crate) fn build<R: MapRegistrator, C: MapRegistrator, O: Optimizer<slam_core::Pose3>>(
        slam: &GraphSlam<R, C, O>,
        lidar_height: f64,
        floors: &FloorLevels,
        poses: &[StampedPose],
        inflation: f64,
    ) -> Result<Self> {
        let loaded = slam.keyframe_scans().collect::<Result<Vec<_>, _>>()?;
        let scans: Vec<(slam_core::Pose3, &slam_core::PointCloud)> =
            loaded.iter().map(|(p, c)| (*p, c.as_ref())).collect();
        let positions: Vec<Point3<f64>> = poses
            .iter()
            .map(|p| Point3::from(p.pose.translation.vector))
            .collect();
        let maps = FloorMaps::build(
            &scans,
            &positions,
            floors,
            lidar_height,
            &NavigationMapConfig::default(),
            inflation,
        )
        .context("building a grid per floor and finding the stairs between them")?;
        for k in 0..floors.levels().len() {
            if let Some(Err(e)) = maps.map(k) {
                eprintln!("note: no grid for floor {k} ({e:#})");
            }
        }
        // Each link with its ends' cell centres (metres), read off the grids it was found on.
        let links = maps
            .links()
            .iter()
            .filter_map(|l| {
                let foot = maps.planning(l.foot.floor)?.cell_center(l.foot.cell);
                let top = maps.planning(l.top.floor)?.cell_center(l.top.cell);
                Some((*l, foot, top))
            })
            .collect();
        let clouds = maps
            .clouds(&scans, 0.05)
            .context("each floor's map cloud")?;
        Ok(Self {
            maps,
            clouds,
            links,
        })
    }

    /// The cells of floor `k`'s grid marked as stairs; `None` when it has no grid.
    pub(crate) fn stairs_cells(&self, k: usize) -> Option<usize> {
        match self.maps.map(k)? {
            Ok(map) => Some(map.occupancy().stairs().count_blocked()),
            Err(_) => None,
        }
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
            if (0..self.maps.floors().levels().len()).any(|k| self.maps.planning(k).is_none()) {
                "not found (a floor has no grid)".to_string()
            } else if each.is_empty() {
                "none (no change of floor has a free cell at both ends)".to_string()
            } else {
                each.join("; ")
            }
        )?;
        Ok(stairs)
    }

    /// A picture, a ROS map and a map cloud per floor in `dir` (`grid_floor{k}.png`,
    /// `map_floor{k}.yaml` + `.pgm`, `map_floor{k}.ply`), the picture with the walk on it, the
    /// stairs (teal) and the stairs' ends marked.
    pub(crate) fn write(&self, mapping: &Mapping, dir: &Path) -> Result<()> {
        let mut written = Vec::new();
        let floors = self.maps.floors();
        for k in 0..floors.levels().len() {
            let (Some(Ok(map)), Some(planning)) = (self.maps.map(k), self.maps.planning(k)) else {
                continue;
            };
            let walked: Vec<Cell> = mapping
                .estimate
                .iter()
                .enumerate()
                .filter(|(i, _)| floors.floor_of(*i) == Some(k))
                .filter_map(|(_, p)| {
                    let t = p.pose.translation.vector;
                    planning.cell_at(Vector2::new(t.x, t.y))
                })
                .collect();
            let ends: Vec<Cell> = self
                .links
                .iter()
                .flat_map(|(l, _, _)| [l.foot, l.top])
                .filter(|end| end.floor == k)
                .map(|end| end.cell)
                .collect();
            let occupancy = map.occupancy();
            let png = dir.join(format!("grid_floor{k}.png"));
            gridmap::write_png(&png, occupancy, Some(planning), &walked, &ends)?;
            gridmap::write_ros_map(occupancy, dir.join(format!("map_floor{k}.yaml")))?;
            slam_core::io::write_ply(
                dir.join(format!("map_floor{k}.ply")),
                &self.clouds[k],
                slam_core::io::PlyEncoding::BinaryLittleEndian,
            )?;
            written.push(format!(
                "grid_floor{k}.png, map_floor{k}.yaml + .pgm, map_floor{k}.ply"
            ));
        }
        out!(
            "wrote       {}: map.ply, map.pcd, trajectory.tum, graph.g2o, {}, summary.json",
            dir.display(),
            written.join(", ")
        )?;
        Ok(())
    }
}
