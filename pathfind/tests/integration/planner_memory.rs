//! `AStar` and `JumpPointSearch` built from an earlier planner's memory answer as new planners,
//! on the same grid and after cells flipped (walls that cut or join components), against
//! Dijkstra's lengths.
#![allow(clippy::unwrap_used, clippy::panic)]

use pathfind::{AStar, Dijkstra, JumpPointSearch};
use proptest::prelude::*;

use crate::support::{free_cell, rng};
use slam_core::{BitGrid, Cell, Planner};

proptest! {
    #![proptest_config(ProptestConfig::with_cases(150))]

    #[test]
    fn planners_from_memory_answer_as_new_ones(
        w in 2u32..60, h in 2u32..60, density in 0u32..=45, seed in any::<u64>(),
        rounds in proptest::collection::vec((0usize..50, any::<u64>(), any::<u64>()), 1..6),
    ) {
        let mut r = rng(seed);
        let mut grid = BitGrid::from_fn(w, h, |_, _| (r() % 100) < u64::from(density)).unwrap();
        let mut astar_memory = AStar::new(&grid).into_memory();
        let mut jps_memory = JumpPointSearch::new(&grid).into_memory();
        for (flips, a, b) in rounds {
            for _ in 0..flips {
                let c = Cell::new((r() % u64::from(w)) as u32, (r() % u64::from(h)) as u32);
                let blocked = grid.is_blocked(c);
                grid.set(c, !blocked).unwrap();
            }
            let mut astar = AStar::with_memory(&grid, astar_memory);
            let mut jps = JumpPointSearch::with_memory(&grid, jps_memory);
            if let (Some(start), Some(goal)) = (free_cell(&grid, a), free_cell(&grid, b)) {
                let want = Dijkstra::new(&grid).plan(start, goal).unwrap().map(|p| p.length);
                let got = astar.plan(start, goal).unwrap();
                prop_assert_eq!(&got, &AStar::new(&grid).plan(start, goal).unwrap());
                prop_assert_eq!(got.is_some(), want.is_some());
                if let (Some(p), Some(want)) = (&got, want) {
                    prop_assert!((p.length - want).abs() < 1e-9);
                }
                let jumped = jps.plan(start, goal).unwrap();
                prop_assert_eq!(&jumped, &JumpPointSearch::new(&grid).plan(start, goal).unwrap());
                match (jumped, want) {
                    (Some(p), Some(want)) => prop_assert!((p.length - want).abs() < 1e-9),
                    (None, None) => {}
                    (got, want) => prop_assert!(false, "JPS {:?}, Dijkstra {:?}", got, want),
                }
            }
            astar_memory = astar.into_memory();
            jps_memory = jps.into_memory();
        }
        // Another size starts afresh.
        let other = BitGrid::new(w + 1, h).unwrap();
        let (start, goal) = (Cell::new(0, 0), Cell::new(w, h - 1));
        prop_assert!(AStar::with_memory(&other, astar_memory).plan(start, goal).unwrap().is_some());
        prop_assert!(JumpPointSearch::with_memory(&other, jps_memory).plan(start, goal).unwrap().is_some());
    }
}
