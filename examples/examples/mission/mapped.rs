//! The map the legs walk on, made by exploring from a random spot (the default) or by the
//! scripted lap (`--lap`), with the simulated Spot standing where the mapping ended.

use anyhow::{Context, Result};
use nalgebra::Vector2;
use slam_core::io::StampedPose;
use slam_core::{GraphSlamConfig, PointCloud, Pose3};
use spot_adapter::nav::{ExplorerConfig, NavigationMap, NavigatorConfig};
use spot_adapter::pipelines::{loam_slam, point_to_plane_slam, scan_context_places};
use spot_adapter::sim::{Building, CommandedSpot, SimulatedSpot, SimulationConfig};
use spot_nav_examples::{Registration, out};

use crate::args::StartArea;
use crate::exploring::{explore_building, random_start};
use crate::legs::Frames;
use crate::mapping::map_building;
use crate::report::{ExplorationSummary, MappingSummary};

/// A mapped building and the robot in it, ready for the legs.
pub(crate) struct Mapped {
    /// The robot, standing where the mapping ended.
    pub(crate) spot: CommandedSpot,
    pub(crate) frames: Frames,
    pub(crate) map: PointCloud,
    pub(crate) navigation: NavigationMap,
    /// The engine's estimate of the body where the mapping ended (map frame).
    pub(crate) map_t_body: Pose3,
    /// Where the robot started mapping (exploring) or navigating (after the lap), world frame.
    pub(crate) start: Vector2<f64>,
    /// The body's estimate and ground truth while exploring (map frame); empty after a lap.
    pub(crate) trajectories: (Vec<StampedPose>, Vec<StampedPose>),
    /// Frontier cells left on the map (map frame); none after a lap.
    pub(crate) frontiers_left: Vec<Vector2<f64>>,
    pub(crate) lap: Option<MappingSummary>,
    pub(crate) exploration: Option<ExplorationSummary>,
}

/// What the mapping needs besides the simulation.
pub(crate) struct MappingSettings<'a> {
    pub(crate) registration: Registration,
    pub(crate) slam: GraphSlamConfig,
    pub(crate) navigator: &'a NavigatorConfig,
    pub(crate) explorer: &'a ExplorerConfig,
    pub(crate) max_scans: usize,
    /// Where an exploration starts.
    pub(crate) start: StartArea,
}

fn print_building(building: &Building, seed: u64) -> Result<()> {
    out!(
        "building    seed {seed}: {:.1} x {:.1} m, {} rooms",
        building.size().x,
        building.size().y,
        building.rooms().len()
    )
}

/// One lap of the corridor loop of `config`'s building mapped, the robot where the lap ended.
pub(crate) fn by_lap(config: &SimulationConfig, settings: MappingSettings<'_>) -> Result<Mapped> {
    let sim = SimulatedSpot::corridor_loop(config)?;
    let building = sim.building().clone();
    let truth = sim.ground_truth();
    let frames = Frames {
        world_t_map: truth.first().context("empty lap")?.pose,
    };
    let lap_end = truth.last().context("empty lap")?.pose;
    print_building(&building, config.seed)?;
    let map_config = settings.navigator.map_config();
    let mapped = match settings.registration {
        // Loops by position and by appearance, as the slam example seeks them.
        Registration::PointToPlane => map_building(
            point_to_plane_slam(settings.slam)?.with_place_recognizer(scan_context_places()),
            sim,
            &map_config,
        )?,
        Registration::Loam => map_building(
            loam_slam(settings.slam)?.with_place_recognizer(scan_context_places()),
            sim,
            &map_config,
        )?,
    };
    let start = lap_end.translation.vector.xy();
    let spot = CommandedSpot::new(building, start, lap_end.rotation.euler_angles().2, config)?;
    Ok(Mapped {
        spot,
        frames,
        map: mapped.map,
        navigation: mapped.navigation,
        map_t_body: mapped.map_t_body,
        start,
        trajectories: (Vec::new(), Vec::new()),
        frontiers_left: Vec::new(),
        lap: Some(mapped.summary),
        exploration: None,
    })
}

/// `config`'s building explored from a random reachable spot (seeded by `config.seed`), the
/// robot where the exploration ended.
pub(crate) fn by_exploring(
    config: &SimulationConfig,
    settings: MappingSettings<'_>,
) -> Result<Mapped> {
    let building = Building::generate(config.seed, &config.building)?;
    print_building(&building, config.seed)?;
    let (start, yaw) = random_start(&building, settings.start, config.seed)?;
    let mut spot = CommandedSpot::new(building, start, yaw, config)?;
    // The engine's map frame is the odometry frame, which starts at the body's start pose.
    let frames = Frames {
        world_t_map: spot.body_pose(),
    };
    out!(
        "start       ({:.1}, {:.1}) m facing {:.0}°, exploring by {}",
        start.x,
        start.y,
        yaw.to_degrees(),
        crate::args::FrontierRule::of(settings.explorer.choice).map_or_else(
            || format!("{:?}", settings.explorer.choice),
            |r| spot_nav_examples::value_name(&r)
        )
    )?;
    let (navigator, explorer, max_scans) =
        (settings.navigator, settings.explorer, settings.max_scans);
    let explored = match settings.registration {
        Registration::PointToPlane => explore_building(
            point_to_plane_slam(settings.slam)?,
            &mut spot,
            &frames,
            navigator,
            explorer,
            max_scans,
        )?,
        Registration::Loam => explore_building(
            loam_slam(settings.slam)?,
            &mut spot,
            &frames,
            navigator,
            explorer,
            max_scans,
        )?,
    };
    Ok(Mapped {
        spot,
        frames,
        map: explored.map,
        navigation: explored.navigation,
        map_t_body: explored.map_t_body,
        start,
        trajectories: explored.trajectories,
        frontiers_left: explored.frontiers_left,
        lap: None,
        exploration: Some(explored.summary),
    })
}
