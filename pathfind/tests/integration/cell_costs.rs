//! `CellCostAStar` against a brute-force Dijkstra on the same per-cell costs, and on a corridor
//! with a door under a clearance cost.
#![allow(clippy::unwrap_used, clippy::panic)]

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use pathfind::movement::{can_step, validate_dense_path};
use pathfind::{AStar, CellCostAStar, Dijkstra, PathfindError};
use proptest::prelude::*;

use crate::support::{free_cell, random_grid, rng};
use slam_core::{BitGrid, Cell, PlanError, Planner};

/// Random multipliers: all 1, uniform in [1, 6), a few expensive cells among cheap ones, or
/// multipliers up to 1000 (past the bucket ring's range: the heap).
fn random_costs(n: usize, kind: u8, seed: u64) -> Vec<f32> {
    let mut r = rng(seed ^ 0x9E37_79B9_7F4A_7C15);
    (0..n)
        .map(|_| match kind {
            0 => 1.0,
            1 => 1.0 + (r() % 5000) as f32 / 1000.0,
            3 => 1.0 + (r() % 1000) as f32,
            _ => {
                if r().is_multiple_of(10) {
                    20.0
                } else {
                    1.0 + (r() % 3) as f32 * 0.25
                }
            }
        })
        .collect()
}

/// Brute-force Dijkstra with the planner's cost model written out independently: a step into
/// cell `n` costs its length times `costs[n]`; legal steps by `can_step` (no corner cutting).
fn oracle(grid: &BitGrid, costs: &[f32], start: Cell, goal: Cell) -> Option<f64> {
    let (w, h) = (i64::from(grid.width()), i64::from(grid.height()));
    let idx = |x: i64, y: i64| (y * w + x) as usize;
    let mut dist = vec![f64::INFINITY; (w * h) as usize];
    let mut heap = BinaryHeap::new();
    let (sx, sy) = (i64::from(start.x), i64::from(start.y));
    dist[idx(sx, sy)] = 0.0;
    heap.push(Reverse((0u64, sx, sy)));
    while let Some(Reverse((bits, x, y))) = heap.pop() {
        let d = f64::from_bits(bits);
        if d > dist[idx(x, y)] {
            continue;
        }
        if (x, y) == (i64::from(goal.x), i64::from(goal.y)) {
            return Some(d);
        }
        for dx in -1..=1 {
            for dy in -1..=1 {
                if (dx, dy) == (0, 0) || !can_step(grid, x, y, dx, dy) {
                    continue;
                }
                let len = if dx != 0 && dy != 0 {
                    std::f64::consts::SQRT_2
                } else {
                    1.0
                };
                let (nx, ny) = (x + dx, y + dy);
                let nd = d + len * f64::from(costs[idx(nx, ny)]);
                if nd < dist[idx(nx, ny)] {
                    dist[idx(nx, ny)] = nd;
                    heap.push(Reverse((nd.to_bits(), nx, ny)));
                }
            }
        }
    }
    None
}

/// The cost of a dense path recomputed from the costs.
fn cost_along(grid: &BitGrid, costs: &[f32], cells: &[Cell]) -> f64 {
    let w = grid.width() as usize;
    cells
        .windows(2)
        .map(|p| {
            let diagonal = p[0].x != p[1].x && p[0].y != p[1].y;
            let len = if diagonal {
                std::f64::consts::SQRT_2
            } else {
                1.0
            };
            len * f64::from(costs[p[1].y as usize * w + p[1].x as usize])
        })
        .sum()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn cost_equals_brute_force_dijkstra(
        w in 1u32..70, h in 1u32..70, density in 0u32..=40, seed in any::<u64>(), kind in 0u8..4,
        picks in proptest::collection::vec((any::<u64>(), any::<u64>()), 1..5),
    ) {
        let grid = random_grid(w, h, density, seed);
        let costs = random_costs(grid.len(), kind, seed);
        let mut planner = CellCostAStar::new(&grid, &costs).unwrap();
        let mut uniform = CellCostAStar::without_heuristic(&grid, &costs).unwrap();
        let mut dijkstra = Dijkstra::new(&grid);
        let mut astar = AStar::new(&grid);
        for (a, b) in picks {
            let (Some(start), Some(goal)) = (free_cell(&grid, a), free_cell(&grid, b)) else { continue };
            let want = oracle(&grid, &costs, start, goal);
            let got = planner.plan_with_cost(start, goal).unwrap();
            let ablation = uniform.plan_with_cost(start, goal).unwrap();
            match (&got, want) {
                (Some(p), Some(want)) => {
                    prop_assert!((p.cost - want).abs() <= 1e-9 * want.max(1.0),
                        "cost {} vs brute force {} from {:?} to {:?}", p.cost, want, start, goal);
                    let a = ablation.unwrap();
                    prop_assert!((a.cost - want).abs() <= 1e-9 * want.max(1.0));
                    prop_assert!(a.path.expanded >= p.path.expanded);
                    let cells = &p.path.cells;
                    prop_assert_eq!(cells.first(), Some(&start));
                    prop_assert_eq!(cells.last(), Some(&goal));
                    prop_assert_eq!(validate_dense_path(&grid, cells), Ok(()));
                    prop_assert!((cost_along(&grid, &costs, cells) - p.cost).abs() <= 1e-9 * want.max(1.0));
                    prop_assert!((pathfind::movement::path_cost(cells) - p.path.length).abs() < 1e-9);
                    prop_assert!(p.cost >= p.path.length - 1e-9, "multipliers are at least 1");
                    if kind == 0 {
                        // Unit costs: the shortest length, as Dijkstra's and A*'s.
                        let d = dijkstra.plan(start, goal).unwrap().unwrap();
                        let s = astar.plan(start, goal).unwrap().unwrap();
                        prop_assert!((p.path.length - d.length).abs() < 1e-9);
                        prop_assert!((p.path.length - s.length).abs() < 1e-9);
                        prop_assert!((p.cost - p.path.length).abs() < 1e-9);
                    }
                }
                (None, None) => prop_assert!(ablation.is_none()),
                _ => prop_assert!(false, "planner {:?} but brute force {:?}", got, want),
            }
        }
    }

    /// A planner built from an earlier one's memory, on the same grid or after cells flipped
    /// (walls that cut or join components) and costs changed, answers as a new planner and as
    /// the brute force: stale component labels would call a joined goal unreachable.
    #[test]
    fn a_planner_from_memory_answers_as_a_new_one(
        w in 2u32..50, h in 2u32..50, density in 0u32..=45, seed in any::<u64>(), kind in 0u8..4,
        rounds in proptest::collection::vec((0usize..40, any::<u64>(), any::<u64>(), any::<u64>()), 1..6),
    ) {
        let mut grid = random_grid(w, h, density, seed);
        let mut costs = random_costs(grid.len(), kind, seed);
        let mut memory = CellCostAStar::new(&grid, &costs).unwrap().into_memory();
        let mut r = rng(seed.rotate_left(7));
        for (flips, a, b, cost_seed) in rounds {
            for _ in 0..flips {
                let c = Cell::new((r() % u64::from(w)) as u32, (r() % u64::from(h)) as u32);
                let blocked = grid.is_blocked(c);
                grid.set(c, !blocked).unwrap();
            }
            if cost_seed % 3 == 0 {
                costs = random_costs(grid.len(), kind, cost_seed);
            }
            let mut reused = CellCostAStar::with_memory(&grid, &costs, memory).unwrap();
            let mut fresh = CellCostAStar::new(&grid, &costs).unwrap();
            if let (Some(start), Some(goal)) = (free_cell(&grid, a), free_cell(&grid, b)) {
                let got = reused.plan_with_cost(start, goal).unwrap();
                prop_assert_eq!(&got, &fresh.plan_with_cost(start, goal).unwrap());
                let want = oracle(&grid, &costs, start, goal);
                prop_assert_eq!(got.is_some(), want.is_some());
                if let (Some(p), Some(want)) = (got, want) {
                    prop_assert!((p.cost - want).abs() <= 1e-9 * want.max(1.0));
                }
            }
            memory = reused.into_memory();
        }
        // A grid of another size, larger or smaller, starts afresh in the memory's allocations.
        for (ow, oh) in [(w + 1, h), (w, h + 3), (w - 1, h)] {
            let other = random_grid(ow, oh, density, seed ^ u64::from(ow));
            let other_costs = random_costs(other.len(), kind, seed.rotate_left(3));
            let mut planner = CellCostAStar::with_memory(&other, &other_costs, memory).unwrap();
            let mut fresh = CellCostAStar::new(&other, &other_costs).unwrap();
            if let (Some(start), Some(goal)) = (free_cell(&other, 1), free_cell(&other, 99)) {
                prop_assert_eq!(
                    planner.plan_with_cost(start, goal).unwrap(),
                    fresh.plan_with_cost(start, goal).unwrap()
                );
            }
            memory = planner.into_memory();
        }
    }
}

#[test]
fn bad_costs_and_endpoints_are_errors() {
    let grid = BitGrid::from_fn(10, 10, |x, _| x == 5).unwrap();
    let short = vec![1.0; 99];
    assert!(matches!(
        CellCostAStar::new(&grid, &short),
        Err(PathfindError::CellCostCount { got: 99, .. })
    ));
    for bad in [0.5, f32::NAN, f32::INFINITY, -1.0] {
        let mut costs = vec![1.0; 100];
        costs[3 * 10 + 2] = bad;
        assert!(matches!(
            CellCostAStar::new(&grid, &costs),
            Err(PathfindError::InvalidCellCost { x: 2, y: 3, .. })
        ));
        // On a blocked cell the value is ignored.
        let mut costs = vec![1.0; 100];
        costs[3 * 10 + 5] = bad;
        assert!(CellCostAStar::new(&grid, &costs).is_ok());
    }
    // Multipliers so large that the costliest path could overflow the fixed-point costs.
    let mut huge = vec![1.0; 100];
    huge[0] = 1.0e30;
    assert!(matches!(
        CellCostAStar::new(&grid, &huge),
        Err(PathfindError::CellCostsTooLarge { cells: 90, .. })
    ));
    // Large but representable with fewer fractional bits: still least-cost paths.
    let mut large = vec![1.0; 100];
    large[2 * 10 + 2] = 1.0e9;
    let mut p = CellCostAStar::new(&grid, &large).unwrap();
    let around = p
        .plan_with_cost(Cell::new(1, 2), Cell::new(3, 2))
        .unwrap()
        .unwrap();
    assert!((around.cost - 2.0 * std::f64::consts::SQRT_2).abs() < 1e-9);
    let through = p
        .plan_with_cost(Cell::new(1, 2), Cell::new(2, 2))
        .unwrap()
        .unwrap();
    assert!((through.cost - 1.0e9).abs() < 1e-3);
    let costs = vec![1.0; 100];
    let mut p = CellCostAStar::new(&grid, &costs).unwrap();
    assert!(matches!(
        p.plan(Cell::new(5, 0), Cell::new(0, 0)),
        Err(PlanError::BlockedCell { which: "start", .. })
    ));
    assert!(matches!(
        p.plan(Cell::new(0, 0), Cell::new(0, 10)),
        Err(PlanError::OutOfBounds { which: "goal", .. })
    ));
    assert_eq!(p.plan(Cell::new(0, 0), Cell::new(9, 9)), Ok(None));
    let same = p
        .plan_with_cost(Cell::new(1, 1), Cell::new(1, 1))
        .unwrap()
        .unwrap();
    assert_eq!(same.path.cells, vec![Cell::new(1, 1)]);
    assert!(same.cost.abs() < f64::EPSILON);
}

/// A corridor with a door, at 0.1 m cells: the map's obstacles, hard-inflated by 0.30 m (Spot's
/// half width 0.25 m + 0.05 m), and a clearance cost computed here by brute force (multiplier
/// `1 + 2 ((1 - d) / 0.7)^2` between 0.3 m and 1 m from the nearest obstacle, 1 beyond).
///
/// The corridor runs east-west, 2.0 m between wall cell centres (19 free rows); a cross wall at
/// x = 6 m has a door that the map shows with 8 free cells (a 0.9 m door: its frame cells' centres
/// 0.9 m apart). Inflated by 0.40 m the door closes; by 0.30 m two cells stay open.
#[test]
fn corridor_path_keeps_to_the_middle_and_passes_the_door() {
    let res = 0.1;
    let (w, h) = (120u32, 21u32);
    let door = 6..14u32; // free rows of the door in the cross wall at column 60
    let obstacle = |x: u32, y: u32| y == 0 || y == h - 1 || (x == 60 && !door.contains(&y));
    let map = BitGrid::from_fn(w, h, obstacle).unwrap();
    let obstacles: Vec<Cell> = map.blocked_cells().collect();
    let distance = |x: u32, y: u32| {
        obstacles
            .iter()
            .map(|o| {
                let (dx, dy) = (f64::from(o.x) - f64::from(x), f64::from(o.y) - f64::from(y));
                (dx * dx + dy * dy).sqrt() * res
            })
            .fold(f64::INFINITY, f64::min)
    };
    let inflated =
        |radius: f64| BitGrid::from_fn(w, h, |x, y| distance(x, y) <= radius + 1e-9).unwrap();
    let costs: Vec<f32> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let d = distance(x, y);
            let p = ((1.0 - d) / 0.7).clamp(0.0, 1.0);
            (1.0 + 2.0 * p * p) as f32
        })
        .collect();
    // Start and goal 0.5 m from the south wall (row 5), either side of the door.
    let (start, goal) = (Cell::new(5, 5), Cell::new(114, 5));
    let wide = inflated(0.40);
    assert_eq!(
        AStar::new(&wide).plan(start, goal).unwrap(),
        None,
        "0.40 m closes the door"
    );
    let grid = inflated(0.30);
    let open: Vec<u32> = (0..h)
        .filter(|&y| !grid.is_blocked(Cell::new(60, y)))
        .collect();
    assert_eq!(
        open,
        vec![9, 10],
        "0.30 m leaves the door's middle two cells"
    );
    let shortest = AStar::new(&grid).plan(start, goal).unwrap().unwrap();
    let found = CellCostAStar::new(&grid, &costs)
        .unwrap()
        .plan_with_cost(start, goal)
        .unwrap()
        .expect("the door is open at 0.30 m");
    validate_dense_path(&grid, &found.path.cells).unwrap();
    assert!(found.path.cells.iter().any(|c| c.x == 60));
    // Away from the ends and the door, the path runs on the corridor's middle rows (9-11, 0.9 m
    // or more from both walls); the shortest path keeps the rows it can.
    let middle = |p: &[Cell]| {
        p.iter()
            .filter(|c| (20..50).contains(&c.x) || (70..100).contains(&c.x))
            .all(|c| (9..=11).contains(&c.y))
    };
    assert!(middle(&found.path.cells), "{:?}", found.path.cells);
    assert!(!middle(&shortest.cells));
    assert!(found.path.length > shortest.length);
    assert!(found.path.length < shortest.length + 2.0, "a small detour");
}
