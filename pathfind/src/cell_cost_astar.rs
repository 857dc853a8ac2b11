//! A* on a grid whose cells cost more to enter than their step length: each step costs its length
//! times the multiplier of the cell it enters (at least 1), so the octile heuristic stays
//! admissible and consistent and the first expansion of the goal is optimal.

use slam_core::{BitGrid, Cell, GridPath, PlanError, Planner, validate_endpoints};

use crate::closed_set::ClosedSet;
use crate::components::Components;
use crate::error::PathfindError;
use crate::movement::{DIRECTIONS, SQRT_2, octile, path_cost};
use crate::open_list::{KeyHeap, Open, OpenList};

/// Length of a step in each of the [`DIRECTIONS`]: four straight, then four diagonal.
const STEP_LENGTH: [f64; 8] = [1.0, 1.0, 1.0, 1.0, SQRT_2, SQRT_2, SQRT_2, SQRT_2];

/// A least-cost path found by [`CellCostAStar`].
#[derive(Clone, Debug, PartialEq)]
pub struct CostedPath {
    /// The cells (dense: every cell from start to goal), their geometric length in cells
    /// (straight 1, diagonal sqrt(2)) and the expansions.
    pub path: GridPath,
    /// The path's cost: the sum over its steps of the step's length (cells) times the cost
    /// multiplier of the cell the step enters. Equals `path.length` when every multiplier is 1.
    pub cost: f64,
}

/// One cell's search record.
#[derive(Clone, Copy, Debug)]
struct Node {
    g: f64,
    parent: u32,
    /// `generation << 1 | closed`: `g` and `parent` are valid when the generation is current.
    stamp: u32,
}

/// Generations run from 1 to this value, then the stamps are cleared once.
const MAX_GENERATION: u32 = u32::MAX >> 1;

/// A* for per-cell traversal costs: a step from a cell to a neighbour costs the step's length
/// (1 straight, sqrt(2) diagonal) times the neighbour's cost multiplier, so the planner returns
/// the least-cost path under f = g + h, with g summing those costs and h the octile distance.
/// This is the thesis' future-work cost f = g + h + o with the obstacle term o spread over the
/// steps: a clearance cost from a distance field (gridmap's `clearance_step_costs`) makes paths
/// keep to the middle of corridors while still passing narrow doors.
///
/// Why it is optimal: every multiplier is at least 1, so a step costs at least its length and the
/// octile distance (the exact cost on an empty grid of unit multipliers) never overestimates:
/// admissible, and consistent since it obeys the triangle inequality step by step. With every
/// multiplier 1 the costs are those of [`AStar`](crate::AStar) and the paths have the same length.
///
/// Movement: 8-connected, no corner cutting (a diagonal step needs both orthogonal neighbours
/// free), as every planner of this crate. Paths are dense (every cell listed). Costs are summed in
/// `f64`; paths of equal cost are told apart by the larger `g` first.
///
/// When not to use it: with every multiplier 1 use [`JumpPointSearch`](crate::JumpPointSearch)
/// (the same path lengths, far fewer expansions); the jump-point planners cannot take per-cell
/// costs.
///
/// ```
/// use pathfind::CellCostAStar;
/// use slam_core::{BitGrid, Cell, Planner};
///
/// // A 9 x 3 strip; the middle row costs 3 per unit length, the outer rows 1.
/// let grid = BitGrid::new(9, 3)?;
/// let costs: Vec<f32> = (0..27).map(|i| if i / 9 == 1 { 3.0 } else { 1.0 }).collect();
/// let mut planner = CellCostAStar::new(&grid, &costs)?;
/// let found = planner.plan_with_cost(Cell::new(0, 1), Cell::new(8, 1))?.expect("a free strip");
/// // Up into the cheap row, along it, and back down: 2 diagonal steps into cost-1 and cost-3
/// // cells and 6 straight cost-1 steps.
/// assert!((found.cost - (6.0 + 4.0 * std::f64::consts::SQRT_2)).abs() < 1e-9);
/// // The plain `Planner` answer is the same path.
/// assert_eq!(planner.plan(Cell::new(0, 1), Cell::new(8, 1))?, Some(found.path));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct CellCostAStar<'g> {
    grid: &'g BitGrid,
    costs: &'g [f32],
    components: Components,
    closed: ClosedSet,
    nodes: Vec<Node>,
    generation: u32,
    open: KeyHeap,
    /// Whether the octile heuristic guides the search (off: Dijkstra's order, an ablation).
    heuristic: bool,
}

impl<'g> CellCostAStar<'g> {
    /// A planner for `grid` with `costs`, the cost multiplier of entering each cell (row-major,
    /// `width * height` values, `costs[y * width + x]` for cell (x, y); dimensionless: a step's
    /// cost is its length in cells times the multiplier). Values on blocked cells are ignored.
    /// Labels the grid's connected components once and allocates 16 bytes of search records per
    /// cell, reused by every query.
    ///
    /// # Errors
    /// [`PathfindError::CellCostCount`] when `costs` does not have one value per cell,
    /// [`PathfindError::InvalidCellCost`] for a free cell whose multiplier is not finite or is
    /// below 1 (a multiplier below 1 would make the octile heuristic overestimate).
    pub fn new(grid: &'g BitGrid, costs: &'g [f32]) -> Result<Self, PathfindError> {
        check_costs(grid, costs)?;
        Ok(Self {
            grid,
            costs,
            components: Components::new(grid),
            closed: ClosedSet::new(grid),
            nodes: vec![
                Node {
                    g: 0.0,
                    parent: 0,
                    stamp: 0,
                };
                grid.len()
            ],
            generation: 0,
            open: KeyHeap::default(),
            heuristic: true,
        })
    }

    /// The same search without a heuristic (uniform-cost search, Dijkstra's order): an ablation
    /// that shows what the octile heuristic saves. Same paths costs, more expansions.
    ///
    /// # Errors
    /// As [`CellCostAStar::new`].
    pub fn without_heuristic(grid: &'g BitGrid, costs: &'g [f32]) -> Result<Self, PathfindError> {
        let mut planner = Self::new(grid, costs)?;
        planner.heuristic = false;
        Ok(planner)
    }

    /// The least-cost path from `start` to `goal` with its cost, or `None` when the goal cannot
    /// be reached (an answer, not an error).
    ///
    /// # Errors
    /// [`PlanError::OutOfBounds`] or [`PlanError::BlockedCell`] for a start or goal off the grid
    /// or on a blocked cell.
    pub fn plan_with_cost(
        &mut self,
        start: Cell,
        goal: Cell,
    ) -> Result<Option<CostedPath>, PlanError> {
        validate_endpoints(self.grid, start, goal)?;
        if !self.components.connected(start, goal) {
            return Ok(None);
        }
        let width = self.grid.width();
        let index = |c: Cell| c.y * width + c.x;
        let (s, t) = (index(start), index(goal));
        self.reset();
        self.closed.reset();
        let generation = self.generation << 1;
        self.nodes[s as usize] = Node {
            g: 0.0,
            parent: s,
            stamp: generation,
        };
        let h = |c: Cell, on: bool| if on { octile(c, goal) } else { 0.0 };
        self.open.push(entry(h(start, self.heuristic), 0.0, s));
        // Index offset of the neighbour in each direction (row-major), modulo 2^32.
        let offset = DIRECTIONS.map(|(dx, dy)| {
            dy.cast_unsigned()
                .wrapping_mul(width)
                .wrapping_add(dx.cast_unsigned())
        });
        let mut expanded = 0;
        while let Some(o) = self.open.pop() {
            let i = o.index;
            let node = &mut self.nodes[i as usize];
            if node.stamp & 1 != 0 {
                continue; // A stale entry of a cell already expanded.
            }
            node.stamp |= 1;
            let g = node.g;
            expanded += 1;
            if i == t {
                return Ok(Some(self.path(s, t, g, expanded)));
            }
            let c = Cell::new(i % width, i / width);
            self.closed.insert(c);
            let mut steps = self.closed.legal_open_steps(self.grid, c);
            while steps != 0 {
                let d = steps.trailing_zeros() as usize;
                steps &= steps - 1;
                let j = i.wrapping_add(offset[d]);
                let g_new = g + STEP_LENGTH[d] * f64::from(self.costs[j as usize]);
                let n = &mut self.nodes[j as usize];
                if n.stamp >> 1 == self.generation && n.g <= g_new {
                    continue;
                }
                *n = Node {
                    g: g_new,
                    parent: i,
                    stamp: generation,
                };
                let (dx, dy) = DIRECTIONS[d];
                let nc = Cell::new(c.x.wrapping_add_signed(dx), c.y.wrapping_add_signed(dy));
                self.open
                    .push(entry(g_new + h(nc, self.heuristic), g_new, j));
            }
        }
        // The open list ran dry: unreachable (the component check above normally answers first).
        Ok(None)
    }

    /// Forget the last query.
    fn reset(&mut self) {
        self.open.clear();
        if self.generation >= MAX_GENERATION {
            for n in &mut self.nodes {
                n.stamp = 0;
            }
            self.generation = 0;
        }
        self.generation += 1;
    }

    /// The path to `goal` by following parents back to `start`.
    fn path(&self, start: u32, goal: u32, cost: f64, expanded: usize) -> CostedPath {
        let width = self.grid.width();
        let cell = |i: u32| Cell::new(i % width, i / width);
        let mut cells = vec![cell(goal)];
        let mut i = goal;
        while i != start {
            i = self.nodes[i as usize].parent;
            cells.push(cell(i));
        }
        cells.reverse();
        CostedPath {
            path: GridPath {
                length: path_cost(&cells),
                cells,
                expanded,
            },
            cost,
        }
    }
}

/// An open-list entry of priority `f` (positive, so its bits order as the numbers do), ties to
/// the larger `g`.
#[inline]
fn entry(f: f64, g: f64, index: u32) -> Open {
    Open {
        f: f.to_bits(),
        tie: u32::MAX - (g as f32).to_bits(),
        index,
    }
}

/// One multiplier per cell, finite and at least 1 on every free cell.
fn check_costs(grid: &BitGrid, costs: &[f32]) -> Result<(), PathfindError> {
    if costs.len() != grid.len() {
        return Err(PathfindError::CellCostCount {
            got: costs.len(),
            width: grid.width(),
            height: grid.height(),
        });
    }
    let width = grid.width() as usize;
    for (row, values) in costs.chunks_exact(width).enumerate() {
        for (x, &v) in values.iter().enumerate() {
            // `!(v >= 1)` also catches NaN.
            if !(v >= 1.0 && v.is_finite()) {
                let c = Cell::new(x as u32, row as u32);
                if !grid.is_blocked(c) {
                    return Err(PathfindError::InvalidCellCost {
                        x: c.x,
                        y: c.y,
                        value: f64::from(v),
                    });
                }
            }
        }
    }
    Ok(())
}

impl Planner for CellCostAStar<'_> {
    /// The least-cost path (see [`CellCostAStar::plan_with_cost`]); its `length` is geometric.
    fn plan(&mut self, start: Cell, goal: Cell) -> Result<Option<GridPath>, PlanError> {
        Ok(self.plan_with_cost(start, goal)?.map(|p| p.path))
    }
}
