//! Run every scenario of a Moving AI map with spot-nav's planners, check each length against the
//! published optimum (too long and too short both fail), and print per planner: scenarios,
//! matched, mean and p99 microseconds per query, mean expanded nodes.
//!
//! `cargo run --release --example movingai -- MAP SCEN [--planner dijkstra|astar|jps|jps-cells|jps-plus|all]`
//!
//! Exits non-zero on any mismatch. Example:
//! `cargo run --release --example movingai -- pathfind/tests/data/arena.map pathfind/tests/data/arena.map.scen`

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::{Parser, ValueEnum};
use pathfind::movingai::{read_map, read_scenarios};
use pathfind::{AStar, Dijkstra, JumpPointSearch, JumpPointSearchPlus};
use slam_core::{BitGrid, Cell, GridPath, Planner};
use spot_nav_examples::{Timings, out, value_name};

/// Check spot-nav's planners on every scenario of a Moving AI map against the published optimum.
///
/// Runs each scenario of the `.scen` file on the `.map`, checks each path length against the
/// published optimum (too long and too short both fail), and prints per planner: scenarios,
/// matched, mean and p99 microseconds per query, mean expanded nodes and setup time.
///
/// Fails when any result differs from the published optimum.
#[derive(Debug, Parser)]
#[command(name = "movingai")]
struct Args {
    /// The map (Moving AI `.map`).
    #[arg(value_name = "MAP")]
    map: PathBuf,
    /// Its scenarios (Moving AI `.scen`, version 1).
    #[arg(value_name = "SCEN")]
    scenarios: PathBuf,
    /// The planner to run, or all of them in turn.
    #[arg(long, value_enum, default_value_t = PlannerChoice::All)]
    planner: PlannerChoice,
}

/// `--planner`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum PlannerChoice {
    /// Dijkstra's algorithm.
    #[value(name = "dijkstra")]
    Dijkstra,
    /// A* with the octile heuristic.
    #[value(name = "astar")]
    AStar,
    /// Jump Point Search with word-at-a-time scans.
    #[value(name = "jps")]
    JumpPointSearch,
    /// Jump Point Search scanning cell by cell.
    #[value(name = "jps-cells")]
    JumpPointSearchCells,
    /// JPS+: jump tables precomputed for the grid, then table lookups.
    #[value(name = "jps-plus")]
    JumpPointSearchPlus,
    /// Every planner above in turn.
    #[value(name = "all")]
    All,
}

impl PlannerChoice {
    /// The planners this choice runs.
    fn planners(self) -> Vec<Self> {
        if self == Self::All {
            Self::value_variants()
                .iter()
                .copied()
                .filter(|&p| p != Self::All)
                .collect()
        } else {
            vec![self]
        }
    }

    /// The planner on `grid`.
    fn build(self, grid: &BitGrid) -> Result<Box<dyn Planner + '_>> {
        Ok(match self {
            Self::Dijkstra => Box::new(Dijkstra::new(grid)),
            Self::AStar => Box::new(AStar::new(grid)),
            Self::JumpPointSearch => Box::new(JumpPointSearch::new(grid)),
            Self::JumpPointSearchCells => Box::new(JumpPointSearch::with_cell_scans(grid)),
            Self::JumpPointSearchPlus => Box::new(JumpPointSearchPlus::new(grid)?),
            Self::All => bail!("`all` is not one planner"),
        })
    }
}

/// The path from `start` to `goal`, or why there is none: the example's only call of
/// `Planner::plan`.
fn plan(planner: &mut dyn Planner, start: Cell, goal: Cell) -> Result<GridPath, String> {
    match planner.plan(start, goal) {
        Ok(Some(path)) => Ok(path),
        Ok(None) => Err("no path".into()),
        Err(e) => Err(e.to_string()),
    }
}

fn main() -> ExitCode {
    spot_nav_examples::run(|| check(&Args::parse()))
}

fn check(args: &Args) -> Result<()> {
    let (map_path, scen_path) = (&args.map, &args.scenarios);
    let map = read_map(map_path).with_context(|| format!("reading {}", map_path.display()))?;
    let scenarios =
        read_scenarios(scen_path).with_context(|| format!("reading {}", scen_path.display()))?;
    let grid = &map.grid;
    out!(
        "map {}: {}x{} cells, {} blocked; {} scenarios",
        map_path.display(),
        grid.width(),
        grid.height(),
        grid.count_blocked(),
        scenarios.len()
    )?;
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
    out!(
        "{:<16} {:>9} {:>8} {:>12} {:>12} {:>12} {:>10}",
        "planner",
        "scenarios",
        "matched",
        "mean us",
        "p99 us",
        "expanded",
        "setup ms"
    )?;
    let mut failures = 0usize;
    for choice in args.planner.planners() {
        let name = value_name(&choice);
        let t = Instant::now();
        let mut planner = choice.build(grid)?;
        let setup_ms = t.elapsed().as_secs_f64() * 1e3;
        let mut us = Vec::with_capacity(scenarios.len());
        let (mut matched, mut expanded) = (0usize, 0usize);
        for (k, s) in scenarios.iter().enumerate() {
            let t = Instant::now();
            let result = plan(planner.as_mut(), s.start, s.goal);
            us.push(t.elapsed().as_secs_f64() * 1e6);
            match result {
                Ok(p) if (p.length - s.optimal_length).abs() <= s.tolerance => {
                    matched += 1;
                    expanded += p.expanded;
                }
                Ok(p) => {
                    failures += 1;
                    eprintln!(
                        "{name}: scenario {k}: length {} but the optimum is {}",
                        p.length, s.optimal_length
                    );
                }
                Err(e) => {
                    failures += 1;
                    eprintln!("{name}: scenario {k}: {e}");
                }
            }
        }
        let times = Timings::new(us);
        out!(
            "{name:<16} {:>9} {matched:>8} {:>12.1} {:>12.1} {:>12.0} {setup_ms:>10.2}",
            scenarios.len(),
            times.as_ref().map_or(0.0, Timings::mean),
            times.as_ref().map_or(0.0, |t| t.quantile(0.99)),
            expanded as f64 / matched.max(1) as f64
        )?;
    }
    if failures > 0 {
        bail!("{failures} scenario results did not match the published optimum");
    }
    Ok(())
}
