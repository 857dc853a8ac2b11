//! Every scenario of eight Moving AI maps, every planner and the peer in the same run: prints the
//! table recorded in `pathfind/README.md` (mean and p99 microseconds per query, speed-up over the
//! peer, expansions, preprocessing). Every planner's length is checked against the peer's, and
//! the peer's against the published optimum (a mismatch with the file is counted, not fatal:
//! some `version 1.0` files were made on another version of their map).
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
    /// The length found for each scenario (infinite: no path).
    lengths: Vec<f64>,
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
                Ok(None) => (f64::INFINITY, 0),
                Err(e) => panic!("{name}: {e}"),
            }),
            us: Vec::new(),
            expanded: 0,
            lengths: Vec::new(),
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
        // A scenario whose endpoint is not free under the strict rule (battleground has some on
        // `T` and `@`) has no answer to time; it is counted, not run.
        let (scenarios, blocked): (Vec<Scenario>, Vec<Scenario>) = all
            .into_iter()
            .step_by(stride)
            .partition(|s| !map.grid.is_blocked(s.start) && !map.grid.is_blocked(s.goal));
        print_map(&name, &map.grid, &scenarios, blocked.len());
    }
}

/// Time every planner on `scenarios` of one map and print its rows. Every planner's length must
/// equal the peer's (an independent search); both are compared with the file's published length,
/// and the scenarios that disagree with it are counted on the map's last line (wc3maps512's
/// scenarios were made on another version of the map, see the data's README).
fn print_map(name: &str, grid: &BitGrid, scenarios: &[Scenario], blocked: usize) {
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
            lengths: Vec::new(),
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
            for pass in 0..2 {
                for (s, best) in chunk.iter().zip(&mut best) {
                    let t = Instant::now();
                    let (length, expanded) = (e.query)(s);
                    *best = best.min(t.elapsed().as_secs_f64() * 1e6);
                    e.expanded += expanded;
                    if pass == 0 {
                        e.lengths.push(length);
                    }
                }
            }
            e.us.extend(best);
        }
    }
    let matched = check_lengths(&entries, scenarios);
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
    if matched < scenarios.len() || blocked > 0 {
        println!(
            "| {name} | published optimum matched by {matched} of {} scenarios; {blocked} skipped (an endpoint not free) | | | | | | |",
            scenarios.len()
        );
    }
}

/// Check every planner's lengths against the peer's (panics on a difference) and return how many
/// of the peer's lengths match the file's published optimum.
fn check_lengths(entries: &[Entry<'_>], scenarios: &[Scenario]) -> usize {
    // Ours sum exact step costs; the peer's integer costs get one rounding error per diagonal.
    let (peer, ours) = entries
        .split_first()
        .unwrap_or_else(|| panic!("the peer runs"));
    for e in ours {
        for ((&l, &p), s) in e.lengths.iter().zip(&peer.lengths).zip(scenarios) {
            let agree = (l.is_infinite() && p.is_infinite())
                || (l - p).abs() <= pathfinding_peer::length_tolerance(p, 1e-9);
            assert!(
                agree,
                "{}: length {l} but the peer's {p} ({:?} to {:?})",
                e.name, s.start, s.goal
            );
        }
    }
    peer.lengths
        .iter()
        .zip(scenarios)
        .filter(|&(&p, s)| {
            (p - s.optimal_length).abs()
                <= pathfinding_peer::length_tolerance(s.optimal_length, s.tolerance)
        })
        .count()
}
