//! The command line: `Args`, `--planner` and the settings file.

use std::path::PathBuf;

use clap::{Parser, ValueEnum};
use nalgebra::Vector2;
use serde::{Deserialize, Serialize};
use slam_core::GraphSlamConfig;
use spot_adapter::nav::{ExplorerConfig, FrontierChoice, NavigatorConfig};
use spot_adapter::pipelines::slam_config;
use spot_adapter::sim::{BuildingConfig, LidarConfig};
use spot_nav_examples::{Registration, SettingsArgs, parse_goal, parse_numbers};

/// The main job on a simulated Spot: map an unknown building, then walk to goals in it.
///
/// By default Spot starts at a random reachable spot of the generated building and explores it
/// with no map and no route (Graph-SLAM mapping live, the nearest frontier that would reveal
/// at least 1 m² walked to next) until no reachable frontier worth a walk is left; with `--lap`
/// it maps in one scripted lap of the corridor loop instead (a route from the true floor plan,
/// as an operator would walk it). Then it walks to each goal in turn on that map with no recorded
/// route (localising against the map each scan, replanning on its inflated occupancy grid),
/// around boxes dropped on the routes after mapping. Prints the mapping accuracy and every
/// leg's result against the simulator's ground truth, and writes the map, the grid picture,
/// the ROS map, the trajectories and `summary.json` to `--out`. Fails when the exploration
/// ends below `--min-coverage`, a goal is not reached within 0.10 m (by the ground truth) or
/// the robot collides.
#[derive(Debug, Parser)]
#[command(name = "mission")]
pub(crate) struct Args {
    /// Seed of the building, the sensor noise and the odometry drift.
    #[arg(
        long,
        value_name = "N",
        allow_negative_numbers = true,
        default_value_t = 3
    )]
    pub(crate) seed: u64,
    /// Random reachable goals to visit (from a fixed generator seeded by `--seed`; after an
    /// exploration, anywhere it mapped free and reachable, rooms included), when no `--goal` is
    /// given.
    #[arg(
        long,
        value_name = "K",
        allow_negative_numbers = true,
        default_value_t = 5
    )]
    pub(crate) goals: usize,
    /// A goal in metres in the map frame (where the robot started mapping, x ahead); repeat for
    /// several, visited in order. Replaces the random goals.
    #[arg(long, value_name = "X,Y", allow_hyphen_values = true, value_parser = parse_goal)]
    pub(crate) goal: Vec<Vector2<f64>>,
    /// Boxes dropped on the routes of as many legs after mapping (never on the first).
    #[arg(
        long,
        value_name = "M",
        allow_negative_numbers = true,
        default_value_t = 1
    )]
    pub(crate) obstacles: usize,
    /// Start navigating with the estimate this far off the truth: metres, degrees.
    #[arg(long, value_name = "METRES,DEGREES", allow_hyphen_values = true, value_parser = parse_numbers::<2>)]
    pub(crate) kidnap: Option<[f64; 2]>,
    /// Map in one scripted lap of the corridor loop (a route from the true floor plan) instead
    /// of exploring.
    #[arg(long)]
    pub(crate) lap: bool,
    /// Floors of the simulated office (1 to 3). Above one, Spot maps by a scripted tour of
    /// every floor by the stairs (a lap of each floor, up and back down), then walks to the
    /// goals, each on another floor than the one before, by the stairs.
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub(crate) floors: usize,
    /// The rule the explorer picks the next frontier by [default: the settings'
    /// `explorer.choice`, the nearest revealing one].
    #[arg(long, value_enum, conflicts_with = "lap")]
    pub(crate) frontier: Option<FrontierRule>,
    /// The exploration's scan budget (5 Hz): it stops there if frontiers are left.
    #[arg(long, value_name = "N", default_value_t = 6000, conflicts_with = "lap")]
    pub(crate) max_scans: usize,
    /// The exploration fails below this share of the reachable floor known free (percent).
    #[arg(long, value_name = "PERCENT", default_value_t = 95.0, value_parser = parse_percent, conflicts_with = "lap")]
    pub(crate) min_coverage: f64,
    /// Where the exploration starts: a random spot of the corridor loop, or anywhere reachable
    /// (rooms included; less reliable today: a room's scans of the corridor beyond its door
    /// can leave phantom obstacles across it).
    #[arg(long, value_enum, default_value_t = StartArea::Corridor, conflicts_with = "lap")]
    pub(crate) start: StartArea,
    /// The generated building: `office` (a 34-44 m x 16-20 m corridor loop with rooms on both
    /// sides), `small` (a 10 m x 10 m loop, about 17 m x 17 m in all) or `large` (a 100-110 m x
    /// 44-50 m loop, four times the office or more) [default: small when exploring, office with
    /// `--lap`].
    #[arg(long, value_enum)]
    pub(crate) building: Option<BuildingSize>,
    /// Odometry and loop refinement backend of the mapping.
    #[arg(long, value_enum, default_value_t = Registration::PointToPlane)]
    pub(crate) registration: Registration,
    /// The navigator's planner [default: the settings' `navigator.planner`, cost-aware].
    #[arg(long, value_enum)]
    pub(crate) planner: Option<PlannerChoice>,
    /// Where the outputs go.
    #[arg(long, value_name = "DIR", default_value = "mission-out")]
    pub(crate) out: PathBuf,
    /// The mapping engine's (`[slam]`, a `GraphSlamConfig`), the navigator's (`[navigator]`, a
    /// `NavigatorConfig`; its grid, floor and band also make the map), the explorer's
    /// (`[explorer]`, an `ExplorerConfig`) and the simulated LiDAR's settings (`[lidar]`, a
    /// `LidarConfig`): `--config FILE`, `--print-config`.
    #[command(flatten)]
    pub(crate) settings: SettingsArgs,
}

/// The settings file of `mission` (`--config`, `--print-config`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub(crate) struct Settings {
    /// The mapping engine (exploring or on the lap); by default spot-adapter's `slam_config()`.
    pub(crate) slam: GraphSlamConfig,
    /// The navigator, and the map it plans on (`grid`, `floor`, `band`).
    pub(crate) navigator: NavigatorConfig,
    /// The explorer (unused with `--lap`).
    pub(crate) explorer: ExplorerConfig,
    /// The simulated LiDAR, a VLP-16 by default.
    pub(crate) lidar: LidarConfig,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            slam: slam_config(),
            navigator: NavigatorConfig::default(),
            explorer: ExplorerConfig::default(),
            lidar: LidarConfig::default(),
        }
    }
}

/// `--planner`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum PlannerChoice {
    /// A* under the clearance cost (least cost: keeps to the middle of corridors).
    CostAware,
    /// Jump Point Search.
    Jps,
    /// A* with the octile heuristic.
    Astar,
}

/// `--frontier`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum FrontierRule {
    /// Among the frontiers at most 4 m farther than the nearest, the one that would reveal least
    /// first (scraps before large areas).
    InformationGain,
    /// The nearest frontier (`explore_lite`'s rule, the baseline).
    Greedy,
    /// The first frontier of the shortest walk through them all.
    Tour,
    /// The nearest frontier that would reveal at least 1 m².
    Revealing,
}

impl FrontierRule {
    /// `choice` if it is already this rule (its margins from the settings), else this rule with
    /// its default margin.
    pub(crate) fn apply(self, choice: FrontierChoice) -> FrontierChoice {
        match (self, choice) {
            (Self::InformationGain, FrontierChoice::InformationGain { .. })
            | (Self::Greedy, FrontierChoice::GreedyNearestFrontier)
            | (Self::Tour, FrontierChoice::Tour { .. })
            | (Self::Revealing, FrontierChoice::NearestRevealing { .. }) => choice,
            (Self::InformationGain, _) => FrontierChoice::InformationGain { detour: 4.0 },
            (Self::Greedy, _) => FrontierChoice::GreedyNearestFrontier,
            (Self::Tour, _) => FrontierChoice::Tour { keep_margin: 2.0 },
            (Self::Revealing, _) => FrontierChoice::NearestRevealing { min_gain: 1.0 },
        }
    }

    /// The rule of `choice`.
    pub(crate) fn of(choice: FrontierChoice) -> Option<Self> {
        match choice {
            FrontierChoice::InformationGain { .. } => Some(Self::InformationGain),
            FrontierChoice::GreedyNearestFrontier => Some(Self::Greedy),
            FrontierChoice::Tour { .. } => Some(Self::Tour),
            FrontierChoice::NearestRevealing { .. } => Some(Self::Revealing),
            _ => None,
        }
    }
}

/// `--start`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum StartArea {
    /// A random spot on the corridor loop's centre line, facing a random way.
    Corridor,
    /// A random spot anywhere reachable, at least 0.6 m from every obstacle.
    Anywhere,
}

/// `--building`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum BuildingSize {
    /// The generator's defaults: an office floor of about 50 m x 30 m.
    Office,
    /// About the smallest building the generator makes (`BuildingConfig::small`).
    Small,
    /// Four times the office floor or more (`BuildingConfig::large`: a 100-110 m x 44-50 m
    /// corridor loop, about 115 m x 57 m in all).
    Large,
}

impl BuildingSize {
    /// `--building`, else the small building when exploring (it takes seconds) and the office
    /// on the lap.
    pub(crate) fn chosen(args: &Args) -> Self {
        args.building.unwrap_or(if args.lap || args.floors > 1 {
            Self::Office
        } else {
            Self::Small
        })
    }

    pub(crate) fn config(self) -> BuildingConfig {
        match self {
            Self::Office => BuildingConfig::default(),
            Self::Small => BuildingConfig::small(),
            Self::Large => BuildingConfig::large(),
        }
    }
}

/// A percentage from 0 to 100.
fn parse_percent(text: &str) -> Result<f64, String> {
    let value: f64 = text
        .parse()
        .map_err(|e| format!("{text:?} is not a number: {e}"))?;
    if (0.0..=100.0).contains(&value) {
        Ok(value)
    } else {
        Err(format!("{value} is not between 0 and 100"))
    }
}
