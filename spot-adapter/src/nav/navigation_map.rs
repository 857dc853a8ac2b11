//! The map a navigator plans on, built once per map: the occupancy of the obstacle band above
//! the floor found under the robot's paths, with free space from the scans' beams and unknown
//! cells where no beam went.

use gridmap::{FloorMap, OccupancyGrid, OccupancyGridBuilder, floor_hints_below};
use slam_core::{BitGrid, PointCloud, Pose3};

use crate::nav::NavError;
use crate::nav::config::NavigationMapConfig;

/// The static layer of navigation: occupancy (obstacles from the floor up, free where beams
/// passed, unknown elsewhere) and the floor under it.
#[derive(Clone, Debug)]
pub struct NavigationMap {
    occupancy: OccupancyGrid,
    floor: FloorMap,
}

impl NavigationMap {
    /// From scans with their poses (`map_T_lidar`, e.g. [`slam_core::GraphSlam::keyframe_scans`])
    /// of a LiDAR mounted `lidar_height` metres above the floor: the floor is found under the
    /// scan poses, obstacles are the points of the band above it (`config.band`), free space
    /// the cells the beams crossed; cells no beam reached are unknown.
    ///
    /// # Errors
    /// [`NavError::NavigationGrid`] (with gridmap's error as its source) for invalid settings
    /// or when the grid cannot be built.
    pub fn from_scans(
        scans: &[(Pose3, &PointCloud)],
        lidar_height: f64,
        config: &NavigationMapConfig,
    ) -> Result<Self, NavError> {
        Self::scanned(scans, lidar_height, None, config)
    }

    /// [`NavigationMap::from_scans`] for one storey of a building whose floor lies within
    /// `tolerance` metres of height `level` (the map frame's z, e.g. a [`gridmap::FloorLevel`]'s
    /// height less the LiDAR's): the floor's tiles kept within it, so that a stairwell does not
    /// drag the floor beside it down (over a flight the lowest points are a step's) and lift
    /// the floor's own returns into the obstacle band.
    ///
    /// # Errors
    /// As [`NavigationMap::from_scans`]; [`NavError::NavigationGrid`] for a level or tolerance
    /// that is not finite (or a negative tolerance).
    pub fn from_scans_at_level(
        scans: &[(Pose3, &PointCloud)],
        lidar_height: f64,
        (level, tolerance): (f64, f64),
        config: &NavigationMapConfig,
    ) -> Result<Self, NavError> {
        Self::scanned(
            scans,
            lidar_height,
            Some((level - tolerance, level + tolerance)),
            config,
        )
    }

    /// [`NavigationMap::from_scans`], the floor's tiles kept within `level` (lowest, highest)
    /// when given.
    fn scanned(
        scans: &[(Pose3, &PointCloud)],
        lidar_height: f64,
        level: Option<(f64, f64)>,
        config: &NavigationMapConfig,
    ) -> Result<Self, NavError> {
        config.validate()?;
        let poses: Vec<Pose3> = scans.iter().map(|(p, _)| *p).collect();
        let hints = floor_hints_below(&poses, lidar_height);
        let floor = FloorMap::estimate_from_scans(scans, &hints, &config.floor)
            .and_then(|f| match level {
                Some((lo, hi)) => f.clamped(lo, hi),
                None => Ok(f),
            })
            .map_err(NavError::NavigationGrid)?;
        let occupancy = OccupancyGridBuilder::new(config.grid.clone())
            .and_then(|b| b.build_floor_band_from_scans(scans, &floor, &config.band))
            .map_err(NavError::NavigationGrid)?;
        Ok(Self { occupancy, floor })
    }

    /// From a map cloud alone (no beams, so no unknown cells: every cell without obstacle
    /// points is free), the floor found under `sensor_poses` (`map_T_lidar` of a LiDAR
    /// `lidar_height` metres above the floor).
    ///
    /// # Errors
    /// As [`NavigationMap::from_scans`].
    pub fn from_cloud(
        map: &PointCloud,
        sensor_poses: &[Pose3],
        lidar_height: f64,
        config: &NavigationMapConfig,
    ) -> Result<Self, NavError> {
        config.validate()?;
        let hints = floor_hints_below(sensor_poses, lidar_height);
        let floor =
            FloorMap::estimate(map, &hints, &config.floor).map_err(NavError::NavigationGrid)?;
        let occupancy = OccupancyGridBuilder::new(config.grid.clone())
            .and_then(|b| b.build_floor_band(map, &floor, &config.band))
            .map_err(NavError::NavigationGrid)?;
        Ok(Self { occupancy, floor })
    }

    /// From an occupancy grid built over `floor` (the explorer's, grown scan by scan).
    pub(crate) fn from_parts(occupancy: OccupancyGrid, floor: FloorMap) -> Self {
        Self { occupancy, floor }
    }

    /// This map with the cells set in `stairs` (e.g. from [`gridmap::stairs_cells`]) marked as
    /// stairs: blocked to the planners on this floor, neither wall nor floor.
    ///
    /// # Errors
    /// [`NavError::NavigationGrid`] when `stairs` is not the size and placement of the grid.
    pub fn mark_stairs(&mut self, stairs: &BitGrid) -> Result<(), NavError> {
        self.occupancy
            .mark_stairs(stairs)
            .map_err(NavError::NavigationGrid)
    }

    /// The occupancy grid (occupied, free, unknown, stairs).
    #[must_use]
    pub fn occupancy(&self) -> &OccupancyGrid {
        &self.occupancy
    }

    /// The floor under the map.
    #[must_use]
    pub fn floor(&self) -> &FloorMap {
        &self.floor
    }
}
