//! What the navigation tests share: a building's map from true-pose scans, random reachable
//! goals, and a navigator on a commanded Spot driven through the `Robot` interface.
#![allow(dead_code, clippy::unwrap_used)]

use nalgebra::Vector2;
use slam_core::{PointCloud, Pose3};
use spot_adapter::nav::{
    DriveOutcome, NavigationMap, NavigationMapConfig, Navigator, NavigatorConfig, drive,
};
use spot_adapter::pipelines::point_to_plane_localiser;
use spot_adapter::robot::Robot;
use spot_adapter::sim::{
    Building, BuildingConfig, CommandedSpot, Route, RouteConfig, SimRng, SimulatedSpot,
    SimulationConfig,
};

/// The building of `seed`, a map cloud of it and its navigation map: every 4th scan of one lap
/// of its corridor loop (with the noise of seed 0), at its true pose (map frame = world frame),
/// the cloud thinned to 5 cm.
pub fn building_and_map(seed: u64) -> (Building, PointCloud, NavigationMap) {
    let building = Building::generate(seed, &BuildingConfig::default()).unwrap();
    let lap = Route::corridor_loop(&building);
    let config = SimulationConfig::default();
    let sim = SimulatedSpot::new(building, &lap, &config).unwrap();
    let building = sim.building().clone();
    let body_t_lidar = sim.body_t_lidar();
    let mut points = Vec::new();
    let mut scans = Vec::new();
    for sample in sim.step_by(4) {
        let world_t_lidar = sample.ground_truth.unwrap() * body_t_lidar;
        points.extend_from_slice(sample.cloud.transformed(&world_t_lidar).points());
        scans.push((world_t_lidar, sample.cloud.voxel_downsample(0.05).unwrap()));
    }
    let map = PointCloud::from_points(points)
        .voxel_downsample(0.05)
        .unwrap();
    let lidar_height = config.spot.body_height + config.spot.body_t_lidar.translation.z;
    let refs: Vec<(Pose3, &PointCloud)> = scans.iter().map(|(p, c)| (*p, c)).collect();
    let navigation =
        NavigationMap::from_scans(&refs, lidar_height, &NavigationMapConfig::default()).unwrap();
    (building, map, navigation)
}

/// `count` goals drawn in rooms and corridors of `building`: at least 0.6 m from every
/// obstacle, on floor the map saw (a floor point of `map` within 0.25 m), each reachable with
/// Spot's clearance from the one before (the first from `start`).
pub fn random_goals(
    building: &Building,
    map: &PointCloud,
    start: Vector2<f64>,
    count: usize,
    seed: u64,
) -> Vec<Vector2<f64>> {
    let floor: Vec<Vector2<f64>> = map
        .points()
        .iter()
        .filter(|p| p.z < 0.1)
        .map(|p| Vector2::new(f64::from(p.x), f64::from(p.y)))
        .collect();
    let cell = 0.25;
    let key = |p: Vector2<f64>| ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64);
    let seen: std::collections::HashSet<(i64, i64)> = floor.iter().map(|&p| key(p)).collect();
    let mut rng = SimRng::new(seed, 0x90a1);
    let mut goals = Vec::with_capacity(count);
    let mut from = start;
    let size = building.size();
    while goals.len() < count {
        let p = Vector2::new(rng.range(0.0, size.x), rng.range(0.0, size.y));
        let observed = seen.contains(&key(p));
        if observed
            && building.clearance(p) >= 0.6
            && (p - from).norm() > 2.0
            && Route::between(building, from, p, &RouteConfig::default()).is_ok()
        {
            goals.push(p);
            from = p;
        }
    }
    goals
}

/// One leg of a multi-goal run, measured on the ground truth.
#[derive(Clone, Debug)]
pub struct Leg {
    pub goal: Vector2<f64>,
    pub outcome: DriveOutcome,
    /// True distance from the goal at the end (metres).
    pub error: f64,
    pub collisions: usize,
    pub cycles: usize,
    pub walked: f64,
    /// Largest localisation error on the leg (metres) above 5 cm, or 0.
    pub worst_localisation: f64,
    /// The first cycle whose localisation error was under 5 cm, if one was.
    pub localised_after: Option<usize>,
    /// The largest localisation error from that cycle on (metres).
    pub worst_after_localised: f64,
}

/// Where a run starts: the true position and heading, and how far the navigator's first
/// estimate is off (`true_pose * kidnap`).
pub struct Start {
    pub position: Vector2<f64>,
    pub yaw: f64,
    pub kidnap: Pose3,
    /// Legs (0-based) before which a 0.6 m box is dropped on the route to their goal (or of
    /// the next leg whose route has room for one 2 m from both ends).
    pub boxes_before: Vec<usize>,
    /// People walking to and fro between two points at 1 m/s from the start (0.5 m square,
    /// 1.7 m tall), seen by the LiDAR and counted by the collision check.
    pub walkers: Vec<(Vector2<f64>, Vector2<f64>)>,
}

impl Start {
    /// At `position` facing east, the estimate exact.
    pub fn at(position: Vector2<f64>) -> Self {
        Self {
            position,
            yaw: 0.0,
            kidnap: Pose3::identity(),
            boxes_before: Vec::new(),
            walkers: Vec::new(),
        }
    }
}

/// Drives a commanded Spot from `start` through `goals` in turn on `map`, each leg starting
/// where the last ended, at most `cycles` scans a leg.
pub fn run_legs(
    building: &Building,
    map: &PointCloud,
    navigation: &NavigationMap,
    start: &Start,
    goals: &[Vector2<f64>],
    cycles: usize,
    config: &NavigatorConfig,
) -> Vec<Leg> {
    let kidnap = &start.kidnap;
    let sim = SimulationConfig::default();
    let mut spot = CommandedSpot::new(building.clone(), start.position, start.yaw, &sim).unwrap();
    for &(from, to) in &start.walkers {
        spot.add_walker(from, to, 1.0, Vector2::new(0.25, 0.25), 1.7)
            .unwrap();
    }
    let mut nav = Navigator::new(
        point_to_plane_localiser(),
        map,
        navigation,
        // The estimate starts `kidnap` away from the truth.
        spot.body_pose() * kidnap,
        spot.description(),
        config.clone(),
    )
    .unwrap();
    let mut legs = Vec::new();
    let mut pending = 0;
    for (k, &goal) in goals.iter().enumerate() {
        pending += start.boxes_before.iter().filter(|&&b| b == k).count();
        if pending > 0
            && let Some(solid) = spot.building().obstacle_on_route(
                spot.position(),
                goal,
                0.6,
                &RouteConfig::default(),
            )
        {
            spot.building_mut().add_box(solid).unwrap();
            pending -= 1;
            eprintln!("box before leg {k}: {solid:?}");
        } else if pending > 0 {
            eprintln!(
                "no room for a box before leg {k}, from {:?} to {goal:?}",
                spot.position()
            );
        }
        let collisions_before = spot.collisions();
        let (mut worst, mut walked) = (0.0f64, 0.0);
        let mut last: Option<Vector2<f64>> = None;
        let (mut cycle_count, mut localised_from) = (0usize, None);
        let mut worst_after = 0.0f64;
        let report = drive(&mut spot, &mut nav, goal, cycles, |cycle| {
            cycle_count += 1;
            let truth = cycle.sample.ground_truth.unwrap().translation.vector.xy();
            let error = (cycle.estimate.translation.vector.xy() - truth).norm();
            if error < 0.05 {
                localised_from.get_or_insert(cycle_count);
            } else {
                worst = worst.max(error);
            }
            if localised_from.is_some() {
                worst_after = worst_after.max(error);
            }
            walked += last.map_or(0.0, |p| (truth - p).norm());
            last = Some(truth);
        })
        .unwrap();
        legs.push(Leg {
            goal,
            outcome: report.outcome,
            error: (spot.position() - goal).norm(),
            collisions: spot.collisions() - collisions_before,
            cycles: report.cycles,
            walked,
            worst_localisation: worst,
            localised_after: localised_from,
            worst_after_localised: worst_after,
        });
    }
    assert_eq!(pending, 0, "no room for every box on the routes");
    legs
}

/// Every loop edge (nodes whose ids are not consecutive) of `slam`'s final graph: whether the
/// optimiser kept it (weight at least 0.5, or an optimiser that keeps every edge) and the
/// distance between its measurement and the ground truth's relative pose, from `world_t_lidar`
/// keyed by the scans' stamps (`f64::to_bits`).
pub fn loop_edges_against_truth<
    R: slam_core::MapRegistrator,
    C: slam_core::MapRegistrator,
    O: slam_core::Optimizer<Pose3>,
>(
    slam: &slam_core::GraphSlam<R, C, O>,
    world_t_lidar: &std::collections::HashMap<u64, Pose3>,
) -> Vec<(bool, f64)> {
    let stamps: Vec<u64> = slam
        .keyframe_trajectory()
        .iter()
        .map(|k| k.stamp.to_bits())
        .collect();
    let graph = slam.graph();
    let weights = slam.optimizer().edge_weights().unwrap_or(&[]);
    let pose_of = |id: u64| world_t_lidar[&stamps[usize::try_from(id).unwrap()]];
    graph
        .edges()
        .iter()
        .enumerate()
        .filter(|(_, e)| graph.nodes()[e.from].id.abs_diff(graph.nodes()[e.to].id) != 1)
        .map(|(k, e)| {
            let (a, b) = (graph.nodes()[e.from].id, graph.nodes()[e.to].id);
            let truth = pose_of(a).inverse() * pose_of(b);
            let error = (truth.translation.vector - e.measurement.translation.vector).norm();
            (weights.get(k).is_none_or(|&w| w >= 0.5), error)
        })
        .collect()
}
