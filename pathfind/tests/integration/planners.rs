//! Every planner against Dijkstra on random grids, and every returned path checked cell by cell.
#![allow(clippy::unwrap_used, clippy::panic)]

use pathfind::movement::{path_cost, validate_dense_path};
use pathfind::{
    AStar, Dijkstra, JumpPointSearch, JumpPointSearchPlus, filter_path, line_of_sight,
    supercover_cells,
};
use proptest::prelude::*;

use crate::support::{free_cell, random_grid};
use slam_core::{BitGrid, Cell, GridPath, PlanError, Planner};

fn check(
    grid: &BitGrid,
    got: &Result<Option<GridPath>, PlanError>,
    want: &Result<Option<GridPath>, PlanError>,
    start: Cell,
    goal: Cell,
    name: &str,
) {
    match (got, want) {
        (Ok(Some(p)), Ok(Some(r))) => {
            assert!(
                (p.length - r.length).abs() < 1e-9,
                "{name}: {} vs Dijkstra {} from {start:?} to {goal:?}",
                p.length,
                r.length
            );
            let dense = p.expand();
            assert_eq!(dense.first(), Some(&start));
            assert_eq!(dense.last(), Some(&goal));
            validate_dense_path(grid, &dense)
                .unwrap_or_else(|e| panic!("{name}: invalid path {e:?}"));
            assert!(
                (path_cost(&dense) - p.length).abs() < 1e-9,
                "{name}: reported length differs from the path's"
            );
            let f = filter_path(grid, p);
            assert_eq!(f.waypoints.first(), Some(&start));
            assert_eq!(f.waypoints.last(), Some(&goal));
            assert!(f.length <= p.length + 1e-9);
            for w in f.waypoints.windows(2) {
                assert!(line_of_sight(grid, w[0], w[1]));
                for (x, y) in supercover_cells(w[0], w[1]) {
                    assert!(
                        grid.is_free_signed(x, y),
                        "{name}: filtered segment crosses ({x}, {y})"
                    );
                }
            }
        }
        (Ok(None), Ok(None)) => {}
        _ => panic!("{name}: {got:?} but Dijkstra says {want:?}"),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn planners_match_dijkstra(
        w in 1u32..200, h in 1u32..200, density in 0u32..=45, seed in any::<u64>(),
        picks in proptest::collection::vec((any::<u64>(), any::<u64>()), 1..6),
    ) {
        let grid = random_grid(w, h, density, seed);
        let mut dijkstra = Dijkstra::new(&grid);
        let mut astar = AStar::new(&grid);
        let mut jps = JumpPointSearch::new(&grid);
        let mut jps_cells = JumpPointSearch::with_cell_scans(&grid);
        let mut tables = JumpPointSearchPlus::new(&grid).unwrap();
        for (a, b) in picks {
            let (Some(start), Some(goal)) = (free_cell(&grid, a), free_cell(&grid, b)) else { continue };
            for goal in [goal, start] {
                let want = dijkstra.plan(start, goal);
                check(&grid, &astar.plan(start, goal), &want, start, goal, "A*");
                check(&grid, &jps.plan(start, goal), &want, start, goal, "JPS");
                check(&grid, &jps_cells.plan(start, goal), &want, start, goal, "JPS cells");
                check(&grid, &tables.plan(start, goal), &want, start, goal, "JPS+ tables");
                if let Ok(Some(p)) = &want {
                    validate_dense_path(&grid, &p.cells).unwrap();
                }
            }
        }
    }
}

/// Thin diagonal walls: the classic case where corner cutting or Bresenham would leak.
#[test]
fn diagonal_wall_blocks_everything() {
    // Cells with x == y are blocked: the two triangles touch only at corners.
    let grid = BitGrid::from_fn(40, 40, |x, y| x == y).unwrap();
    let (a, b) = (Cell::new(5, 0), Cell::new(0, 5));
    for r in [
        Dijkstra::new(&grid).plan(a, b),
        AStar::new(&grid).plan(a, b),
        JumpPointSearch::new(&grid).plan(a, b),
        JumpPointSearch::with_cell_scans(&grid).plan(a, b),
        JumpPointSearchPlus::new(&grid).unwrap().plan(a, b),
    ] {
        assert_eq!(r, Ok(None));
    }
    // A blocked anti-diagonal pair: the segment between (0, 0) and (2, 2) passes the corner
    // between (1, 0)/(0, 1)-style blocks and must be refused.
    let pinch = BitGrid::from_fn(3, 3, |x, y| (x, y) == (2, 1) || (x, y) == (1, 2)).unwrap();
    assert!(!line_of_sight(&pinch, Cell::new(1, 1), Cell::new(2, 2)));
    assert!(line_of_sight(&pinch, Cell::new(0, 0), Cell::new(1, 1)));
}

#[test]
fn bad_endpoints_are_errors() {
    let grid = BitGrid::from_fn(10, 10, |x, _| x == 5).unwrap();
    let mut p = JumpPointSearchPlus::new(&grid).unwrap();
    assert!(matches!(
        p.plan(Cell::new(5, 0), Cell::new(0, 0)),
        Err(PlanError::BlockedCell { which: "start", .. })
    ));
    assert!(matches!(
        p.plan(Cell::new(0, 0), Cell::new(10, 0)),
        Err(PlanError::OutOfBounds { which: "goal", .. })
    ));
    // Unreachable is an answer, not an error.
    assert_eq!(p.plan(Cell::new(0, 0), Cell::new(9, 9)), Ok(None));
    let same = p.plan(Cell::new(1, 1), Cell::new(1, 1)).unwrap().unwrap();
    assert_eq!(same.cells, vec![Cell::new(1, 1)]);
    assert!(same.length.abs() < f64::EPSILON);
}

/// Long straight runs exercise the 64-cell scans across word boundaries, with the goal inside a
/// scanned stretch.
#[test]
fn word_scans_stop_at_the_goal() {
    for w in [63u32, 64, 65, 127, 128, 129, 300] {
        let grid = BitGrid::from_fn(w, 3, |x, y| y == 0 && x % 50 == 25).unwrap();
        let mut p = JumpPointSearch::new(&grid);
        let mut t = JumpPointSearchPlus::new(&grid).unwrap();
        let mut d = Dijkstra::new(&grid);
        for (sx, gx) in [(0, w - 1), (w - 1, 0), (1, w / 2), (w / 2, 1)] {
            for y in 1..3 {
                let (s, g) = (Cell::new(sx, y), Cell::new(gx, y));
                let want = d.plan(s, g).unwrap().unwrap().length;
                assert!((p.plan(s, g).unwrap().unwrap().length - want).abs() < 1e-9);
                assert!((t.plan(s, g).unwrap().unwrap().length - want).abs() < 1e-9);
            }
        }
    }
}

proptest! {
    /// The word-based 3 x 3 neighbourhood agrees with cell-by-cell step checks.
    #[test]
    fn legal_steps_match_can_step(w in 1u32..140, h in 1u32..6, density in 0u32..60, seed in any::<u64>()) {
        use pathfind::movement::{DIRECTIONS, can_step, legal_steps};
        let grid = random_grid(w, h, density, seed);
        for y in 0..h {
            for x in 0..w {
                let c = Cell::new(x, y);
                if grid.is_blocked(c) {
                    continue;
                }
                let m = legal_steps(&grid, c);
                for (d, &(dx, dy)) in DIRECTIONS.iter().enumerate() {
                    let want = can_step(&grid, i64::from(x), i64::from(y), i64::from(dx), i64::from(dy));
                    prop_assert_eq!((m >> d) & 1 == 1, want, "cell {:?} direction {:?}", c, (dx, dy));
                }
            }
        }
    }
}

/// A path from a cell to itself has length +0.0 (a sum of no steps started at -0.0 before), in
/// every planner, in the filter and in the costed search.
#[test]
fn start_equal_to_goal_has_length_plus_zero() {
    let grid = BitGrid::from_fn(6, 4, |x, y| x == 3 && y < 3).unwrap();
    let c = Cell::new(1, 2);
    let mut planners: Vec<Box<dyn Planner>> = vec![
        Box::new(Dijkstra::new(&grid)),
        Box::new(AStar::new(&grid)),
        Box::new(JumpPointSearch::new(&grid)),
        Box::new(JumpPointSearchPlus::new(&grid).unwrap()),
    ];
    for p in &mut planners {
        let path = p.plan(c, c).unwrap().unwrap();
        assert_eq!(path.length.to_bits(), 0.0f64.to_bits());
        assert_eq!(filter_path(&grid, &path).length.to_bits(), 0.0f64.to_bits());
    }
    assert_eq!(path_cost(&[c]).to_bits(), 0.0f64.to_bits());
    let costs = vec![2.0f32; 24];
    let costed = pathfind::CellCostAStar::new(&grid, &costs)
        .unwrap()
        .plan_with_cost(c, c)
        .unwrap()
        .unwrap();
    assert_eq!(costed.cost.to_bits(), 0.0f64.to_bits());
}

/// JPS+ tables are refused past 32,767 cells a side and past 2^28 cells in all, before they are
/// allocated.
#[test]
fn jump_tables_check_sides_and_total() {
    let max_cells = pathfind::MAX_JUMP_TABLE_CELLS;
    for (w, h) in [(32_768, 1), (1, 32_768), (16_384, 16_385)] {
        let grid = BitGrid::new(w, h).unwrap();
        assert!(
            matches!(
                JumpPointSearchPlus::new(&grid),
                Err(pathfind::PathfindError::GridTooLargeForTables { max_cells: m, .. }) if m == max_cells
            ),
            "{w}x{h}"
        );
    }
    assert!(JumpPointSearchPlus::new(&BitGrid::new(32_767, 2).unwrap()).is_ok());
}
