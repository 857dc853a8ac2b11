//! A walk through a mapped building again adds no keyframes: the engine rides on the keyframes
//! of the first lap, stays localised (against the simulator's ground truth), and its graph stays
//! connected; with revisits off, the same walk keeps adding keyframes.
#![allow(clippy::unwrap_used)]

use std::collections::HashSet;

use nalgebra::Vector2;
use slam_core::GraphSlamConfig;
use spot_adapter::eval::TrajectoryEvaluation;
use spot_adapter::pipelines::{
    PointToPlaneSlam, point_to_plane_slam, scan_context_places, slam_config,
};
use spot_adapter::sim::{Building, BuildingConfig, Route, SimulatedSpot, SimulationConfig};

/// What one walk left: the keyframes after the first lap, the engine, and the ATE (metres) of
/// the part after the first lap.
struct Walk {
    keyframes_after_lap: usize,
    slam: PointToPlaneSlam,
    second_part_ate: f64,
}

/// Seed 1's corridor lap, then half of it again 0.2 m to the side.
fn walk(config: GraphSlamConfig) -> Walk {
    let seed = 1;
    let building = Building::generate(seed, &BuildingConfig::default()).unwrap();
    let lap = Route::corridor_loop(&building);
    let sim_config = SimulationConfig::with_seed(seed);
    let lap_samples = SimulatedSpot::new(building.clone(), &lap, &sim_config)
        .unwrap()
        .len();
    let shift = Vector2::new(0.14, 0.14);
    let mut points = lap.points().to_vec();
    points.extend(lap.points()[..3].iter().map(|p| p + shift));
    let route = Route::new(points, false).unwrap();
    let sim = SimulatedSpot::new(building, &route, &sim_config).unwrap();
    let body_t_lidar = sim.body_t_lidar();
    let truth = sim.ground_truth();
    let mut slam = point_to_plane_slam(config)
        .unwrap()
        .with_place_recognizer(scan_context_places());
    let mut keyframes_after_lap = 0;
    for (i, sample) in sim.enumerate() {
        slam.process(&sample.scan_input());
        if i + 1 == lap_samples {
            keyframes_after_lap = slam.keyframe_count();
        }
    }
    let second_part: Vec<_> = slam.scan_trajectory()[lap_samples..].to_vec();
    let (e, _) =
        TrajectoryEvaluation::of_lidar_trajectory(second_part, &body_t_lidar, &truth).unwrap();
    Walk {
        keyframes_after_lap,
        slam,
        second_part_ate: e.ate.rmse,
    }
}

#[test]
fn a_second_walk_through_a_mapped_corridor_rides_on_its_keyframes() {
    let revisits = walk(slam_config());
    let report = revisits.slam.report();
    let added = report.keyframes - revisits.keyframes_after_lap;
    // The second part walks 40 m (about 165 keyframes' worth, as revisits off shows below):
    // the map already has it all.
    assert!(
        added <= 5,
        "{added} keyframes added on the revisit: {report:?}"
    );
    assert!(report.revisits >= 150, "{report:?}");
    assert!(report.loops_closed >= 1, "{report:?}");
    assert!(
        revisits.second_part_ate <= 0.03,
        "ATE on the revisit {} m",
        revisits.second_part_ate
    );
    // Connected: every node but the first has an odometry edge from an earlier node.
    let graph = revisits.slam.graph();
    let ids: Vec<u64> = graph.nodes().iter().map(|n| n.id).collect();
    assert_eq!(revisits.slam.loop_edges().len(), report.loops_closed);
    let reached: HashSet<u64> = graph
        .edges()
        .iter()
        .filter(|e| ids[e.from] < ids[e.to])
        .map(|e| ids[e.to])
        .collect();
    assert!(ids[1..].iter().all(|id| reached.contains(id)));

    // Today's behaviour beside it: a keyframe every 0.2 m, revisit or not.
    let mut every = slam_config();
    every.revisit_radius = 0.0;
    let every = walk(every);
    let report = every.slam.report();
    assert!(
        report.keyframes - every.keyframes_after_lap >= 150,
        "{report:?}"
    );
    assert_eq!(report.revisits, 0);
}
