//! The navigator's settings, and the three of them the map it plans on is built with.

use gridmap::{
    FloorConfig, LiveLayerConfig, ObstacleBandConfig, OccupancyGridConfig, PlanningGridConfig,
    StairsConfig,
};

use crate::nav::NavError;
use crate::nav::localiser::LocaliserConfig;
use crate::nav::stuck::StuckConfig;

/// Settings of [`Navigator`](crate::nav::Navigator) (and of the
/// [`NavigationMap`](crate::nav::NavigationMap) it plans on, see [`NavigatorConfig::map_config`]). Lengths in metres,
/// angles in radians, speeds per second.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct NavigatorConfig {
    /// The occupancy grid's cells (0.10 m) and limits.
    pub grid: OccupancyGridConfig,
    /// How the floor under the map is found (1 m tiles).
    pub floor: FloorConfig,
    /// The obstacle band above the floor: from 0.08 m to 0.94 m (Spot with its LiDAR plus
    /// 0.10 m).
    pub band: ObstacleBandConfig,
    /// Hard inflation by the half width plus 0.05 m (0.30 m), the clearance cost, and how
    /// unknown cells count (not traversable by default).
    pub planning: PlanningGridConfig,
    /// The live layer each scan is fused into (8 m window; beams clear only below 0.3 m;
    /// changes decay after 20 s unseen).
    pub live: LiveLayerConfig,
    /// Replan at least every this many cycles even when the path stays clear, 25 (5 s).
    pub replan_every: usize,
    /// When something new blocks the path and the way around is this much longer than the
    /// blocked way (or there is none), 5 m, the robot stands and waits for it to clear (a
    /// person crossing, a door held) ...
    pub detour_extra: f64,
    /// ... for at most this many cycles, 40 (8 s), before it takes the way around (or answers
    /// `NoPath`).
    pub detour_patience: usize,
    /// Arrived when the estimated body is this close to the goal, 0.05 m (localisation is good
    /// to a few centimetres, so the true body ends within 0.10 m).
    pub goal_tolerance: f64,
    /// ... and, for a goal with a heading, faces it this closely, 0.1 rad.
    pub heading_tolerance: f64,
    /// Within this distance of the goal, with nothing in between, the robot walks straight at it
    /// sideways and forwards without turning (Spot walks in any direction), 0.6 m.
    pub approach_distance: f64,
    /// Speed of that final approach per metre still to go, 1.5 /s, ...
    pub approach_gain: f64,
    /// ... and at most this, 0.3 m/s.
    pub approach_speed: f64,
    /// Turn in place while the heading error to the next waypoint exceeds this, 0.5 (29°).
    pub turn_in_place_above: f64,
    /// Walking speed, 0.6 m/s (the simulated Spot's).
    pub speed: f64,
    /// Turn rate per radian of heading error, 1.5 /s (capped at the robot's limit).
    pub heading_gain: f64,
    /// Straight segments between waypoints keep at least this clearance where they can, 0.45 m;
    /// in narrower places (doors) the path's own cells are followed.
    pub shortcut_clearance: f64,
    /// Along closely spaced waypoints the robot steers at the farthest one within this
    /// distance that a straight line clear of the hard inflation reaches, 0.8 m.
    pub lookahead: f64,
    /// The planner on the planning grid.
    pub planner: PlannerKind,
    /// Localisation against the map: corrections, health, the wide search when lost.
    pub localiser: LocaliserConfig,
    /// What counts as stuck and how the robot gets free.
    pub stuck: StuckConfig,
}

impl Default for NavigatorConfig {
    fn default() -> Self {
        Self {
            grid: OccupancyGridConfig::default(),
            floor: FloorConfig::default(),
            band: ObstacleBandConfig::default(),
            planning: PlanningGridConfig::default(),
            // Changes live 20 s unseen: an obstacle too close to see stays until beams low enough
            // to see the floor behind it show it gone.
            live: LiveLayerConfig {
                decay: 300.0,
                ..LiveLayerConfig::default()
            },
            replan_every: 25,
            detour_extra: 5.0,
            detour_patience: 40,
            goal_tolerance: 0.05,
            heading_tolerance: 0.1,
            approach_distance: 0.6,
            approach_gain: 1.5,
            approach_speed: 0.3,
            turn_in_place_above: 0.5,
            speed: 0.6,
            heading_gain: 1.5,
            shortcut_clearance: 0.45,
            lookahead: 0.8,
            planner: PlannerKind::default(),
            localiser: LocaliserConfig::default(),
            stuck: StuckConfig::default(),
        }
    }
}

impl NavigatorConfig {
    /// Every length, angle, speed and gain finite and positive; the grids', the localiser's
    /// and the stuck monitor's settings valid.
    ///
    /// # Errors
    /// [`NavError::InvalidConfig`] naming the first bad setting, or
    /// [`NavError::NavigationGrid`] with gridmap's error for a bad grid setting.
    pub fn validate(&self) -> Result<(), NavError> {
        for (setting, value) in [
            ("goal_tolerance", self.goal_tolerance),
            ("heading_tolerance", self.heading_tolerance),
            ("approach_distance", self.approach_distance),
            ("approach_gain", self.approach_gain),
            ("approach_speed", self.approach_speed),
            ("turn_in_place_above", self.turn_in_place_above),
            ("speed", self.speed),
            ("heading_gain", self.heading_gain),
            ("shortcut_clearance", self.shortcut_clearance),
            ("lookahead", self.lookahead),
            ("detour_extra", self.detour_extra),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(NavError::invalid(setting, value, "finite and positive"));
            }
        }
        if self.replan_every == 0 {
            return Err(NavError::invalid("replan_every", 0.0, "at least 1"));
        }
        validate_floor_band(&self.floor, &self.band)?;
        self.planning.validate().map_err(NavError::NavigationGrid)?;
        self.live.validate().map_err(NavError::NavigationGrid)?;
        self.localiser.validate()?;
        self.stuck.validate()
    }

    /// The settings of the map this navigator plans on, for
    /// [`NavigationMap::from_scans`](crate::nav::NavigationMap::from_scans) and `from_cloud`.
    #[must_use]
    pub fn map_config(&self) -> NavigationMapConfig {
        NavigationMapConfig {
            grid: self.grid.clone(),
            floor: self.floor.clone(),
            band: self.band.clone(),
            stairs: StairsConfig::default(),
        }
    }
}

/// The planner a [`Navigator`](crate::nav::Navigator) uses on its planning grid.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum PlannerKind {
    /// [`CellCostAStar`](pathfind::CellCostAStar): least cost under the clearance cost (paths keep to the middle of
    /// corridors, yet pass doors the hard inflation leaves open); shortest paths when the cost
    /// is off.
    #[default]
    CellCostAStar,
    /// [`JumpPointSearch`](pathfind::JumpPointSearch) with word scans: shortest paths, the clearance cost ignored.
    JumpPointSearch,
    /// [`AStar`](pathfind::AStar) with the octile heuristic: shortest paths, the clearance cost ignored.
    AStar,
}

/// Settings of a [`NavigationMap`](crate::nav::NavigationMap): the grid, the floor under it and
/// the obstacle band above the floor. The navigator's own [`NavigatorConfig::map_config`] gives
/// the ones it plans with.
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct NavigationMapConfig {
    /// The occupancy grid's cells (0.10 m) and limits.
    pub grid: OccupancyGridConfig,
    /// How the floor under the map is found (1 m tiles).
    pub floor: FloorConfig,
    /// The obstacle band above the floor: from 0.08 m to 0.94 m (Spot with its LiDAR plus
    /// 0.10 m).
    pub band: ObstacleBandConfig,
    /// How the flights of stairs a walk over several floors took are found on the floors'
    /// grids ([`crate::nav::FloorMaps`]).
    pub stairs: StairsConfig,
}

impl NavigationMapConfig {
    /// The floor's, the band's and the stairs' settings valid (the grid's are checked when it
    /// is built).
    ///
    /// # Errors
    /// [`NavError::NavigationGrid`] with gridmap's error for a bad setting.
    pub fn validate(&self) -> Result<(), NavError> {
        validate_floor_band(&self.floor, &self.band)?;
        self.stairs.validate().map_err(NavError::NavigationGrid)
    }
}

fn validate_floor_band(floor: &FloorConfig, band: &ObstacleBandConfig) -> Result<(), NavError> {
    floor.validate().map_err(NavError::NavigationGrid)?;
    band.validate().map_err(NavError::NavigationGrid)
}
