//! The planners for the clearance cost beside the shortest-path planners, on building-sized
//! grids: the simulated building (seed 3) mapped from its obstacle band at 0.10 m with the
//! default planning layer (0.30 m hard inflation, clearance weight 2 up to 1 m), and Moving AI's
//! `den520d` (a game map) and `Berlin_0_512` (a city's streets) read as 0.10 m grids with the same
//! planning layer (a synthetic clearance cost; the room maps' one-cell doors would close under
//! any inflation). Each iteration runs the same fixed set of queries (reachable pairs drawn from
//! a fixed generator); the setup (mapping, the planning layer, the planners' construction) is
//! outside the timed loop. Before timing, every planner's path is checked: `CellCostAStar` with
//! unit costs has `AStar`'s lengths, the cost-aware searches agree on the cost.
//!
//! `cargo bench -p spot-nav-benches --bench cost_planners`

// A planner error or disagreement must stop the bench: its figures would be meaningless.
#![allow(clippy::panic)]

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use gridmap::{CellState, OccupancyGrid, PlanningGrid, PlanningGridConfig};
use pathfind::movingai::read_map;
use pathfind::{AStar, CellCostAStar, Components, JumpPointSearch};
use slam_core::{BitGrid, Cell, GridGeometry, Planner};
use spot_nav_benches::{data_root, mapped_building};

/// Queries per iteration.
const QUERIES: usize = 40;

/// `QUERIES` pairs of free cells in the same component, at least a quarter of the grid's
/// diagonal apart, from a fixed xorshift.
fn queries(grid: &BitGrid) -> Vec<(Cell, Cell)> {
    let components = Components::new(grid);
    let (w, h) = (grid.width(), grid.height());
    let min = f64::from(w.max(h)) / 4.0;
    let mut s = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    };
    let mut out = Vec::new();
    for _ in 0..1_000_000 {
        if out.len() == QUERIES {
            break;
        }
        let a = Cell::new(
            (next() % u64::from(w)) as u32,
            (next() % u64::from(h)) as u32,
        );
        let b = Cell::new(
            (next() % u64::from(w)) as u32,
            (next() % u64::from(h)) as u32,
        );
        let far = f64::from(a.x.abs_diff(b.x)).hypot(f64::from(a.y.abs_diff(b.y))) >= min;
        if far && components.connected(a, b) {
            out.push((a, b));
        }
    }
    out
}

/// Sum of the path lengths (cells) of `planner` over `queries`.
fn lengths(planner: &mut impl Planner, queries: &[(Cell, Cell)]) -> f64 {
    queries
        .iter()
        .map(|&(a, b)| match planner.plan(a, b) {
            Ok(Some(p)) => p.length,
            Ok(None) => panic!("the pairs are connected"),
            Err(e) => panic!("query endpoints are free cells: {e}"),
        })
        .sum()
}

/// Sum of the path costs and the expansions of a cost-aware planner over `queries`.
fn costs(planner: &mut CellCostAStar<'_>, queries: &[(Cell, Cell)]) -> (f64, usize) {
    queries
        .iter()
        .map(|&(a, b)| match planner.plan_with_cost(a, b) {
            Ok(Some(p)) => (p.cost, p.path.expanded),
            Ok(None) => panic!("the pairs are connected"),
            Err(e) => panic!("query endpoints are free cells: {e}"),
        })
        .fold((0.0, 0), |(c, e), (pc, pe)| (c + pc, e + pe))
}

/// A Moving AI map as a 0.10 m occupancy grid (blocked = occupied, the rest free).
fn movingai_occupancy(set: &str, name: &str) -> Option<OccupancyGrid> {
    let map = read_map(data_root().join(format!("movingai/maps/{set}/{name}.map"))).ok()?;
    let g = &map.grid;
    let geometry = GridGeometry::try_new(nalgebra::Vector2::zeros(), 0.1).ok()?;
    let mut grid = OccupancyGrid::new(g.width(), g.height(), geometry, CellState::Free).ok()?;
    for c in g.blocked_cells() {
        grid.set(c, CellState::Occupied).ok()?;
    }
    Some(grid)
}

fn bench_grid(c: &mut Criterion, name: &str, occupancy: &OccupancyGrid) {
    let layer = match PlanningGrid::new(occupancy, PlanningGridConfig::default()) {
        Ok(l) => l,
        Err(e) => panic!("{name}: planning layer: {e}"),
    };
    let grid = layer.blocked();
    let sample = queries(grid);
    let ones = vec![1.0f32; grid.len()];
    let new = |costs| CellCostAStar::new(grid, costs).unwrap_or_else(|e| panic!("{e}"));
    let mut astar = AStar::new(grid);
    let mut jps = JumpPointSearch::new(grid);
    let mut unit = new(&ones);
    let mut cost_astar = new(layer.step_costs());
    let mut cost_dijkstra = CellCostAStar::without_heuristic(grid, layer.step_costs())
        .unwrap_or_else(|e| panic!("{e}"));
    // Check the answers before timing them.
    let shortest = lengths(&mut astar, &sample);
    let (unit_cost, unit_expanded) = costs(&mut unit, &sample);
    let (cost, expanded) = costs(&mut cost_astar, &sample);
    let (cost_d, expanded_d) = costs(&mut cost_dijkstra, &sample);
    if sample.is_empty() {
        eprintln!("cost_planners: {name} has no pair of distant connected cells; skipping it");
        return;
    }
    assert!((lengths(&mut jps, &sample) - shortest).abs() < 1e-6 * shortest);
    assert!(
        (unit_cost - shortest).abs() < 1e-6 * shortest,
        "{unit_cost} vs {shortest}"
    );
    assert!((cost - cost_d).abs() < 1e-6 * cost, "{cost} vs {cost_d}");
    let n = sample.len();
    eprintln!(
        "{name}: {} x {} cells, {} queries; mean expansions: CellCostAStar unit {}, clearance {}, \
         without heuristic {}; mean cost / shortest length {:.3}",
        grid.width(),
        grid.height(),
        n,
        unit_expanded / n,
        expanded / n,
        expanded_d / n,
        cost / shortest,
    );
    let mut group = c.benchmark_group("cost_planners");
    group.sample_size(10);
    group.throughput(Throughput::Elements(n as u64));
    group.bench_function(BenchmarkId::new("JumpPointSearch", name), |b| {
        b.iter(|| lengths(&mut jps, &sample));
    });
    group.bench_function(BenchmarkId::new("AStar", name), |b| {
        b.iter(|| lengths(&mut astar, &sample));
    });
    group.bench_function(BenchmarkId::new("CellCostAStar_unit_costs", name), |b| {
        b.iter(|| costs(&mut unit, &sample));
    });
    group.bench_function(BenchmarkId::new("CellCostAStar_clearance", name), |b| {
        b.iter(|| costs(&mut cost_astar, &sample));
    });
    group.bench_function(
        BenchmarkId::new("CellCostAStar_without_heuristic_clearance", name),
        |b| b.iter(|| costs(&mut cost_dijkstra, &sample)),
    );
    // Construction: what a replan after a live-layer change pays before its search.
    group.throughput(Throughput::Elements(1));
    group.bench_function(BenchmarkId::new("CellCostAStar_new", name), |b| {
        b.iter(|| {
            new(layer.step_costs())
                .plan(sample[0].0, sample[0].0)
                .is_ok()
        });
    });
    group.finish();
}

fn cost_planners(c: &mut Criterion) {
    match mapped_building::map(3, 4) {
        Ok(m) => bench_grid(c, "sim_building_3", &m.occupancy),
        Err(e) => eprintln!("cost_planners: simulated building failed ({e}); skipping it"),
    }
    for (set, name) in [("dao", "den520d"), ("cities", "Berlin_0_512")] {
        match movingai_occupancy(set, name) {
            Some(grid) => bench_grid(c, name, &grid),
            None => eprintln!(
                "cost_planners: {name} not found under {} (set SPOT_NAV_DATA); skipping it",
                data_root().display()
            ),
        }
    }
}

criterion_group!(benches, cost_planners);
criterion_main!(benches);
