//! A* on a grid whose cells cost more to enter than their step length: each step costs its length
//! times the multiplier of the cell it enters (at least 1), so the octile heuristic stays
//! admissible and consistent and the first expansion of the goal is optimal.

use slam_core::{BitGrid, Cell, GridPath, PlanError, Planner, validate_endpoints};

use crate::closed_set::ClosedSet;
use crate::components::Components;
use crate::cost_ring::CostRing;
use crate::error::PathfindError;
use crate::movement::{DIRECTIONS, SQRT_2, path_cost};
use crate::open_list::{KeyHeap, Open, OpenList};
use crate::search_space::next_generation;

/// Fractional bits of the fixed-point costs at most (as [`crate::cost`]: 2^-29 cells).
const MAX_FRACTION_BITS: u32 = 29;
/// ... and at least: fewer would round the multipliers too coarsely.
const MIN_FRACTION_BITS: u32 = 16;

/// Above this largest multiplier the open list is a binary heap, below it a bucket ring (whose
/// buckets would grow too wide to be worth it).
const RING_UP_TO: f32 = 64.0;

/// A least-cost path found by [`CellCostAStar`].
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
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
    g: u64,
    parent: u32,
    /// `generation << 1 | closed`: `g` and `parent` are valid when the generation is current.
    stamp: u32,
}

/// What a [`CellCostAStar`] keeps for the next planner on the same grid
/// ([`CellCostAStar::into_memory`], [`CellCostAStar::with_memory`]): the grid's component labels
/// and the search records.
pub struct CellCostMemory {
    labelled: BitGrid,
    components: Components,
    closed: ClosedSet,
    nodes: Vec<Node>,
    generation: u32,
}

impl std::fmt::Debug for CellCostMemory {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CellCostMemory")
            .field("width", &self.labelled.width())
            .field("height", &self.labelled.height())
            .finish_non_exhaustive()
    }
}

/// A search record no query has written.
const FRESH: Node = Node {
    g: 0,
    parent: 0,
    stamp: 0,
};

/// Generations run from 1 to this value, then the stamps are cleared once.
const MAX_GENERATION: u32 = u32::MAX >> 1;

/// The open list: a ring of buckets when the multipliers are bounded (a successor's priority
/// exceeds its parent's by at most its step's cost plus its length), else a heap.
enum Queue {
    Ring(CostRing),
    Heap(KeyHeap),
}

impl Queue {
    #[inline]
    fn clear(&mut self) {
        match self {
            Self::Ring(r) => r.clear(),
            Self::Heap(h) => h.clear(),
        }
    }

    #[inline]
    fn push(&mut self, f: u64, tie: u32, index: u32) {
        match self {
            Self::Ring(r) => r.push(f, tie, index),
            Self::Heap(h) => h.push(Open { f, tie, index }),
        }
    }

    #[inline]
    fn pop(&mut self) -> Option<(u64, u32)> {
        match self {
            Self::Ring(r) => r.pop().map(|e| (e.f, e.index)),
            Self::Heap(h) => h.pop().map(|o| (o.f, o.index)),
        }
    }
}

/// Fixed-point path costs in units of `2^-bits` cells.
#[derive(Clone, Copy, Debug)]
struct Units {
    bits: u32,
    straight: u64,
    diagonal: u64,
}

impl Units {
    fn new(bits: u32) -> Self {
        let straight = 1u64 << bits;
        Self {
            bits,
            straight,
            diagonal: (SQRT_2 * straight as f64).round() as u64,
        }
    }

    /// The octile distance: the exact cost on an empty grid of unit multipliers, never above the
    /// fixed-point cost of any path (every step costs at least `straight` or `diagonal`).
    #[inline]
    fn octile(&self, a: Cell, b: Cell) -> u64 {
        let dx = a.x.abs_diff(b.x);
        let dy = a.y.abs_diff(b.y);
        let (lo, hi) = if dx < dy { (dx, dy) } else { (dy, dx) };
        u64::from(hi - lo) * self.straight + u64::from(lo) * self.diagonal
    }
}

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
/// // Diagonally up into the cheap row, along it, and straight down into the goal: one diagonal
/// // and seven straight steps into cost-1 cells, one straight step into the cost-3 goal.
/// assert!((found.cost - (10.0 + std::f64::consts::SQRT_2)).abs() < 1e-9);
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
    open: Queue,
    /// Cells queued with `f` equal to `current_f`: expanded before anything on the open list.
    same_f: Vec<u32>,
    /// `f` of the last cell taken off the open list.
    current_f: u64,
    units: Units,
    /// Whether the octile heuristic guides the search (off: Dijkstra's order, an ablation).
    heuristic: bool,
    /// The memory's copy of its grid, overwritten by [`Self::into_memory`]'s.
    labelled: Option<BitGrid>,
}

/// The grid's size and whether the heuristic guides the search; not the costs and records.
impl std::fmt::Debug for CellCostAStar<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CellCostAStar")
            .field("width", &self.grid.width())
            .field("height", &self.grid.height())
            .field("heuristic", &self.heuristic)
            .finish_non_exhaustive()
    }
}

impl<'g> CellCostAStar<'g> {
    /// A planner for `grid` with `costs`, the cost multiplier of entering each cell (row-major,
    /// `width * height` values, `costs[y * width + x]` for cell (x, y); dimensionless: a step's
    /// cost is its length in cells times the multiplier). Values on blocked cells are ignored.
    /// Labels the grid's connected components once and allocates 16 bytes of search records per
    /// cell, reused by every query.
    ///
    /// The search adds costs in fixed point, `2^-b` cells with `b` = 29 (as the other planners
    /// of this crate) unless the largest multiplier times the free cells needs fewer bits (`b`
    /// down to 16), so that no path's cost can overflow; each step's cost is rounded down to a
    /// unit, never below its length. The path found is optimal for those costs, which differ
    /// from the exact ones by less than one unit per step (`2^-29` cells, relative `2e-9`).
    ///
    /// # Errors
    /// [`PathfindError::CellCostCount`] when `costs` does not have one value per cell,
    /// [`PathfindError::InvalidCellCost`] for a free cell whose multiplier is not finite or is
    /// below 1 (a multiplier below 1 would make the octile heuristic overestimate),
    /// [`PathfindError::CellCostsTooLarge`] when the largest multiplier times the free cells
    /// exceeds `2^46 / sqrt(2)` (about 5e13).
    pub fn new(grid: &'g BitGrid, costs: &'g [f32]) -> Result<Self, PathfindError> {
        Self::build(grid, costs, None)
    }

    /// [`CellCostAStar::new`] reusing what an earlier planner kept ([`Self::into_memory`]): on
    /// the grid that planner had (compared cell by cell) the component labels are kept, and on
    /// a grid of the same size the search records' memory; only the costs are checked again.
    /// A navigator that plans again and again on one map builds the labels once per map change.
    /// The paths are those of a new planner.
    ///
    /// ```
    /// use pathfind::CellCostAStar;
    /// use slam_core::{BitGrid, Cell, Planner};
    ///
    /// let mut grid = BitGrid::new(20, 20)?;
    /// let costs = vec![1.0; 400];
    /// let mut planner = CellCostAStar::new(&grid, &costs)?;
    /// assert!(planner.plan(Cell::new(0, 0), Cell::new(19, 19))?.is_some());
    /// let memory = planner.into_memory();
    /// // A wall across the grid: the labels are made again, and the goal is out of reach.
    /// for y in 0..20 {
    ///     grid.set(Cell::new(10, y), true)?;
    /// }
    /// let mut planner = CellCostAStar::with_memory(&grid, &costs, memory)?;
    /// assert_eq!(planner.plan(Cell::new(0, 0), Cell::new(19, 19))?, None);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// As [`CellCostAStar::new`].
    pub fn with_memory(
        grid: &'g BitGrid,
        costs: &'g [f32],
        memory: CellCostMemory,
    ) -> Result<Self, PathfindError> {
        Self::build(grid, costs, Some(memory))
    }

    /// What a later planner on the same grid can reuse ([`Self::with_memory`]).
    #[must_use]
    pub fn into_memory(self) -> CellCostMemory {
        // A copy, so that a planner built from this memory can tell whether its grid is the one
        // the labels are of (in the memory's own copy, when it came with one).
        let labelled = match self.labelled {
            Some(mut labelled) => {
                labelled.clone_from(self.grid);
                labelled
            }
            None => self.grid.clone(),
        };
        CellCostMemory {
            labelled,
            components: self.components,
            closed: self.closed,
            nodes: self.nodes,
            generation: self.generation,
        }
    }

    fn build(
        grid: &'g BitGrid,
        costs: &'g [f32],
        memory: Option<CellCostMemory>,
    ) -> Result<Self, PathfindError> {
        let largest = check_costs(grid, costs)?;
        // The costliest simple path visits every free cell once: keep it and its priority (g
        // plus a heuristic of at most the grid's octile diameter) below 2^62.
        let free = (grid.len() - grid.count_blocked()) as f64;
        let worst = SQRT_2
            * (f64::from(largest) * (free + 1.0)
                + f64::from(grid.width())
                + f64::from(grid.height()));
        let room = (62.0 - worst.log2()).floor();
        if room < f64::from(MIN_FRACTION_BITS) {
            return Err(PathfindError::CellCostsTooLarge {
                largest: f64::from(largest),
                cells: grid.len() - grid.count_blocked(),
            });
        }
        let units = Units::new((room as u32).min(MAX_FRACTION_BITS));
        let open = if largest <= RING_UP_TO {
            // A step costs at most sqrt(2) times the largest multiplier (in units, rounded down)
            // and lowers the octile heuristic by at most one diagonal.
            let window = (units.diagonal as f64 * f64::from(largest)) as u64 + units.diagonal + 1;
            Queue::Ring(CostRing::new(window, units.bits.saturating_sub(6)))
        } else {
            Queue::Heap(KeyHeap::default())
        };
        // A memory of another grid lends its allocations: the same as fresh records, with no
        // new memory while the grid keeps its size, and otherwise grown in place when it can
        // (the navigator's grids grow as the map does).
        let (components, closed, nodes, generation, labelled) = match memory {
            Some(mut m) => {
                if (m.labelled.width(), m.labelled.height()) == (grid.width(), grid.height()) {
                    if m.labelled != *grid {
                        m.components.relabel(grid);
                    }
                } else {
                    m.components.relabel(grid);
                    m.closed.renew(grid);
                    m.nodes.clear();
                    m.nodes.resize(grid.len(), FRESH);
                    m.generation = 0;
                }
                (
                    m.components,
                    m.closed,
                    m.nodes,
                    m.generation,
                    Some(m.labelled),
                )
            }
            None => (
                Components::new(grid),
                ClosedSet::new(grid),
                vec![FRESH; grid.len()],
                0,
                None,
            ),
        };
        Ok(Self {
            grid,
            costs,
            components,
            closed,
            nodes,
            generation,
            open,
            same_f: Vec::new(),
            current_f: 0,
            units,
            heuristic: true,
            labelled,
        })
    }

    /// The same search without a heuristic (uniform-cost search, Dijkstra's order): an ablation
    /// that shows what the octile heuristic saves. Same path costs, more expansions.
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
        let (s, t) = (start.y * width + start.x, goal.y * width + goal.x);
        self.reset();
        self.closed.reset();
        let generation = self.generation << 1;
        self.nodes[s as usize] = Node {
            g: 0,
            parent: s,
            stamp: generation,
        };
        let (units, heuristic) = (self.units, self.heuristic);
        let h = |c: Cell| if heuristic { units.octile(c, goal) } else { 0 };
        self.open.push(h(start), u32::MAX, s);
        // Index offset of the neighbour in each direction (row-major), modulo 2^32.
        let offset = DIRECTIONS.map(|(dx, dy)| {
            dy.cast_unsigned()
                .wrapping_mul(width)
                .wrapping_add(dx.cast_unsigned())
        });
        let step = [units.straight as f64, units.diagonal as f64];
        let mut expanded = 0;
        while let Some((i, g)) = self.pop() {
            expanded += 1;
            if i == t {
                return Ok(Some(self.path(s, t, expanded)));
            }
            let c = Cell::new(i % width, i / width);
            self.closed.insert(c);
            let mut steps = self.closed.legal_open_steps(self.grid, c);
            while steps != 0 {
                let d = steps.trailing_zeros() as usize;
                steps &= steps - 1;
                let j = i.wrapping_add(offset[d]);
                // Rounded down, but never below the step's length (multipliers are at least 1).
                let cost = (step[d / 4] * f64::from(self.costs[j as usize])) as u64;
                let g_new = g + cost;
                let n = &mut self.nodes[j as usize];
                if n.stamp >> 1 == self.generation && (n.g <= g_new || n.stamp & 1 != 0) {
                    continue;
                }
                *n = Node {
                    g: g_new,
                    parent: i,
                    stamp: generation,
                };
                let (dx, dy) = DIRECTIONS[d];
                let f = g_new
                    + h(Cell::new(
                        c.x.wrapping_add_signed(dx),
                        c.y.wrapping_add_signed(dy),
                    ));
                // `f` never decreases along the expansions (consistent heuristic, exact integer
                // costs), so `f <= current_f` means equal: expand it next, off the open list.
                if f <= self.current_f {
                    self.same_f.push(j);
                } else {
                    // Among equal `f`, the larger `g` first.
                    let tie = u32::MAX - u32::try_from(g_new >> units.bits).unwrap_or(u32::MAX);
                    self.open.push(f, tie, j);
                }
            }
        }
        // The open list ran dry: unreachable (the component check above normally answers first).
        Ok(None)
    }

    /// The next cell to expand (not expanded before in this query), marked expanded, with its
    /// cost.
    #[inline]
    fn pop(&mut self) -> Option<(u32, u64)> {
        while let Some(i) = self.same_f.pop() {
            let n = &mut self.nodes[i as usize];
            if n.stamp & 1 == 0 {
                n.stamp |= 1;
                return Some((i, n.g));
            }
        }
        while let Some((f, i)) = self.open.pop() {
            let n = &mut self.nodes[i as usize];
            if n.stamp & 1 == 0 {
                n.stamp |= 1;
                self.current_f = f;
                return Some((i, n.g));
            }
        }
        None
    }

    /// Forget the last query.
    fn reset(&mut self) {
        self.open.clear();
        self.same_f.clear();
        self.current_f = 0;
        next_generation(&mut self.generation, MAX_GENERATION, &mut self.nodes, |n| {
            n.stamp = 0;
        });
    }

    /// The path to `goal` by following parents back to `start`, with its cost summed in `f64`.
    fn path(&self, start: u32, goal: u32, expanded: usize) -> CostedPath {
        let width = self.grid.width();
        let cell = |i: u32| Cell::new(i % width, i / width);
        let mut cells = vec![cell(goal)];
        let mut i = goal;
        while i != start {
            i = self.nodes[i as usize].parent;
            cells.push(cell(i));
        }
        cells.reverse();
        let cost = cells
            .windows(2)
            .map(|w| {
                let diagonal = w[0].x != w[1].x && w[0].y != w[1].y;
                let m = f64::from(self.costs[(w[1].y * width + w[1].x) as usize]);
                if diagonal { SQRT_2 * m } else { m }
            })
            // From +0.0: `sum()` of no steps is -0.0.
            .fold(0.0, |a, b| a + b);
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

/// One multiplier per cell, finite and at least 1 on every free cell; returns the largest on a
/// free cell.
fn check_costs(grid: &BitGrid, costs: &[f32]) -> Result<f32, PathfindError> {
    if costs.len() != grid.len() {
        return Err(PathfindError::CellCostCount {
            got: costs.len(),
            width: grid.width(),
            height: grid.height(),
        });
    }
    let width = grid.width() as usize;
    let mut largest = 1.0f32;
    for (row, values) in costs.chunks_exact(width).enumerate() {
        for (x, &v) in values.iter().enumerate() {
            // `!(v >= 1)` also catches NaN.
            if !(v >= 1.0 && v.is_finite()) || v > largest {
                let c = Cell::new(x as u32, row as u32);
                if grid.is_blocked(c) {
                    continue;
                }
                if v > largest && v.is_finite() {
                    largest = v;
                } else {
                    return Err(PathfindError::InvalidCellCost {
                        x: c.x,
                        y: c.y,
                        value: f64::from(v),
                    });
                }
            }
        }
    }
    Ok(largest)
}

impl Planner for CellCostAStar<'_> {
    /// The least-cost path (see [`CellCostAStar::plan_with_cost`]); its `length` is geometric.
    fn plan(&mut self, start: Cell, goal: Cell) -> Result<Option<GridPath>, PlanError> {
        Ok(self.plan_with_cost(start, goal)?.map(|p| p.path))
    }
}
