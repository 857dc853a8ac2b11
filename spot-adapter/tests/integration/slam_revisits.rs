//! A walk through a mapped building again adds no keyframes: the engine rides on the keyframes
//! of the first lap, stays localised (against the simulator's ground truth), and its graph stays
//! connected; with revisits off, the same walk keeps adding keyframes.
#![allow(clippy::unwrap_used)]

use std::collections::HashSet;

use nalgebra::Point3;
use nalgebra::Vector2;
use slam_core::GraphSlamConfig;
use spot_adapter::eval::TrajectoryEvaluation;
use spot_adapter::pipelines::{
    PointToPlaneSlam, point_to_plane_slam, scan_context_places, slam_config,
};
use spot_adapter::sim::{
    BoxKind, Building, BuildingConfig, Route, SimulatedSpot, SimulationConfig, SolidBox,
};

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

/// Seed 1's corridor lap in the empty building, then its first leg again in the same building
/// with crates along that leg (LiDAR-only: the two walks are stitched by their stamps).
#[test]
fn a_changed_place_gets_new_keyframes_and_the_map_shows_the_change() {
    let seed = 1;
    let building = Building::generate(seed, &BuildingConfig::default()).unwrap();
    let lap = Route::corridor_loop(&building);
    let (start, corner) = (lap.points()[0], lap.points()[1]);
    let along = (corner - start).normalize();
    let side = Vector2::new(-along.y, along.x);
    let half_width = 0.5 * building.corridor_width();
    let mut changed = building.clone();
    let mut crates = Vec::new();
    for (k, s) in [3.0, 5.0, 7.0, 9.0, 11.0, 13.0].into_iter().enumerate() {
        // Against alternate walls, 0.6 m deep, 2 m long: a corridor turned into a store.
        let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
        let near = start + along * s + side * sign * (half_width - 0.6);
        let far = start + along * (s + 2.0) + side * sign * half_width;
        let solid = SolidBox {
            min: Point3::new(near.x.min(far.x), near.y.min(far.y), 0.0),
            max: Point3::new(near.x.max(far.x), near.y.max(far.y), 1.5),
            kind: BoxKind::Obstacle,
        };
        changed.add_box(solid).unwrap();
        crates.push(solid);
    }
    let config = SimulationConfig::with_seed(seed);
    let first = SimulatedSpot::new(building, &lap, &config).unwrap();
    let second_route = Route::new(vec![start, corner], false).unwrap();
    let second = SimulatedSpot::new(changed, &second_route, &config).unwrap();
    let body_t_lidar = first.body_t_lidar();
    let lap_end = first.ground_truth().last().unwrap().stamp + 0.2;
    let mut truth = first.ground_truth();
    truth.extend(second.ground_truth().into_iter().map(|mut p| {
        p.stamp += lap_end;
        p
    }));
    let mut slam = point_to_plane_slam(slam_config())
        .unwrap()
        .with_place_recognizer(scan_context_places());
    for sample in first {
        slam.process(&sample.lidar_only_input());
    }
    let after_lap = slam.keyframe_count();
    let revisits_after_lap = slam.report().revisits;
    let lap_scans = slam.scan_trajectory().len();
    for sample in second {
        let mut input = sample.lidar_only_input();
        input.stamp += lap_end;
        slam.process(&input);
    }
    let report = slam.report();
    assert!(report.revisits > revisits_after_lap, "{report:?}");
    // New keyframes where the crates changed the place (seen from up to a few metres away).
    let added: Vec<_> = slam.keyframe_trajectory()[after_lap..].to_vec();
    assert!(
        !added.is_empty(),
        "no keyframe for the changed place: {report:?}"
    );
    // LiDAR-only, the map frame is the body frame at the first scan.
    let world_t_map = truth[0].pose;
    for k in &added {
        let p = (world_t_map * k.pose).translation.vector.xy();
        let nearest = crates
            .iter()
            .map(|c| (p - 0.5 * (c.min.coords.xy() + c.max.coords.xy())).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(nearest < 8.0, "a keyframe {nearest:.1} m from any crate");
    }
    // The map now shows the crates.
    let map = slam.map(0.05).unwrap();
    let on_crates = map
        .points()
        .iter()
        .map(|q| world_t_map * Point3::new(f64::from(q.x), f64::from(q.y), f64::from(q.z)))
        .filter(|q| {
            crates
                .iter()
                .any(|c| (0..3).all(|a| q[a] >= c.min[a] - 0.05 && q[a] <= c.max[a] + 0.05))
        })
        .count();
    assert!(on_crates >= 100, "{on_crates} map points on the crates");
    let second_part = slam.scan_trajectory()[lap_scans..].to_vec();
    let (e, _) =
        TrajectoryEvaluation::of_lidar_trajectory(second_part, &body_t_lidar, &truth).unwrap();
    assert!(
        e.ate.rmse <= 0.03,
        "ATE on the changed leg {} m",
        e.ate.rmse
    );
}
