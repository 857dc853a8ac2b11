//! Every scenario of five Moving AI maps against its published optimal length (both too long and
//! too short fail), for every planner. See `tests/data/README.md` for provenance.
#![allow(clippy::unwrap_used, clippy::panic)]

use std::path::PathBuf;

use pathfind::movingai::{parse_map, parse_scenarios, read_map, read_scenarios};
use pathfind::{AStar, Dijkstra, JumpPointSearch, JumpPointSearchPlus};
use slam_core::{BitGrid, Planner};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// Run every scenario of `map` with `planner`; returns the number checked.
fn run(name: &str, planner: &mut dyn Planner, grid: &BitGrid, map: &str) -> usize {
    let scenarios = read_scenarios(data(&format!("{map}.map.scen"))).unwrap();
    for (k, s) in scenarios.iter().enumerate() {
        assert_eq!((s.map_width, s.map_height), (grid.width(), grid.height()));
        let p = planner
            .plan(s.start, s.goal)
            .unwrap_or_else(|e| panic!("{name} {map} #{k}: {e}"))
            .unwrap_or_else(|| panic!("{name} {map} #{k}: no path, but the scenario has one"));
        assert!(
            (p.length - s.optimal_length).abs() <= s.tolerance,
            "{name} on {map} scenario {k}: {} but the optimum is {} (tolerance {})",
            p.length,
            s.optimal_length,
            s.tolerance
        );
    }
    scenarios.len()
}

fn all_planners(map: &str, with_slow: bool) {
    let m = read_map(data(&format!("{map}.map"))).unwrap();
    let g = &m.grid;
    let n = run("JPS", &mut JumpPointSearch::new(g), g, map);
    run(
        "JPS cells",
        &mut JumpPointSearch::with_cell_scans(g),
        g,
        map,
    );
    run("JPS+", &mut JumpPointSearchPlus::new(g).unwrap(), g, map);
    if with_slow {
        run("A*", &mut AStar::new(g), g, map);
        run("Dijkstra", &mut Dijkstra::new(g), g, map);
    }
    assert!(n > 100);
}

#[test]
fn arena_game_map() {
    if slam_core::skip_without_test_data!("tests/data") {
        return;
    }
    all_planners("arena", true);
}

#[test]
fn ht_chantry_game_map() {
    if slam_core::skip_without_test_data!("tests/data") {
        return;
    }
    all_planners("ht_chantry", true);
}

#[test]
fn room_map() {
    if slam_core::skip_without_test_data!("tests/data") {
        return;
    }
    all_planners("8room_000", false);
    // A* on every room scenario too (Dijkstra on 512 x 512 maps is left to the example).
    let m = read_map(data("8room_000.map")).unwrap();
    run("A*", &mut AStar::new(&m.grid), &m.grid, "8room_000");
}

#[test]
fn maze_map() {
    if slam_core::skip_without_test_data!("tests/data") {
        return;
    }
    all_planners("maze512-32-0", false);
}

#[test]
fn random_map() {
    if slam_core::skip_without_test_data!("tests/data") {
        return;
    }
    all_planners("random512-10-0", false);
    let m = read_map(data("random512-10-0.map")).unwrap();
    run("A*", &mut AStar::new(&m.grid), &m.grid, "random512-10-0");
}

#[test]
fn readers_reject_malformed_files() {
    let good = "type octile\nheight 2\nwidth 3\nmap\n.@.\nGST\n";
    let m = parse_map(good).unwrap();
    assert_eq!(m.grid.count_blocked(), 2);
    assert_eq!(m.terrain, b".@.GST");
    for (bad, line) in [
        // 6 cells stated, 4 bytes after the `map` line: refused at that line, before allocating.
        ("type octile\nheight 2\nwidth 3\nmap\n.@.\n", 4),
        ("type octile\nheight 2\nwidth 3\nmap\n.@.\r\r\r\n", 0),
        ("type octile\nheight 2\nwidth 3\nmap\n.@\nGST\n", 5),
        ("type octile\nheight 2\nwidth 3\nmap\n.@.\nGSX\n", 6),
        ("type octile\nheight x\nwidth 3\nmap\n", 2),
    ] {
        match parse_map(bad) {
            Err(pathfind::PathfindError::Parse { line: l, .. }) => assert_eq!(l, line, "{bad:?}"),
            other => panic!("{bad:?} gave {other:?}"),
        }
    }
    let scen = "version 1.0\n0 maps/x.map 3 2 0 0 2 0 2.00\n";
    let s = parse_scenarios(scen).unwrap();
    assert_eq!(s[0].goal, slam_core::Cell::new(2, 0));
    assert!((s[0].tolerance - 0.005).abs() < 1e-6);
    let tabs = "version 1\n0\tmaps/x.map\t3\t2\t0\t0\t2\t0\t273.764\n";
    assert!((parse_scenarios(tabs).unwrap()[0].tolerance - 1e-3).abs() < 1e-12);
    assert!(parse_scenarios("version 2\n").is_err());
    assert!(matches!(
        parse_scenarios("version 1\n0 m 3 2 0 0 2 0\n"),
        Err(pathfind::PathfindError::Parse { line: 2, .. })
    ));
}

/// The writers read back to the same map and queries (a real map and its scenarios).
#[test]
fn written_maps_and_scenarios_read_back() {
    if slam_core::skip_without_test_data!("tests/data") {
        return;
    }
    let map = read_map(data("arena.map")).unwrap();
    let back = parse_map(&pathfind::movingai::map_text(&map)).unwrap();
    assert_eq!((back.grid, back.terrain), (map.grid, map.terrain));
    let scen = read_scenarios(data("arena.map.scen")).unwrap();
    let back = parse_scenarios(&pathfind::movingai::scenarios_text(&scen)).unwrap();
    assert_eq!(back.len(), scen.len());
    for (a, b) in back.iter().zip(&scen) {
        assert_eq!(
            (a.bucket, &a.map, a.start, a.goal, a.optimal_length),
            (b.bucket, &b.map, b.start, b.goal, b.optimal_length)
        );
    }
}
