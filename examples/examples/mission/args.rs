//! The command line: `Args`, `--planner` and the settings file.

use std::path::PathBuf;

use clap::{Parser, ValueEnum};
use nalgebra::Vector2;
use serde::{Deserialize, Serialize};
use slam_core::GraphSlamConfig;
use spot_adapter::nav::NavigatorConfig;
use spot_adapter::pipelines::slam_config;
use spot_nav_examples::{Registration, SettingsArgs, parse_goal, parse_numbers};

/// The main job on a simulated Spot: map an unknown building, then walk to goals in it.
///
/// Maps the generated building with Graph-SLAM in one lap of its corridor loop, then walks from
/// where the lap ended to each goal in turn on that map with no recorded route (localising
/// against the map each scan, replanning on its inflated occupancy grid), around boxes dropped
/// on the routes after mapping. Prints the mapping accuracy and every leg's result against the
/// simulator's ground truth, and writes the map, the grid picture, the ROS map, the
/// trajectories and `summary.json` to `--out`. Fails when a goal is not reached within 0.10 m
/// (by the ground truth) or the robot collides.
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
    /// Random reachable goals to visit (from a fixed generator seeded by `--seed`), when no
    /// `--goal` is given.
    #[arg(
        long,
        value_name = "K",
        allow_negative_numbers = true,
        default_value_t = 5
    )]
    pub(crate) goals: usize,
    /// A goal in metres in the map frame (where the lap started, x ahead); repeat for several,
    /// visited in order. Replaces the random goals.
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
    /// Odometry and loop refinement backend of the mapping lap.
    #[arg(long, value_enum, default_value_t = Registration::PointToPlane)]
    pub(crate) registration: Registration,
    /// The navigator's planner [default: the settings' `navigator.planner`, cost-aware].
    #[arg(long, value_enum)]
    pub(crate) planner: Option<PlannerChoice>,
    /// Where the outputs go.
    #[arg(long, value_name = "DIR", default_value = "mission-out")]
    pub(crate) out: PathBuf,
    /// The mapping engine's (`[slam]`, a `GraphSlamConfig`) and the navigator's settings
    /// (`[navigator]`, a `NavigatorConfig`; its grid, floor and band also make the map):
    /// `--config FILE`, `--print-config`.
    #[command(flatten)]
    pub(crate) settings: SettingsArgs,
}

/// The settings file of `mission` (`--config`, `--print-config`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub(crate) struct Settings {
    /// The mapping lap's engine; by default spot-adapter's `slam_config()`.
    pub(crate) slam: GraphSlamConfig,
    /// The navigator, and the map it plans on (`grid`, `floor`, `band`).
    pub(crate) navigator: NavigatorConfig,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            slam: slam_config(),
            navigator: NavigatorConfig::default(),
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
