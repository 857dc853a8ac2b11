//! gridmap's planning layer with pathfind's cost-aware planner, end to end: in a 2 m corridor
//! with a 0.9 m door the path keeps to the middle and passes the door, which 0.40 m of inflation
//! closes. (The two crates never see each other; this crate sees both.)
#![allow(clippy::unwrap_used, clippy::panic)]

use gridmap::{CellState, OccupancyGrid, PlanningGrid, PlanningGridConfig, inflate};
use nalgebra::Vector2;
use pathfind::movement::validate_dense_path;
use pathfind::{AStar, CellCostAStar, JumpPointSearch};
use slam_core::{Cell, GridGeometry, Planner};

#[test]
fn corridor_middle_and_door_through_the_planning_layer() {
    // 12 m x 2.1 m at 0.1 m: walls on rows 0 and 20 (centres 2.0 m apart), a cross wall at
    // column 60 with a door the map shows 8 cells wide (a 0.9 m door between frame cells whose
    // centres are 0.9 m apart). Everything else seen free.
    let geometry = GridGeometry::try_new(Vector2::new(0.0, 0.0), 0.1).unwrap();
    let mut map = OccupancyGrid::new(120, 21, geometry, CellState::Free).unwrap();
    for x in 0..120 {
        for y in [0, 20] {
            map.set(Cell::new(x, y), CellState::Occupied).unwrap();
        }
    }
    for y in (1..6).chain(14..20) {
        map.set(Cell::new(60, y), CellState::Occupied).unwrap();
    }
    let layer = PlanningGrid::new(&map, PlanningGridConfig::default()).unwrap();
    let (start, goal) = (Cell::new(5, 5), Cell::new(114, 5));
    let closed = inflate(map.occupied(), 0.40).unwrap();
    assert_eq!(AStar::new(&closed).plan(start, goal).unwrap(), None);
    let grid = layer.blocked();
    let found = CellCostAStar::new(grid, layer.step_costs())
        .unwrap()
        .plan_with_cost(start, goal)
        .unwrap()
        .expect("the door is open under the 0.30 m hard inflation");
    validate_dense_path(grid, &found.path.cells).unwrap();
    let away = |c: &&Cell| (15..50).contains(&c.x) || (70..105).contains(&c.x);
    assert!(
        found
            .path
            .cells
            .iter()
            .filter(away)
            .all(|c| (9..=11).contains(&c.y)),
        "the middle rows: {:?}",
        found.path.cells
    );
    // With the cost off every multiplier is 1: the shortest planners' lengths.
    let off = PlanningGridConfig {
        cost: gridmap::ClearanceCostConfig {
            weight: 0.0,
            ..gridmap::ClearanceCostConfig::default()
        },
        ..PlanningGridConfig::default()
    };
    let flat = PlanningGrid::new(&map, off).unwrap();
    assert!(!flat.cost_enabled());
    assert_eq!(flat.blocked(), grid);
    let unit = CellCostAStar::new(flat.blocked(), flat.step_costs())
        .unwrap()
        .plan(start, goal)
        .unwrap()
        .unwrap();
    let jps = JumpPointSearch::new(grid)
        .plan(start, goal)
        .unwrap()
        .unwrap();
    assert!((unit.length - jps.length).abs() < 1e-9);
    assert!(found.path.length > jps.length);
}
