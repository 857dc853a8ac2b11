//! `TravelCosts`: the length of the shortest walk from the robot to every cell of the planning
//! grid, one Dijkstra search for all the frontiers an explorer weighs (a plan per frontier would
//! repeat the same search from the same start).

use pathfind::movement::DIRECTIONS;
use slam_core::{BitGrid, Cell};

/// Shortest walking distances (metres) from one start cell over a grid's free cells, under the
/// grid rules the planners follow: 8-connected, diagonal steps sqrt(2) long, no corner cutting.
#[derive(Clone, Debug)]
pub struct TravelCosts {
    width: u32,
    /// Metres per cell side.
    resolution: f64,
    /// Cell sides from the start per cell, row-major; infinite where it cannot be reached
    /// (metres on lookup: one multiplication there instead of a pass over the grid).
    sides: Vec<f64>,
}

impl TravelCosts {
    /// The distances from `start` over the free cells of `blocked` (empty when `start` is off
    /// the grid or blocked: nothing is reachable).
    #[must_use]
    pub fn from_start(blocked: &BitGrid, start: Cell) -> Self {
        Self::search(blocked, start, &[])
    }

    /// The walking distances (metres) from `start` to each of `targets` (`None` where it
    /// cannot be reached or is off the grid), the search stopped once every reachable target
    /// is settled: the tour between frontier goals needs a handful of cells, not the grid.
    #[must_use]
    pub fn between(blocked: &BitGrid, start: Cell, targets: &[Cell]) -> Vec<Option<f64>> {
        let costs = Self::search(blocked, start, targets);
        targets.iter().map(|&t| costs.to(t)).collect()
    }

    /// Dijkstra from `start`; with `targets`, stopped once all of them reachable are settled
    /// (the other cells' distances are then not final).
    fn search(blocked: &BitGrid, start: Cell, targets: &[Cell]) -> Self {
        let (w, h) = (blocked.width(), blocked.height());
        let resolution = blocked.geometry().resolution;
        let mut sides = vec![f64::INFINITY; w as usize * h as usize];
        let index = |c: Cell| c.y as usize * w as usize + c.x as usize;
        let free = |x: i64, y: i64| blocked.is_free_signed(x, y);
        if blocked.get(start) != Some(false) {
            return Self {
                width: w,
                resolution,
                sides,
            };
        }
        // Only a search for targets needs the flags (a whole-grid search would fill a grid's
        // worth of `false` for nothing).
        let mut is_target = vec![false; if targets.is_empty() { 0 } else { sides.len() }];
        let mut unsettled = 0usize;
        for &t in targets {
            if blocked.get(t) == Some(false) && !is_target[index(t)] {
                is_target[index(t)] = true;
                unsettled += 1;
            }
        }
        // Distances in cell sides, queued in buckets one cell side wide: every step is at least
        // one side long, so no cell of the bucket being settled can shorten another's walk and
        // the bucket's cells are final in any order (Dial's queue; the distances are Dijkstra's
        // to the bit, each the least of the same sums). A binary heap's pops cost a third of
        // an explorer's decision on a large building.
        let mut buckets: Vec<Vec<(f64, u32, u32)>> = vec![vec![(0.0, start.x, start.y)]];
        sides[index(start)] = 0.0;
        let mut pending = 1usize;
        let mut current = 0usize;
        let mut settling = Vec::new();
        'search: while pending > 0 {
            std::mem::swap(&mut settling, &mut buckets[current]);
            pending -= settling.len();
            for &(d, x, y) in &settling {
                if d > sides[index(Cell::new(x, y))] {
                    continue;
                }
                if is_target.get(index(Cell::new(x, y))) == Some(&true) {
                    unsettled -= 1;
                    if unsettled == 0 {
                        break 'search;
                    }
                }
                let (xi, yi) = (i64::from(x), i64::from(y));
                for (dx, dy) in DIRECTIONS.map(|(dx, dy)| (i64::from(dx), i64::from(dy))) {
                    let (nx, ny) = (xi + dx, yi + dy);
                    if !free(nx, ny) {
                        continue;
                    }
                    let diagonal = dx != 0 && dy != 0;
                    // No corner cutting: a diagonal step needs both orthogonal neighbours free.
                    if diagonal && !(free(xi + dx, yi) && free(xi, yi + dy)) {
                        continue;
                    }
                    let step = if diagonal {
                        std::f64::consts::SQRT_2
                    } else {
                        1.0
                    };
                    let next = Cell::new(nx as u32, ny as u32);
                    let nd = d + step;
                    if nd < sides[index(next)] {
                        sides[index(next)] = nd;
                        // Finite and below the grid's cell count: the cast is exact enough.
                        let bucket = nd as usize;
                        if bucket >= buckets.len() {
                            buckets.resize_with(bucket + 1, Vec::new);
                        }
                        buckets[bucket].push((nd, next.x, next.y));
                        pending += 1;
                    }
                }
            }
            settling.clear();
            current += 1;
        }
        Self {
            width: w,
            resolution,
            sides,
        }
    }

    /// The walking distance (metres) to `cell`; `None` when it cannot be reached or is off the
    /// grid.
    #[must_use]
    pub fn to(&self, cell: Cell) -> Option<f64> {
        if cell.x >= self.width {
            return None;
        }
        let k = cell.y as usize * self.width as usize + cell.x as usize;
        self.sides
            .get(k)
            .map(|d| d * self.resolution)
            .filter(|m| m.is_finite())
    }

    /// Metres per cell side of the grid it was computed on.
    #[must_use]
    pub fn resolution(&self) -> f64 {
        self.resolution
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use slam_core::Planner;

    /// Every reachable cell's distance is Dijkstra's path cost to it (pathfind's, one search per
    /// cell), and no other cell is reachable.
    #[test]
    fn distances_equal_dijkstras_path_costs() {
        let mut next = crate::nav::test_lcg::lcg(7u64);
        for _ in 0..20 {
            let (w, h) = (2 + next() % 10, 2 + next() % 10);
            let grid = BitGrid::from_fn(w, h, |x, y| (x, y) != (0, 0) && next().is_multiple_of(4))
                .unwrap();
            let costs = TravelCosts::from_start(&grid, Cell::new(0, 0));
            let mut dijkstra = pathfind::Dijkstra::new(&grid);
            for y in 0..h {
                for x in 0..w {
                    let goal = Cell::new(x, y);
                    let expected = if grid.is_blocked(goal) {
                        None
                    } else {
                        dijkstra
                            .plan(Cell::new(0, 0), goal)
                            .unwrap()
                            .map(|p| p.length * grid.geometry().resolution)
                    };
                    match (costs.to(goal), expected) {
                        (Some(a), Some(b)) => assert!((a - b).abs() < 1e-9, "{a} vs {b}"),
                        (a, b) => assert_eq!(a, b, "cell ({x}, {y})"),
                    }
                }
            }
        }
    }

    /// Stopped at its targets, the search gives them the whole search's distances, to the bit.
    #[test]
    fn distances_between_targets_equal_the_whole_search() {
        let mut next = crate::nav::test_lcg::lcg(11u64);
        for _ in 0..50 {
            let (w, h) = (2 + next() % 20, 2 + next() % 20);
            let grid = BitGrid::from_fn(w, h, |x, y| (x, y) != (0, 0) && next().is_multiple_of(4))
                .unwrap();
            let targets: Vec<Cell> = (0..=next() % 5)
                .map(|_| Cell::new(next() % (w + 2), next() % h))
                .collect();
            let whole = TravelCosts::from_start(&grid, Cell::new(0, 0));
            let expected: Vec<Option<f64>> = targets.iter().map(|&t| whole.to(t)).collect();
            assert_eq!(
                TravelCosts::between(&grid, Cell::new(0, 0), &targets),
                expected
            );
        }
    }

    #[test]
    fn a_blocked_start_reaches_nothing() {
        let grid = BitGrid::from_fn(3, 3, |x, y| (x, y) == (1, 1)).unwrap();
        let costs = TravelCosts::from_start(&grid, Cell::new(1, 1));
        assert_eq!(costs.to(Cell::new(0, 0)), None);
        assert_eq!(costs.to(Cell::new(5, 0)), None);
    }
}
