//! Every scenario of eight Moving AI maps, every planner and the peer in the same run: prints the
//! table recorded in `pathfind/README.md` (mean and p99 microseconds per query, speed-up over the
//! peer, expansions, preprocessing). Every length is checked against the published optimum.
//! Planners take turns over chunks of 500 scenarios so that load changes on a shared machine hit
//! them alike; each chunk runs twice and each query keeps its faster time (drops preemptions).
//!
//! `cargo bench -p spot-nav-benches --bench planners_table`
//! (`SPOT_NAV_DATA` names the shared data folder; `PLANNERS_TABLE_STRIDE=k` runs every k-th
//! scenario for a quick look; `PLANNERS_TABLE_MAPS=den520d,AR0011SR` picks any maps of the data
//! folder's `movingai/` (`all` runs every map that has a scenario file; the default is the
//! README's eight);
//! `PLANNERS_TABLE_PLANNERS=AStar,word` keeps the peer and the planners whose names contain one of
//! the words.)

// A wrong or missing path must stop the bench: its figures would be meaningless.
#![allow(clippy::panic)]

use std::time::Instant;

use pathfind::movingai::{Scenario, read_map, read_scenarios};
use pathfind::{AStar, JumpPointSearch, JumpPointSearchPlus};
use slam_core::{BitGrid, Planner};
use spot_nav_benches::{data_root_or_notice, pathfinding_peer, pick_movingai_maps};

/// Scenarios each planner runs in a row before the next planner takes its turn.
const CHUNK: usize = 500;

/// The maps of the table in `pathfind/README.md` (the default of `PLANNERS_TABLE_MAPS`).
const DEFAULT_MAPS: [&str; 8] = [
    "den520d",
    "lak303d",
    "Aftershock",
    "Berlin_0_512",
    "Boston_0_1024",
    "32room_000",
    "maze512-8-0",
    "random512-25-0",
];

/// One query: the path length found and the nodes expanded.
type Query<'g> = Box<dyn FnMut(&Scenario) -> (f64, usize) + 'g>;

/// One column of the table: a name, what it keeps per cell, how long it took to build, and the
/// query.
struct Entry<'g> {
    name: &'static str,
    bytes_per_cell: f64,
    setup_ms: f64,
    query: Query<'g>,
    us: Vec<f64>,
    expanded: usize,
}

impl<'g> Entry<'g> {
    /// Build a planner with `make` (timed as preprocessing).
    fn ours<P: Planner + 'g>(
        name: &'static str,
        make: impl FnOnce() -> P,
        extra_bytes: impl FnOnce(&P) -> usize,
        cells: f64,
    ) -> Self {
        let t = Instant::now();
        let mut planner = make();
        let setup_ms = t.elapsed().as_secs_f64() * 1e3;
        // Component labels (4 bytes per cell) plus the planner's own tables.
        let bytes_per_cell = 4.0 + extra_bytes(&planner) as f64 / cells;
        Self {
            name,
            bytes_per_cell,
            setup_ms,
            query: Box::new(move |s: &Scenario| match planner.plan(s.start, s.goal) {
                Ok(Some(p)) => (p.length, p.expanded),
                Ok(None) => panic!("{name}: no path, but the scenario has one"),
                Err(e) => panic!("{name}: {e}"),
            }),
            us: Vec::new(),
            expanded: 0,
        }
    }
}

fn main() {
    // Cargo passes `--bench`; this binary has no options of its own.
    let Some(root) = data_root_or_notice("planners_table") else {
        return;
    };
    let stride: usize = std::env::var("PLANNERS_TABLE_STRIDE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1)
        .max(1);
    println!(
        "| map | planner | mean µs/query | p99 µs | speed-up vs peer | mean expansions | preprocessing ms | extra bytes/cell |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for (set, name) in pick_movingai_maps(&root, "PLANNERS_TABLE_MAPS", &DEFAULT_MAPS) {
        let dir = root.join("movingai");
        let map = match read_map(dir.join(format!("maps/{set}/{name}.map"))) {
            Ok(m) => m,
            Err(e) => {
                eprintln!("{name}: {e}; skipping");
                continue;
            }
        };
        let all = match read_scenarios(dir.join(format!("scenarios/{set}/{name}.map.scen"))) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("{name} scenarios: {e}; skipping");
                continue;
            }
        };
        let scenarios: Vec<Scenario> = all.into_iter().step_by(stride).collect();
        print_map(&name, &map.grid, &scenarios);
    }
}

/// Time every planner on `scenarios` of one map and print its rows.
fn print_map(name: &str, grid: &BitGrid, scenarios: &[Scenario]) {
    let cells = grid.len() as f64;
    let mut entries = vec![
        Entry {
            name: "pathfinding::astar (peer)",
            bytes_per_cell: 0.0,
            setup_ms: 0.0,
            query: Box::new(|s: &Scenario| {
                (
                    pathfinding_peer::astar_length(grid, s.start, s.goal).unwrap_or(f64::INFINITY),
                    0,
                )
            }),
            us: Vec::new(),
            expanded: 0,
        },
        Entry::ours("AStar", || AStar::new(grid), |_| 0, cells),
        Entry::ours(
            "JumpPointSearch (cell scans)",
            || JumpPointSearch::with_cell_scans(grid),
            JumpPointSearch::preprocessed_bytes,
            cells,
        ),
        Entry::ours(
            "JumpPointSearch (word scans)",
            || JumpPointSearch::new(grid),
            JumpPointSearch::preprocessed_bytes,
            cells,
        ),
    ];
    if grid.width() <= 32_767 && grid.height() <= 32_767 {
        entries.push(Entry::ours(
            "JumpPointSearchPlus (JPS+ tables)",
            || JumpPointSearchPlus::new(grid).unwrap_or_else(|e| panic!("{e}")),
            JumpPointSearchPlus::preprocessed_bytes,
            cells,
        ));
    }
    if let Ok(picked) = std::env::var("PLANNERS_TABLE_PLANNERS") {
        let mut first = true;
        entries.retain(|e| {
            let keep = first || picked.split(',').any(|p| e.name.contains(p));
            first = false;
            keep
        });
    }
    // Round robin over chunks of scenarios, so a change of machine load hits every planner alike
    // while each planner still runs warm (one query at a time would let the others evict its
    // tables and search records from the caches between queries).
    for chunk in scenarios.chunks(CHUNK) {
        for e in &mut entries {
            // Two passes over the chunk; each query keeps its faster time, so a preemption by
            // other work on a shared machine does not land in the figures, while the caches see
            // 499 other queries between the two runs of one query, as in a plain sequential run.
            let mut best = vec![f64::INFINITY; chunk.len()];
            for _ in 0..2 {
                for (s, best) in chunk.iter().zip(&mut best) {
                    let t = Instant::now();
                    let (length, expanded) = (e.query)(s);
                    *best = best.min(t.elapsed().as_secs_f64() * 1e6);
                    e.expanded += expanded;
                    // Our planners sum exact step costs; the peer's integer costs get their
                    // own rounding allowance.
                    let tolerance = if e.name.ends_with("(peer)") {
                        pathfinding_peer::length_tolerance(s.optimal_length, s.tolerance)
                    } else {
                        s.tolerance
                    };
                    assert!(
                        (length - s.optimal_length).abs() <= tolerance,
                        "{}: length {length} but the optimum is {}",
                        e.name,
                        s.optimal_length
                    );
                }
            }
            e.us.extend(best);
        }
    }
    let n = scenarios.len().max(1) as f64;
    let peer_mean = entries[0].us.iter().sum::<f64>() / n;
    for e in &mut entries {
        let mean = e.us.iter().sum::<f64>() / n;
        e.us.sort_by(f64::total_cmp);
        let p99 = e.us[((e.us.len() - 1) as f64 * 0.99).round() as usize];
        println!(
            "| {name} | {} | {mean:.1} | {p99:.1} | {:.1}x | {:.0} | {:.1} | {:.2} |",
            e.name,
            peer_mean / mean,
            e.expanded as f64 / (2.0 * n),
            e.setup_ms,
            e.bytes_per_cell
        );
    }
}
