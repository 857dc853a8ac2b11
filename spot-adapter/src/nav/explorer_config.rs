//! The explorer's settings and the rule it picks the next frontier by.

use crate::nav::NavError;

/// How the explorer picks the next frontier among the reachable ones.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(tag = "kind", deny_unknown_fields)
)]
pub enum FrontierChoice {
    /// Scraps before large areas: among the frontiers whose walk is at most `detour` metres
    /// longer than the nearest one's, the one that would reveal least (unknown area in sight
    /// within sensor range) is taken first. A scrap left behind costs a walk back later; a large
    /// unknown area will be walked into anyway, and the scraps by the way are cleared on the
    /// way to it. (Weighing the other way, the most area per walk, `gain * exp(-0.25 /m *
    /// cost)` after González-Baños and Latombe, walked 1-55 % farther than the nearest-first
    /// rule on the small test building: it leaves the scraps behind.) Measured so far, this rule
    /// walks about as far as the nearest-first one, 0.93-1.24x on four small buildings: not
    /// yet the better explorer the issue asks for.
    InformationGain {
        /// Metres more than the nearest frontier's walk that a frontier may cost and still be
        /// weighed, 4 m (the length of a room or two along a corridor).
        detour: f64,
    },
    /// `explore_lite`'s rule, the baseline: the frontier with the shortest walk, whatever it
    /// reveals.
    GreedyNearestFrontier,
    /// The first frontier of the shortest walk from the robot through every reachable frontier
    /// goal (an open travelling-salesman path over the walks between goals; FUEL, Zhou et al.,
    /// RA-L 2021): a dead end passed on the way is cleared then, not walked back to later, as
    /// nearest-first does. The frontier already walked to is kept unless a tour starting
    /// elsewhere is shorter by more than `keep_margin`: the map grows between decisions and a
    /// tour that flips between two frontiers walks to neither.
    Tour {
        /// Metres a tour must save over the one through the frontier already walked to before
        /// the explorer turns to another, 2 m.
        keep_margin: f64,
    },
    /// The nearest frontier worth a walk: `explore_lite`'s rule over the frontiers that would
    /// reveal at least `min_gain` square metres (unknown area in sight of the frontier's middle
    /// within sensor range); the rest are left, and the exploration ends when only they are.
    /// On the small buildings the nearest-first rule walked half its distance after its map had
    /// stopped growing, to scraps along walls and behind furniture (0.1-1.4 m² in sight each)
    /// whose goals mostly ended with no path, twice each, and again after the first `NoPath`
    /// lapsed; this rule walked 0.66x its distance over seeds 11-28 (the default).
    NearestRevealing {
        /// Square metres a frontier must reveal to be walked to, 1 (a patch of floor 1 m
        /// square; a corridor or a room seen through its door shows ten times that or more).
        min_gain: f64,
    },
}

impl Default for FrontierChoice {
    fn default() -> Self {
        Self::NearestRevealing { min_gain: 1.0 }
    }
}

/// Settings of the [`Explorer`](crate::nav::Explorer) and of the exploration loop
/// ([`explore`](crate::nav::explore)). Lengths in metres.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct ExplorerConfig {
    /// The rule the next frontier is picked by.
    pub choice: FrontierChoice,
    /// Frontiers shorter than this many cells are ignored, 5 (0.5 m at 0.10 m cells): a gap
    /// the robot could not see through anyway.
    pub min_frontier_cells: usize,
    /// What a frontier would reveal: the unknown cells in sight of its middle (rays stopped by
    /// the first occupied cell) within this distance, 4 m (a room, a stretch of corridor).
    pub sensor_range: f64,
    /// A frontier's goal is the reachable cell nearest its middle within this distance, 1.5 m,
    /// that sees it (no occupied cell on the segment between them: the nearest cell behind a
    /// wall from a strip seen through a door shows nothing of it); a frontier with none (beyond
    /// the hard inflation of a gap, say) is unreachable.
    pub goal_reach: f64,
    /// The walk to a frontier is re-decided after this many new keyframes, 10 (2 m at the
    /// engine's 0.2 m gate): by then the map has grown and the frontier may be gone.
    pub decide_every: usize,
    /// A frontier goal within this distance of one given up is not tried again, 0.3 m.
    pub give_up_radius: f64,
    /// Arrived at a frontier goal within this distance, 0.3 m (the navigator's own goal
    /// tolerance is for goals that must be met to the centimetre; a frontier need not).
    pub arrive_within: f64,
    /// The map is rendered (occupancy grid and the cloud the navigator localises against) from
    /// one keyframe per square of this side, 1 m, and the newest: a LiDAR sees all round, and
    /// the render then costs what the area explored costs, not the length of the walk.
    pub keyframe_spacing: f64,
    /// The map cloud the navigator localises against is thinned to this voxel, 0.1 m (the
    /// localiser's own).
    pub map_voxel: f32,
    /// Each walk's navigator localises against the map within this distance of where the walk
    /// starts (horizontally), 30 m, and the walk is re-decided once the robot is half of it
    /// from there: setting up the navigator then costs the same at the end of a long
    /// exploration as at its start, where the whole map took 12 ms mean and 25 ms at the end on
    /// the office floor. At least twice [`Self::sensor_range`].
    pub localise_within: f64,
}

impl Default for ExplorerConfig {
    fn default() -> Self {
        Self {
            choice: FrontierChoice::default(),
            min_frontier_cells: 5,
            sensor_range: 4.0,
            goal_reach: 1.5,
            decide_every: 10,
            give_up_radius: 0.3,
            arrive_within: 0.3,
            keyframe_spacing: 1.0,
            map_voxel: 0.1,
            localise_within: 30.0,
        }
    }
}

impl ExplorerConfig {
    /// Every length finite and positive (the choice's detour or margin not negative), the counts at
    /// least 1, `localise_within` at least twice `sensor_range`.
    ///
    /// # Errors
    /// [`NavError::InvalidConfig`] naming the first bad setting.
    pub fn validate(&self) -> Result<(), NavError> {
        for (setting, value) in [
            ("ExplorerConfig::sensor_range", self.sensor_range),
            ("ExplorerConfig::goal_reach", self.goal_reach),
            ("ExplorerConfig::give_up_radius", self.give_up_radius),
            ("ExplorerConfig::arrive_within", self.arrive_within),
            ("ExplorerConfig::keyframe_spacing", self.keyframe_spacing),
            ("ExplorerConfig::map_voxel", f64::from(self.map_voxel)),
            ("ExplorerConfig::localise_within", self.localise_within),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(NavError::invalid(setting, value, "finite and positive"));
            }
        }
        for (setting, value) in [
            (
                "ExplorerConfig::min_frontier_cells",
                self.min_frontier_cells,
            ),
            ("ExplorerConfig::decide_every", self.decide_every),
        ] {
            if value == 0 {
                return Err(NavError::invalid(setting, 0.0, "at least 1"));
            }
        }
        let metres = "finite and not negative (metres)";
        let margin = match self.choice {
            FrontierChoice::InformationGain { detour } => {
                Some(("FrontierChoice::InformationGain::detour", detour, metres))
            }
            FrontierChoice::Tour { keep_margin } => {
                Some(("FrontierChoice::Tour::keep_margin", keep_margin, metres))
            }
            FrontierChoice::NearestRevealing { min_gain } => Some((
                "FrontierChoice::NearestRevealing::min_gain",
                min_gain,
                "finite and not negative (square metres)",
            )),
            FrontierChoice::GreedyNearestFrontier => None,
        };
        if let Some((setting, value, expected)) = margin
            && !(value.is_finite() && value >= 0.0)
        {
            return Err(NavError::invalid(setting, value, expected));
        }
        // The walk's map must hold what the robot sees of its frontier from where it stands.
        if self.localise_within < 2.0 * self.sensor_range {
            return Err(NavError::invalid(
                "ExplorerConfig::localise_within",
                self.localise_within,
                "at least twice sensor_range",
            ));
        }
        Ok(())
    }
}
