//! Run every scenario of a Moving AI map with spot-nav's planners, check each length against the
//! published optimum (too long and too short both fail), and print per planner: scenarios,
//! matched, mean and p99 microseconds per query, mean expanded nodes.
//!
//! `cargo run --release --example movingai -- MAP SCEN [--planner dijkstra|astar|jps|jps-cells|jps-plus|all]`
//!
//! Exits non-zero on any mismatch. Example:
//! `cargo run --release --example movingai -- pathfind/tests/data/arena.map pathfind/tests/data/arena.map.scen`

use std::time::Instant;

use anyhow::{Context, Result, bail};
use pathfind::movingai::{read_map, read_scenarios};
use pathfind::{AStar, Dijkstra, JumpPointSearch, JumpPointSearchPlus};
use slam_core::{BitGrid, Planner};

const USAGE: &str =
    "usage: movingai MAP SCEN [--planner dijkstra|astar|jps|jps-cells|jps-plus|all]";

/// The planner called `name` on the command line.
fn build<'g>(name: &str, grid: &'g BitGrid) -> Result<Box<dyn Planner + 'g>> {
    Ok(match name {
        "dijkstra" => Box::new(Dijkstra::new(grid)),
        "astar" => Box::new(AStar::new(grid)),
        "jps" => Box::new(JumpPointSearch::new(grid)),
        "jps-cells" => Box::new(JumpPointSearch::with_cell_scans(grid)),
        "jps-plus" => Box::new(JumpPointSearchPlus::new(grid)?),
        other => bail!("unknown planner {other:?}; {USAGE}"),
    })
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut positional = Vec::new();
    let mut which = "all".to_string();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--planner" => which.clone_from(it.next().context(USAGE)?),
            "-h" | "--help" => {
                println!("{USAGE}");
                return Ok(());
            }
            _ => positional.push(a.clone()),
        }
    }
    let [map_path, scen_path] = positional.as_slice() else {
        bail!("{USAGE}")
    };
    let map = read_map(map_path).with_context(|| format!("reading {map_path}"))?;
    let scenarios = read_scenarios(scen_path).with_context(|| format!("reading {scen_path}"))?;
    let grid = &map.grid;
    println!(
        "map {map_path}: {}x{} cells, {} blocked; {} scenarios",
        grid.width(),
        grid.height(),
        grid.count_blocked(),
        scenarios.len()
    );
    if let Some(s) = scenarios
        .iter()
        .find(|s| (s.map_width, s.map_height) != (grid.width(), grid.height()))
    {
        bail!(
            "scenario for a {}x{} map, the map is {}x{}",
            s.map_width,
            s.map_height,
            grid.width(),
            grid.height()
        );
    }
    let names: Vec<&str> = if which == "all" {
        vec!["dijkstra", "astar", "jps", "jps-cells", "jps-plus"]
    } else {
        vec![which.as_str()]
    };
    println!(
        "{:<16} {:>9} {:>8} {:>12} {:>12} {:>12} {:>10}",
        "planner", "scenarios", "matched", "mean us", "p99 us", "expanded", "setup ms"
    );
    let mut failures = 0usize;
    for name in names {
        let t = Instant::now();
        let mut planner = build(name, grid)?;
        let setup_ms = t.elapsed().as_secs_f64() * 1e3;
        let mut us = Vec::with_capacity(scenarios.len());
        let (mut matched, mut expanded) = (0usize, 0usize);
        for (k, s) in scenarios.iter().enumerate() {
            let t = Instant::now();
            let result = planner.plan(s.start, s.goal);
            us.push(t.elapsed().as_secs_f64() * 1e6);
            match result {
                Ok(Some(p)) if (p.length - s.optimal_length).abs() <= s.tolerance => {
                    matched += 1;
                    expanded += p.expanded;
                }
                Ok(p) => {
                    failures += 1;
                    let got = p.map_or("no path".into(), |p| format!("length {}", p.length));
                    eprintln!("{name}: scenario {k}: {got}, optimum {}", s.optimal_length);
                }
                Err(e) => {
                    failures += 1;
                    eprintln!("{name}: scenario {k}: {e}");
                }
            }
        }
        let mean = us.iter().sum::<f64>() / us.len().max(1) as f64;
        us.sort_by(f64::total_cmp);
        let p99 = us
            .get(((us.len().saturating_sub(1)) as f64 * 0.99).round() as usize)
            .copied()
            .unwrap_or(0.0);
        println!(
            "{name:<16} {:>9} {matched:>8} {mean:>12.1} {p99:>12.1} {:>12.0} {setup_ms:>10.2}",
            scenarios.len(),
            expanded as f64 / matched.max(1) as f64
        );
    }
    if failures > 0 {
        bail!("{failures} scenario results did not match the published optimum");
    }
    Ok(())
}
