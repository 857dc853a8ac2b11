//! Criterion ablation of the grid planners against the `pathfinding` crate's `astar` on Moving AI
//! maps: each iteration runs the same fixed sample of scenarios (every k-th, about 50), so the time
//! per iteration divided by the sample size is the mean time per query. Setup (reading the map,
//! building the planner) is outside the timed loop. For the full table over every scenario see
//! `planners_table`.
//!
//! `cargo bench -p spot-nav-benches --bench planners` (`SPOT_NAV_DATA` names the data folder,
//! `PLANNERS_MAPS=den520d,AR0011SR` or `all` picks its maps)

// A planner error on a scenario's free endpoints must stop the bench: its figures would be
// meaningless.
#![allow(clippy::panic)]

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use pathfind::movingai::{Scenario, read_map, read_scenarios};
use pathfind::{AStar, JumpPointSearch, JumpPointSearchPlus};
use slam_core::Planner;
use spot_nav_benches::{data_root_or_notice, pathfinding_peer, pick_movingai_maps};

/// The maps run unless `PLANNERS_MAPS` names others (any maps of the data folder's `movingai/`,
/// comma-separated, or `all`).
const DEFAULT_MAPS: [&str; 4] = ["den520d", "Aftershock", "32room_000", "random512-25-0"];

fn run(planner: &mut impl Planner, scenarios: &[Scenario]) -> f64 {
    scenarios
        .iter()
        .map(|s| match planner.plan(s.start, s.goal) {
            Ok(p) => p.map_or(0.0, |p| p.length),
            Err(e) => panic!("scenario endpoints are free cells: {e}"),
        })
        .sum()
}

fn planners(c: &mut Criterion) {
    let Some(root) = data_root_or_notice("planners") else {
        return;
    };
    let mut group = c.benchmark_group("planners");
    group.sample_size(10);
    for (set, name) in pick_movingai_maps(&root, "PLANNERS_MAPS", &DEFAULT_MAPS) {
        let dir = root.join("movingai");
        let (Ok(map), Ok(all)) = (
            read_map(dir.join(format!("maps/{set}/{name}.map"))),
            read_scenarios(dir.join(format!("scenarios/{set}/{name}.map.scen"))),
        ) else {
            eprintln!("planners: {name} missing; skipping");
            continue;
        };
        let stride = (all.len() / 50).max(1);
        let sample: Vec<Scenario> = all.into_iter().step_by(stride).collect();
        let grid = &map.grid;
        group.throughput(Throughput::Elements(sample.len() as u64));
        group.bench_function(BenchmarkId::new("pathfinding_astar_peer", &name), |b| {
            b.iter(|| {
                sample
                    .iter()
                    .map(|s| pathfinding_peer::astar_length(grid, s.start, s.goal).unwrap_or(0.0))
                    .sum::<f64>()
            });
        });
        let mut astar = AStar::new(grid);
        group.bench_function(BenchmarkId::new("AStar", &name), |b| {
            b.iter(|| run(&mut astar, &sample));
        });
        let mut jps = JumpPointSearch::new(grid);
        group.bench_function(BenchmarkId::new("JumpPointSearch", &name), |b| {
            b.iter(|| run(&mut jps, &sample));
        });
        let mut jps_cells = JumpPointSearch::with_cell_scans(grid);
        group.bench_function(BenchmarkId::new("JumpPointSearch_cells", &name), |b| {
            b.iter(|| run(&mut jps_cells, &sample));
        });
        if let Ok(mut tables) = JumpPointSearchPlus::new(grid) {
            group.bench_function(BenchmarkId::new("JumpPointSearchPlus", &name), |b| {
                b.iter(|| run(&mut tables, &sample));
            });
        }
    }
    group.finish();
}

criterion_group!(benches, planners);
criterion_main!(benches);
