//! The navigator on the simulated Spot (seed 3), with the map built once:
//! - `navigation_seed3/prepare_map`: the navigation map from the lap's scans (floor, obstacle
//!   band, free space from the beams) and the registrator's target;
//! - `navigation_seed3/cycle`: one full cycle on a scan (localise against the whole map, fuse
//!   the scan into the live layer, plan across the building, command);
//! - printed after the criterion groups: every cycle of a walk into the farthest room (mean,
//!   p99 and max), the cost users see, replans included; beside it, in lockstep, the same walk
//!   registering every scan in full to 0.1 mm steps, and the ratio of the two means.
//!
//! `cargo bench -p spot-nav-benches --bench navigation`

use std::hint::black_box;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use slam_core::{PointCloud, Pose3, Registrator};
use spot_adapter::nav::{NavigationMap, NavigationStep, Navigator, NavigatorConfig};
use spot_adapter::pipelines::point_to_plane_localiser;
use spot_adapter::robot::{MobilityCommand, Robot};
use spot_adapter::sim::{
    Building, BuildingConfig, CommandedSpot, Route, SimulatedSpot, SimulationConfig,
};

/// Scans with their `map_T_lidar`.
type Scans = Vec<(Pose3, PointCloud)>;

/// Building 3, its map cloud and its navigation map from every 4th scan of one lap at its true
/// pose (as the navigation tests build them).
fn setup() -> Option<(Building, PointCloud, Scans)> {
    let config = SimulationConfig::default();
    let building = Building::generate(3, &BuildingConfig::default()).ok()?;
    let sim =
        SimulatedSpot::new(building.clone(), &Route::corridor_loop(&building), &config).ok()?;
    let body_t_lidar = sim.body_t_lidar();
    let mut points = Vec::new();
    let mut scans = Vec::new();
    for sample in sim.step_by(4) {
        let world_t_lidar = sample.ground_truth? * body_t_lidar;
        points.extend_from_slice(sample.cloud.transformed(&world_t_lidar).points());
        scans.push((world_t_lidar, sample.cloud.voxel_downsample(0.05).ok()?));
    }
    let map = PointCloud::from_points(points)
        .voxel_downsample(0.05)
        .ok()?;
    Some((building, map, scans))
}

fn navigation(c: &mut Criterion) {
    let Some((building, map, scans)) = setup() else {
        eprintln!("navigation bench: simulation failed; skipping");
        return;
    };
    let config = SimulationConfig::default();
    let lidar_height = config.spot.body_height + config.spot.body_t_lidar.translation.z;
    let refs: Vec<(Pose3, &PointCloud)> = scans.iter().map(|(p, c)| (*p, c)).collect();
    let nav_config = NavigatorConfig::default();
    let map_config = nav_config.map_config();
    let start = building.corridor_loop()[0];
    // The farthest room's entry: every plan crosses the building.
    let Some(goal) = building
        .rooms()
        .iter()
        .map(spot_adapter::sim::Room::entry_point)
        .max_by(|a, b| (a - start).norm().total_cmp(&(b - start).norm()))
    else {
        return;
    };
    let mut group = c.benchmark_group("navigation_seed3");
    group.sample_size(10);
    group.bench_function("prepare_map", |b| {
        b.iter(|| {
            let navigation = NavigationMap::from_scans(&refs, lidar_height, &map_config);
            let target = point_to_plane_localiser().prepare_target(&map);
            black_box((navigation.is_ok(), target.is_ok()))
        });
    });
    let Ok(navigation) = NavigationMap::from_scans(&refs, lidar_height, &map_config) else {
        eprintln!("navigation bench: navigation map failed; skipping");
        return;
    };
    let Ok(mut spot) = CommandedSpot::new(building.clone(), start, 0.0, &config) else {
        return;
    };
    let Ok(mut nav) = Navigator::new(
        point_to_plane_localiser(),
        &map,
        &navigation,
        spot.body_pose(),
        spot.description(),
        nav_config.clone(),
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
    // The same scan again and again: each cycle localises and fuses it; stamps may not go back,
    // so each cycle's sample is a little later.
    let mut later = sample.clone();
    group.bench_function("cycle", |b| {
        b.iter(|| {
            later.stamp += 0.2;
            black_box(nav.step(&later, goal).ok())
        });
    });
    group.finish();
    walk_cycles(&building, &map, &navigation, start, goal, &nav_config);
}

/// A walk's cycle times (ms): mean, p99, max.
fn summary(ms: &mut [f64]) -> (f64, f64, f64) {
    ms.sort_by(f64::total_cmp);
    let n = ms.len().max(1);
    let mean = ms.iter().sum::<f64>() / n as f64;
    let p99 = ms[((ms.len() as f64 * 0.99) as usize).min(ms.len().saturating_sub(1))];
    (mean, p99, ms[ms.len() - 1])
}

/// Every cycle's time over a walk into the farthest room, printed: the navigator as shipped,
/// and beside it, cycle for cycle in the same process (so the machine's drift hits both alike),
/// the same navigator registering every scan in full and to 0.1 mm steps (before 2026-12-03).
fn walk_cycles(
    building: &Building,
    map: &PointCloud,
    navigation: &NavigationMap,
    start: nalgebra::Vector2<f64>,
    goal: nalgebra::Vector2<f64>,
    config: &NavigatorConfig,
) {
    let sim = SimulationConfig::default();
    let mut full = config.clone();
    full.localiser.walking_scan_voxel = 0.0;
    let mut fine = point_to_plane_localiser();
    fine.config.translation_tolerance = 1e-4;
    let variants = [
        ("walk", point_to_plane_localiser(), config.clone()),
        ("walk, full scans to 0.1 mm", fine, full),
    ];
    let mut runs = Vec::new();
    for (name, registrator, config) in variants {
        let Ok(spot) = CommandedSpot::new(building.clone(), start, 0.0, &sim) else {
            return;
        };
        let Ok(nav) = Navigator::new(
            registrator,
            map,
            navigation,
            spot.body_pose(),
            spot.description(),
            config,
        ) else {
            return;
        };
        runs.push((name, spot, nav, Vec::new(), false));
    }
    for i in 0..1500 {
        // Alternate which goes first.
        for k in 0..runs.len() {
            let (_, spot, nav, ms, done) = &mut runs[(i + k) % 2];
            if *done {
                continue;
            }
            let Ok(sample) = spot.next_sample() else {
                return;
            };
            let t = Instant::now();
            let step = nav.step(&sample, goal);
            ms.push(t.elapsed().as_secs_f64() * 1e3);
            match step {
                Ok(NavigationStep::Walk(command)) => {
                    let _ = spot.send(&MobilityCommand::Velocity(command));
                }
                Ok(NavigationStep::Hold) => {
                    let _ = spot.stop();
                }
                _ => *done = true,
            }
        }
        if runs.iter().all(|r| r.4) {
            break;
        }
    }
    let mut means = Vec::new();
    for (name, _, nav, ms, _) in &mut runs {
        let cycles = ms.len();
        let (mean, p99, max) = summary(ms);
        means.push(mean);
        println!(
            "navigation_seed3/{name}: {cycles} cycles ({} plans): mean {mean:.2} ms, p99 {p99:.2} ms, max {max:.2} ms per cycle",
            nav.replans(),
        );
    }
    println!(
        "navigation_seed3/walk: {:.2} of the time with full scans to 0.1 mm",
        means[0] / means[1]
    );
}

criterion_group!(benches, navigation);
criterion_main!(benches);
