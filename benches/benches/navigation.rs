//! The navigator's cycle on the simulated Spot (seed 3): localising one scan against the map,
//! replanning across the building and the command, with the map built once; and the map's
//! preparation (occupancy grid, inflation, the registrator's target; the planner's labelling of
//! the grid happens once more in `Navigator::new`).
//!
//! `cargo bench -p spot-nav-benches --bench navigation`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use slam_core::{PointCloud, Registrator};
use spot_adapter::nav::{Navigator, NavigatorConfig, navigation_grid};
use spot_adapter::pipelines::point_to_plane_tracker;
use spot_adapter::robot::Robot;
use spot_adapter::sim::{
    Building, BuildingConfig, CommandedSpot, Route, SimulatedSpot, SimulationConfig,
};

fn navigation(c: &mut Criterion) {
    let config = SimulationConfig::default();
    // Building 3 with the noise and drift of seed 0, as the navigation test's map.
    let sim = Building::generate(3, &BuildingConfig::default())
        .and_then(|b| SimulatedSpot::new(b.clone(), &Route::corridor_loop(&b), &config));
    let Ok(sim) = sim else {
        eprintln!("navigation bench: simulation failed; skipping");
        return;
    };
    let building = sim.building().clone();
    let body_t_lidar = sim.body_t_lidar();
    // The map: every 4th scan of one lap at its true pose, thinned to 5 cm (as the tests).
    let mut points = Vec::new();
    for sample in sim.step_by(4) {
        if let Some(truth) = sample.ground_truth {
            points.extend_from_slice(sample.cloud.transformed(&(truth * body_t_lidar)).points());
        }
    }
    let Ok(map) = PointCloud::from_points(points).voxel_downsample(0.05) else {
        return;
    };
    let start = building.corridor_loop()[0];
    // The farthest room's entry: every cycle plans across the building.
    let Some(goal) = building
        .rooms()
        .iter()
        .map(spot_adapter::sim::Room::entry_point)
        .max_by(|a, b| (a - start).norm().total_cmp(&(b - start).norm()))
    else {
        return;
    };
    let Ok(mut spot) = CommandedSpot::new(building, start, 0.0, &config) else {
        return;
    };
    let lidar_height = config.spot.body_height + config.spot.body_t_lidar.translation.z;
    let start_pose = spot.body_pose();
    let mut group = c.benchmark_group("navigation_seed3");
    group.sample_size(10);
    let nav_config = NavigatorConfig::default();
    group.bench_function("prepare_map", |b| {
        b.iter(|| {
            let grid = navigation_grid(&map, lidar_height, &nav_config);
            let target = point_to_plane_tracker().prepare_target(&map);
            black_box((grid.is_ok(), target.is_ok()))
        });
    });
    let Ok(grid) = navigation_grid(&map, lidar_height, &nav_config) else {
        eprintln!("navigation bench: grid failed; skipping");
        return;
    };
    let Ok(mut nav) = Navigator::new(
        point_to_plane_tracker(),
        &map,
        &grid,
        start_pose,
        spot.description(),
        nav_config,
    ) else {
        eprintln!("navigation bench: navigator failed; skipping");
        return;
    };
    let sample = spot.sense();
    // Normals on first use: warm the map's target as a running navigator has.
    if let Err(e) = nav.step(&sample, goal) {
        eprintln!("navigation bench: navigator step failed: {e}; skipping");
        return;
    }
    group.sample_size(30);
    group.bench_function("cycle_localise_plan_command", |b| {
        b.iter(|| black_box(nav.step(&sample, goal)));
    });
    group.finish();
}

criterion_group!(benches, navigation);
criterion_main!(benches);
