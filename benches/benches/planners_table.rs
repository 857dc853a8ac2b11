//! Every scenario of eight Moving AI maps, every planner and the peer in the same run: prints the
//! table recorded in `pathfind/README.md` (mean and p99 microseconds per query, speed-up over the
//! peer, expansions, preprocessing). Every length is checked against the published optimum.
//!
//! `cargo bench -p spot-nav-benches --bench planners_table`
//! (`SPOT_NAV_DATA` names the shared data folder; `PLANNERS_TABLE_STRIDE=k` runs every k-th
//! scenario for a quick look; `PLANNERS_TABLE_MAPS=den520d,maze512-8-0` picks maps.)

// A wrong or missing path must stop the bench: its figures would be meaningless.
#![allow(clippy::panic)]

use std::time::Instant;

use pathfind::movingai::{Scenario, read_map, read_scenarios};
use pathfind::{AStar, JumpPointSearch, JumpPointSearchPlus};
use slam_core::{BitGrid, Planner};
use spot_nav_benches::{data_root_or_notice, pathfinding_peer};

const MAPS: [(&str, &str); 8] = [
    ("dao", "den520d"),
    ("dao", "lak303d"),
    ("sc1", "Aftershock"),
    ("cities", "Berlin_0_512"),
    ("cities", "Boston_0_1024"),
    ("rooms", "32room_000"),
    ("mazes", "maze512-8-0"),
    ("random", "random512-25-0"),
];

struct Row {
    mean_us: f64,
    p99_us: f64,
    expanded: f64,
}

fn time_queries(scenarios: &[Scenario], mut query: impl FnMut(&Scenario) -> (f64, usize)) -> Row {
    let mut us = Vec::with_capacity(scenarios.len());
    let mut expanded = 0usize;
    for s in scenarios {
        let t = Instant::now();
        let (length, exp) = query(s);
        us.push(t.elapsed().as_secs_f64() * 1e6);
        expanded += exp;
        assert!(
            (length - s.optimal_length).abs() <= s.tolerance.max(1e-5 * s.optimal_length),
            "length {length} but the optimum is {}",
            s.optimal_length
        );
    }
    let n = us.len() as f64;
    let mean_us = us.iter().sum::<f64>() / n;
    us.sort_by(f64::total_cmp);
    let p99_us = us[((us.len() - 1) as f64 * 0.99).round() as usize];
    Row {
        mean_us,
        p99_us,
        expanded: expanded as f64 / n,
    }
}

fn ours(planner: &mut impl Planner, scenarios: &[Scenario]) -> Row {
    time_queries(scenarios, |s| match planner.plan(s.start, s.goal) {
        Ok(p) => (p.length, p.expanded),
        Err(e) => panic!("{e}"),
    })
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
    let picked = std::env::var("PLANNERS_TABLE_MAPS").ok();
    for (set, name) in MAPS {
        if picked
            .as_deref()
            .is_some_and(|p| !p.split(',').any(|m| m == name))
        {
            continue;
        }
        let dir = root.join("movingai");
        let map = match read_map(dir.join(format!("maps/{set}/{name}.map"))) {
            Ok(m) => m,
            Err(e) => {
                eprintln!("{name}: {e}; skipping");
                continue;
            }
        };
        let Ok(all) = read_scenarios(dir.join(format!("scenarios/{set}/{name}.map.scen"))) else {
            continue;
        };
        let scenarios: Vec<Scenario> = all.into_iter().step_by(stride).collect();
        let grid: &BitGrid = &map.grid;
        let cells = grid.len() as f64;
        let peer = time_queries(&scenarios, |s| {
            (
                pathfinding_peer::astar_length(grid, s.start, s.goal).unwrap_or(f64::INFINITY),
                0,
            )
        });
        let print = |planner: &str, r: &Row, pre_ms: f64, bytes: f64| {
            println!(
                "| {name} | {planner} | {:.1} | {:.1} | {:.1}x | {:.0} | {pre_ms:.1} | {bytes:.2} |",
                r.mean_us,
                r.p99_us,
                peer.mean_us / r.mean_us,
                r.expanded
            );
        };
        print("pathfinding::astar (peer)", &peer, 0.0, 0.0);
        let t = Instant::now();
        let mut astar = AStar::new(grid);
        let pre = t.elapsed().as_secs_f64() * 1e3;
        print("AStar", &ours(&mut astar, &scenarios), pre, 4.0);
        let t = Instant::now();
        let mut cells_jps = JumpPointSearch::with_cell_scans(grid);
        let pre = t.elapsed().as_secs_f64() * 1e3;
        print(
            "JumpPointSearch (cell scans)",
            &ours(&mut cells_jps, &scenarios),
            pre,
            4.0,
        );
        let t = Instant::now();
        let mut jps = JumpPointSearch::new(grid);
        let pre = t.elapsed().as_secs_f64() * 1e3;
        let bytes = 4.0 + jps.preprocessed_bytes() as f64 / cells;
        print(
            "JumpPointSearch (word scans)",
            &ours(&mut jps, &scenarios),
            pre,
            bytes,
        );
        let t = Instant::now();
        let mut blocks = JumpPointSearchPlus::new(grid);
        let pre = t.elapsed().as_secs_f64() * 1e3;
        let bytes = 4.0 + blocks.preprocessed_bytes() as f64 / cells;
        print(
            "JumpPointSearchPlus (block scans)",
            &ours(&mut blocks, &scenarios),
            pre,
            bytes,
        );
        let t = Instant::now();
        let Ok(mut tables) = JumpPointSearchPlus::with_jump_tables(grid) else {
            continue;
        };
        let pre = t.elapsed().as_secs_f64() * 1e3;
        let bytes = 4.0 + tables.preprocessed_bytes() as f64 / cells;
        print(
            "JumpPointSearchPlus (JPS+ tables)",
            &ours(&mut tables, &scenarios),
            pre,
            bytes,
        );
    }
}
