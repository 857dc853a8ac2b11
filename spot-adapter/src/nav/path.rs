//! From the planning grid to the waypoints the robot steers at: the planner's path with every
//! cell, then the turning points a straight segment with room to spare cannot skip.

use gridmap::PlanningGrid;
use nalgebra::Vector2;

use pathfind::filter_path;
use pathfind::movement::validate_dense_path;
use slam_core::{BitGrid, Cell, GridPath};

use crate::nav::NavError;
use crate::nav::planner::NavPlanner;

/// A path to the goal and the waypoints along it, kept together from the plan to the goal: the
/// path's cells are what the blocked-path test and the detour policy read, the waypoints what
/// the controller steers at.
#[derive(Clone, Debug)]
pub(crate) struct Plan {
    /// Every cell from the start to the goal, and the length in cells (straight 1, diagonal
    /// sqrt(2)).
    path: GridPath,
    /// Waypoints (metres) after the start, ending at the goal ...
    waypoints: Vec<Vector2<f64>>,
    /// ... of which this many are behind the robot.
    passed: usize,
}

impl Default for Plan {
    fn default() -> Self {
        Self {
            path: GridPath {
                cells: Vec::new(),
                length: 0.0,
                expanded: 0,
            },
            waypoints: Vec::new(),
            passed: 0,
        }
    }
}

impl Plan {
    /// A plan on `planning` by `planner` from `position` to `goal`, its straight segments
    /// keeping `shortcut_clearance` (metres) where they can, or `None` when no path joins them
    /// (either end off the map, the goal blocked, or no path). A start inside the inflated
    /// obstacles (the robot brushed a wall) plans from the nearest free cell.
    pub(crate) fn search<P: NavPlanner>(
        planning: &PlanningGrid,
        planner: &mut P,
        memory: &mut P::Memory,
        shortcut_clearance: f64,
        position: Vector2<f64>,
        goal: Vector2<f64>,
    ) -> Result<Option<Self>, NavError> {
        let Some(path) = dense_path(planning, planner, memory, position, goal)? else {
            return Ok(None);
        };
        let waypoints = waypoints_along(planning, shortcut_clearance, &path, goal);
        Ok(Some(Self {
            path,
            waypoints,
            passed: 0,
        }))
    }

    /// The path, every cell from the start to the goal (empty when there is none).
    pub(crate) fn path(&self) -> &GridPath {
        &self.path
    }

    /// Whether there is a path to follow.
    pub(crate) fn has_path(&self) -> bool {
        !self.path.cells.is_empty()
    }

    /// The waypoints (metres) still ahead, ending at the goal.
    pub(crate) fn waypoints(&self) -> &[Vector2<f64>] {
        &self.waypoints[self.passed..]
    }

    /// Pass the waypoints within `near` (metres) of `position`, all but the last.
    pub(crate) fn pass(&mut self, position: Vector2<f64>, near: f64) {
        while self.waypoints().len() > 1 && (self.waypoints()[0] - position).norm() <= near {
            self.passed += 1;
        }
    }

    /// Drop the path and its waypoints.
    pub(crate) fn clear(&mut self) {
        self.clear_path();
        self.clear_waypoints();
    }

    /// Drop the path (the next cycle plans again); the waypoints stay until it does.
    pub(crate) fn clear_path(&mut self) {
        self.path.cells.clear();
        self.path.length = 0.0;
    }

    /// Drop the waypoints (the robot stops following them); the path stays.
    pub(crate) fn clear_waypoints(&mut self) {
        self.waypoints.clear();
        self.passed = 0;
    }

    /// The index and centre (metres) of the path's cell nearest `position`, or `None` without a
    /// path.
    pub(crate) fn nearest_cell(
        &self,
        grid: &BitGrid,
        position: Vector2<f64>,
    ) -> Option<(usize, Vector2<f64>)> {
        self.path
            .cells
            .iter()
            .map(|c| grid.cell_center(*c))
            .enumerate()
            .min_by(|a, b| {
                let d = |c: &Vector2<f64>| (c - position).norm_squared();
                d(&a.1).total_cmp(&d(&b.1))
            })
    }

    /// The path from the robot on: `connection` (a dense path from the robot's cell to the
    /// path's cell `at`), then the path after `at`, its waypoints made afresh: the route kept, as
    /// a replan from here along it would give. Joining the path by a plan, not at its nearest
    /// cell, matters: the robot walks the straight shortcuts between waypoints, so the nearest
    /// cell can lie half a metre off, and the first waypoint from there round a corner the
    /// robot cannot see past.
    pub(crate) fn follow_on(
        &mut self,
        planning: &PlanningGrid,
        shortcut_clearance: f64,
        connection: GridPath,
        at: usize,
        goal: Vector2<f64>,
    ) {
        let mut cells = connection.cells;
        cells.extend_from_slice(self.path.cells.get(at + 1..).unwrap_or_default());
        self.path.cells = cells;
        self.path.length = cells_length(&self.path.cells);
        self.waypoints = waypoints_along(planning, shortcut_clearance, &self.path, goal);
        self.passed = 0;
    }
}

/// The path on `planning` from `position` to `goal` by `planner` with every cell, its length
/// that of those cells, or `None` when none joins them (see [`Plan::search`]); the planner
/// reuses and keeps `memory`.
///
/// # Errors
/// [`NavError::Planner`] with the planner's error; [`NavError::InvalidPath`] when its path does
/// not join the endpoints through free cells.
pub(crate) fn dense_path<P: NavPlanner>(
    planning: &PlanningGrid,
    planner: &mut P,
    memory: &mut P::Memory,
    position: Vector2<f64>,
    goal: Vector2<f64>,
) -> Result<Option<GridPath>, NavError> {
    let grid = planning.blocked();
    let Some(goal_cell) = grid.cell_at(goal).filter(|&c| !grid.is_blocked(c)) else {
        return Ok(None);
    };
    let Some(start) = grid.cell_at(position).and_then(|c| nearest_free(grid, c)) else {
        return Ok(None);
    };
    let Some(path) = planner
        .plan(planning, memory, start, goal_cell)
        .map_err(NavError::Planner)?
    else {
        return Ok(None);
    };
    let cells = path.expand();
    // Any planner may be plugged in: what it returns is checked before the robot follows it.
    if let Err(violation) = validate_dense_path(grid, &cells) {
        return Err(NavError::InvalidPath { violation });
    }
    let ends = (cells.first().copied(), cells.last().copied());
    if ends != (Some(start), Some(goal_cell)) {
        return Err(NavError::PathEndpoints {
            start,
            goal: goal_cell,
            first: ends.0.unwrap_or(start),
            last: ends.1.unwrap_or(goal_cell),
        });
    }
    // The length of the cells walked, not the planner's cost (which counts the clearance cost).
    Ok(Some(GridPath {
        length: cells_length(&cells),
        expanded: path.expanded,
        cells,
    }))
}

/// Waypoints (metres) along the dense `path` to `goal`, after its first cell: the turning
/// points a straight segment keeping `shortcut_clearance` cannot skip, then the goal.
fn waypoints_along(
    planning: &PlanningGrid,
    shortcut_clearance: f64,
    path: &GridPath,
    goal: Vector2<f64>,
) -> Vec<Vector2<f64>> {
    let grid = planning.blocked();
    // Shortcuts only where they keep room to spare; in narrow places the path's cells.
    let roomy = planning.roomy(shortcut_clearance);
    let filtered = filter_path(&roomy, path);
    let mut waypoints: Vec<Vector2<f64>> = filtered
        .waypoints
        .iter()
        .skip(1)
        .map(|&c| grid.cell_center(c))
        .collect();
    // The goal itself, not its cell's centre, ends the path.
    if let Some(last) = waypoints.last_mut() {
        *last = goal;
    } else {
        waypoints.push(goal);
    }
    waypoints
}

/// Length of a chain of 8-connected cells, in cells.
fn cells_length(cells: &[Cell]) -> f64 {
    cells
        .windows(2)
        .map(|w| {
            let diagonal = w[0].x != w[1].x && w[0].y != w[1].y;
            if diagonal {
                std::f64::consts::SQRT_2
            } else {
                1.0
            }
        })
        .sum()
}

/// `cell` when free, else the nearest free cell within 1 m at 0.10 m cells (rings of growing
/// Chebyshev radius, nearest centre first within a ring).
fn nearest_free(grid: &BitGrid, cell: Cell) -> Option<Cell> {
    if !grid.is_blocked(cell) {
        return Some(cell);
    }
    let (cx, cy) = (i64::from(cell.x), i64::from(cell.y));
    for r in 1..=10i64 {
        let ring = (-r..=r)
            .flat_map(|dx| (-r..=r).map(move |dy| (dx, dy)))
            .filter(|&(dx, dy)| dx.abs() == r || dy.abs() == r);
        let best = ring
            .filter(|&(dx, dy)| grid.is_free_signed(cx + dx, cy + dy))
            .min_by_key(|&(dx, dy)| dx * dx + dy * dy);
        if let Some((dx, dy)) = best {
            return Some(Cell::new((cx + dx) as u32, (cy + dy) as u32));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nav::{PlannerKind, PlannerMemory};
    use gridmap::{CellState, OccupancyGrid, PlanningGridConfig};
    use pathfind::line_of_sight;
    use slam_core::{GridGeometry, PlanError};

    /// A planner that answers every query with the same cells (or error).
    struct Fixed(Result<Vec<Cell>, &'static str>);

    impl NavPlanner for Fixed {
        type Memory = ();

        fn plan(
            &mut self,
            _: &PlanningGrid,
            (): &mut (),
            _: Cell,
            _: Cell,
        ) -> Result<Option<GridPath>, PlanError> {
            let cells = self.0.clone().map_err(|e| PlanError::backend("fixed", e))?;
            Ok(Some(GridPath {
                cells,
                length: 0.0,
                expanded: 0,
            }))
        }
    }

    /// 40 x 20 free cells of 0.1 m, with an obstacle at `wall` if given.
    fn planning(wall: Option<Cell>) -> PlanningGrid {
        let cells = GridGeometry {
            resolution: 0.1,
            ..GridGeometry::default()
        };
        let mut occupancy = OccupancyGrid::new(40, 20, cells, CellState::Free).unwrap();
        if let Some(c) = wall {
            occupancy.set(c, CellState::Occupied).unwrap();
        }
        PlanningGrid::new(&occupancy, PlanningGridConfig::default()).unwrap()
    }

    #[test]
    fn a_plugged_in_planners_path_is_checked_before_it_is_followed() {
        // From cell (5, 10) to cell (35, 10).
        let (from, to) = (Vector2::new(0.55, 1.05), Vector2::new(3.55, 1.05));
        let (start, goal) = (Cell::new(5, 10), Cell::new(35, 10));
        let free = planning(None);
        // Turning points joined by straight runs: expanded to every cell, its length walked.
        let path = dense_path(&free, &mut Fixed(Ok(vec![start, goal])), &mut (), from, to)
            .unwrap()
            .unwrap();
        assert_eq!(path.cells.len(), 31);
        assert!((path.length - 30.0).abs() < 1e-12);
        // Short of the goal.
        let short = dense_path(
            &free,
            &mut Fixed(Ok(vec![start, Cell::new(20, 10)])),
            &mut (),
            from,
            to,
        );
        assert!(
            matches!(short, Err(NavError::PathEndpoints { last, .. }) if last == Cell::new(20, 10)),
            "{short:?}"
        );
        // Through an obstacle: the straight run crosses its inflation.
        let walled = planning(Some(Cell::new(20, 10)));
        let through = dense_path(
            &walled,
            &mut Fixed(Ok(vec![start, goal])),
            &mut (),
            from,
            to,
        );
        assert!(
            matches!(through, Err(NavError::InvalidPath { .. })),
            "{through:?}"
        );
        // No cells at all.
        let empty = dense_path(&free, &mut Fixed(Ok(Vec::new())), &mut (), from, to);
        assert!(
            matches!(empty, Err(NavError::InvalidPath { .. })),
            "{empty:?}"
        );
        // The planner's own failure, its error kept as the source.
        let failed = dense_path(&free, &mut Fixed(Err("out of fuel")), &mut (), from, to);
        let Err(NavError::Planner(
            e @ PlanError::Backend {
                backend: "fixed", ..
            },
        )) = failed
        else {
            panic!("{failed:?}");
        };
        let source = std::error::Error::source(&e).unwrap();
        assert_eq!(source.to_string(), "out of fuel");
        // Ours go round the obstacle, each keeping its memory.
        for mut kind in [
            PlannerKind::CellCostAStar,
            PlannerKind::JumpPointSearch,
            PlannerKind::AStar,
        ] {
            let mut memory = PlannerMemory::default();
            for _ in 0..2 {
                let path = dense_path(&walled, &mut kind, &mut memory, from, to)
                    .unwrap()
                    .unwrap();
                assert_eq!(path.cells.first(), Some(&start));
                assert_eq!(path.cells.last(), Some(&goal));
                assert!(path.length > 30.0, "{kind:?}: {}", path.length);
            }
        }
    }

    #[test]
    fn a_blocked_start_moves_to_the_closest_free_cell_of_the_first_ring_that_has_one() {
        // A 3-cell-thick wall across the middle; free everywhere else.
        let grid = BitGrid::from_fn(20, 20, |_, y| (9..12).contains(&y)).unwrap();
        assert_eq!(nearest_free(&grid, Cell::new(5, 3)), Some(Cell::new(5, 3)));
        // From the wall's middle row, the nearest free cells are 2 rows away, straight up or down.
        let found = nearest_free(&grid, Cell::new(5, 10)).unwrap();
        assert_eq!(found.x, 5);
        assert!(found.y == 8 || found.y == 12, "{found:?}");
        // Nothing free within 10 cells: no start.
        let solid = BitGrid::from_fn(30, 30, |_, _| true).unwrap();
        assert_eq!(nearest_free(&solid, Cell::new(15, 15)), None);
    }

    #[test]
    fn following_on_from_off_the_path_joins_it_where_the_robot_can_see() {
        // 40 x 40 cells of 0.1 m with a block in the middle (cells 14..26 both ways), inflated.
        let cells = GridGeometry {
            resolution: 0.1,
            ..GridGeometry::default()
        };
        let mut occupancy = OccupancyGrid::new(40, 40, cells, CellState::Free).unwrap();
        for x in 14..26 {
            for y in 14..26 {
                occupancy.set(Cell::new(x, y), CellState::Occupied).unwrap();
            }
        }
        let planning = PlanningGrid::new(&occupancy, PlanningGridConfig::default()).unwrap();
        let grid = planning.blocked();
        let centre = |c: Cell| grid.cell_center(c);
        // The path runs below the block and up its right side; the robot stands 0.8 m above its
        // first leg, where a shortcut would have taken it, left of the block.
        let (turn, goal) = (Cell::new(32, 8), Cell::new(32, 36));
        let route = vec![Cell::new(3, 8), turn, goal];
        let mut plan = Plan::search(
            &planning,
            &mut Fixed(Ok(route)),
            &mut (),
            0.0,
            centre(Cell::new(3, 8)),
            centre(goal),
        )
        .unwrap()
        .unwrap();
        let robot = Cell::new(6, 16);
        let position = centre(robot);
        assert!(!grid.is_blocked(robot));
        let (at, nearest) = plan.nearest_cell(grid, position).unwrap();
        assert_eq!(grid.cell_at(nearest), Some(Cell::new(6, 8)));
        // The case this guards: made afresh from the nearest cell, the first waypoint is the
        // turn below the block's far corner, which the robot cannot see (the block is between).
        let mut from_nearest = plan.path.clone();
        from_nearest.cells.drain(..at);
        let naive = waypoints_along(&planning, 0.0, &from_nearest, centre(goal));
        let first = grid.cell_at(naive[0]).unwrap();
        assert!(!line_of_sight(grid, robot, first), "{first:?}");
        // Joined by a plan from the robot's cell, every waypoint sees the next, the first seen
        // from the robot; the route (below the block) kept.
        let join = vec![robot, Cell::new(6, 8)];
        let connection = dense_path(&planning, &mut Fixed(Ok(join)), &mut (), position, nearest)
            .unwrap()
            .unwrap();
        plan.follow_on(&planning, 0.0, connection, at, centre(goal));
        assert_eq!(plan.path().cells.first(), Some(&robot));
        assert_eq!(plan.path().cells.last(), Some(&goal));
        validate_dense_path(grid, &plan.path().cells).unwrap();
        let mut from = robot;
        for w in plan.waypoints() {
            let cell = grid.cell_at(*w).unwrap();
            assert!(line_of_sight(grid, from, cell), "{from:?} -> {cell:?}");
            from = cell;
        }
        assert!(plan.path().cells.contains(&turn));
    }

    #[test]
    fn passing_waypoints_keeps_the_last_one() {
        let mut plan = Plan {
            waypoints: vec![
                Vector2::new(0.0, 0.0),
                Vector2::new(0.01, 0.0),
                Vector2::new(1.0, 0.0),
            ],
            ..Plan::default()
        };
        plan.pass(Vector2::zeros(), 0.02);
        assert_eq!(plan.waypoints(), &[Vector2::new(1.0, 0.0)]);
        plan.pass(Vector2::new(1.0, 0.0), 0.02);
        assert_eq!(plan.waypoints(), &[Vector2::new(1.0, 0.0)]);
        plan.clear_waypoints();
        assert!(plan.waypoints().is_empty());
    }
}
