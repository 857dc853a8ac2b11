//! `FloorGraph`: a route to a goal on another floor, over the floors' planning grids and the
//! stairs that join them. Within a floor the walk is the grid's shortest (8-connected, no
//! corner cutting, as the planners walk); the stairs are links of known length between a cell
//! of one floor's grid and a cell of another's. The route is a shortest path over a small graph
//! (the start, the goal and the stairs' ends), each of its edges one Dijkstra search on a grid.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use slam_core::{BitGrid, Cell, InvalidSetting};

use crate::nav::NavError;
use crate::nav::travel_costs::TravelCosts;

/// A cell of one floor's grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FloorCell {
    /// The floor (an index into the grids given to [`FloorGraph::new`]).
    pub floor: usize,
    /// The cell of its grid.
    pub cell: Cell,
}

/// A flight of stairs, walkable both ways: its foot on one floor, its top on another.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StairsLink {
    /// Where it is entered on the lower floor.
    pub foot: FloorCell,
    /// Where it is left on the upper floor.
    pub top: FloorCell,
    /// The walk along it (metres).
    pub length: f64,
}

/// One part of a [`FloorRoute`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RouteLeg {
    /// A walk on one floor's grid, from a cell to another.
    Walk {
        /// The floor.
        floor: usize,
        /// Where it starts.
        from: Cell,
        /// Where it ends.
        to: Cell,
        /// Its length (metres).
        length: f64,
    },
    /// A flight of stairs (an index into [`FloorGraph::links`]), up or down.
    Stairs {
        /// Which link.
        link: usize,
        /// Whether it is climbed (from its foot to its top).
        up: bool,
    },
}

/// A route from a floor cell to another, walks and stairs in order.
#[derive(Clone, Debug, PartialEq)]
pub struct FloorRoute {
    /// Its parts, in walking order (a route on one floor is one walk).
    pub legs: Vec<RouteLeg>,
    /// Its length (metres): the walks' and the stairs'.
    pub length: f64,
}

/// The floors' planning grids and the stairs between them.
///
/// ```
/// use slam_core::{BitGrid, Cell, GridGeometry};
/// use spot_adapter::nav::{FloorCell, FloorGraph, RouteLeg, StairsLink};
///
/// let g = GridGeometry::try_new(nalgebra::Vector2::zeros(), 0.1)?;
/// let floor = BitGrid::new(20, 10)?.with_geometry(g);
/// let upstairs = BitGrid::new(20, 10)?.with_geometry(g);
/// let stairs = StairsLink {
///     foot: FloorCell { floor: 0, cell: Cell::new(15, 5) },
///     top: FloorCell { floor: 1, cell: Cell::new(15, 5) },
///     length: 5.0,
/// };
/// let graph = FloorGraph::new(vec![&floor, &upstairs], vec![stairs])?;
/// let route = graph
///     .route(
///         FloorCell { floor: 0, cell: Cell::new(5, 5) },
///         FloorCell { floor: 1, cell: Cell::new(5, 5) },
///     )?
///     .expect("the stairs join the floors");
/// assert!((route.length - (1.0 + 5.0 + 1.0)).abs() < 1e-9);
/// assert_eq!(route.legs[1], RouteLeg::Stairs { link: 0, up: true });
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug)]
pub struct FloorGraph<'a> {
    floors: Vec<&'a BitGrid>,
    links: Vec<StairsLink>,
}

/// A node of the route's graph: the start, the goal, or an end of a link.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Node {
    Start,
    Goal,
    Foot(usize),
    Top(usize),
}

impl<'a> FloorGraph<'a> {
    /// The floors' grids (floor `k` is `floors[k]`) and the stairs between them.
    ///
    /// # Errors
    /// [`NavError::NoSuchFloor`] for a link to a floor not given, [`NavError::OffFloorGrid`]
    /// for a link's end off its floor's grid, and [`NavError::InvalidConfig`] naming
    /// `StairsLink::length` for a length that is not finite and non-negative.
    pub fn new(floors: Vec<&'a BitGrid>, links: Vec<StairsLink>) -> Result<Self, NavError> {
        let graph = Self { floors, links };
        for link in &graph.links {
            graph.check(link.foot, "a stairs link's foot")?;
            graph.check(link.top, "a stairs link's top")?;
            InvalidSetting::check(
                link.length.is_finite() && link.length >= 0.0,
                "StairsLink::length",
                link.length,
                "finite and not negative",
            )?;
        }
        Ok(graph)
    }

    /// The stairs, as given.
    #[must_use]
    pub fn links(&self) -> &[StairsLink] {
        &self.links
    }

    /// The shortest route from `start` to `goal`; `None` when no walk and no stairs join them
    /// (a goal on a floor no stairs reach, or a cell cut off on its own floor).
    ///
    /// # Errors
    /// [`NavError::NoSuchFloor`] or [`NavError::OffFloorGrid`] for a start or goal not on a
    /// floor's grid.
    pub fn route(&self, start: FloorCell, goal: FloorCell) -> Result<Option<FloorRoute>, NavError> {
        self.check(start, "the start")?;
        self.check(goal, "the goal")?;
        let mut nodes = vec![(Node::Start, start), (Node::Goal, goal)];
        for (i, link) in self.links.iter().enumerate() {
            nodes.push((Node::Foot(i), link.foot));
            nodes.push((Node::Top(i), link.top));
        }
        // Walks between the nodes of each floor: one search from each node.
        let n = nodes.len();
        let mut walks: Vec<Vec<Option<f64>>> = vec![vec![None; n]; n];
        for (a, &(_, from)) in nodes.iter().enumerate() {
            let same: Vec<usize> = (0..n).filter(|&b| nodes[b].1.floor == from.floor).collect();
            let targets: Vec<Cell> = same.iter().map(|&b| nodes[b].1.cell).collect();
            let costs = TravelCosts::between(self.floors[from.floor], from.cell, &targets);
            for (&b, cost) in same.iter().zip(costs) {
                walks[a][b] = cost;
            }
        }
        // Dijkstra over the nodes: walks on a floor, and each link both ways.
        let mut best = vec![f64::INFINITY; n];
        let mut came: Vec<Option<(usize, Option<usize>)>> = vec![None; n];
        let mut heap = BinaryHeap::new();
        best[0] = 0.0;
        heap.push(Reverse((Ordered(0.0), 0usize)));
        while let Some(Reverse((Ordered(d), a))) = heap.pop() {
            if d > best[a] {
                continue;
            }
            let mut relax = |b: usize, step: f64, link: Option<usize>| {
                if d + step < best[b] {
                    best[b] = d + step;
                    came[b] = Some((a, link));
                    heap.push(Reverse((Ordered(d + step), b)));
                }
            };
            for (b, walk) in walks[a].iter().enumerate() {
                if let Some(w) = *walk
                    && b != a
                {
                    relax(b, w, None);
                }
            }
            match nodes[a].0 {
                Node::Foot(i) => relax(2 + 2 * i + 1, self.links[i].length, Some(i)),
                Node::Top(i) => relax(2 + 2 * i, self.links[i].length, Some(i)),
                Node::Start | Node::Goal => {}
            }
        }
        if !best[1].is_finite() {
            return Ok(None);
        }
        let mut legs = Vec::new();
        let mut at = 1;
        while let Some((from, link)) = came[at] {
            legs.push(match link {
                Some(i) => RouteLeg::Stairs {
                    link: i,
                    up: nodes[from].0 == Node::Foot(i),
                },
                None => RouteLeg::Walk {
                    floor: nodes[at].1.floor,
                    from: nodes[from].1.cell,
                    to: nodes[at].1.cell,
                    length: best[at] - best[from],
                },
            });
            at = from;
        }
        if legs.is_empty() {
            // The goal is the start.
            legs.push(RouteLeg::Walk {
                floor: start.floor,
                from: start.cell,
                to: goal.cell,
                length: 0.0,
            });
        }
        legs.reverse();
        Ok(Some(FloorRoute {
            legs,
            length: best[1],
        }))
    }

    /// `at` is on a floor given and on its grid.
    fn check(&self, at: FloorCell, what: &'static str) -> Result<(), NavError> {
        let Some(grid) = self.floors.get(at.floor) else {
            return Err(NavError::NoSuchFloor {
                what,
                floor: at.floor,
                floors: self.floors.len(),
            });
        };
        if at.cell.x >= grid.width() || at.cell.y >= grid.height() {
            return Err(NavError::OffFloorGrid {
                what,
                floor: at.floor,
                cell: at.cell,
            });
        }
        Ok(())
    }
}

/// A distance ordered for the heap (the distances here are finite sums of finite lengths).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Ordered(f64);

impl Eq for Ordered {}

impl PartialOrd for Ordered {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Ordered {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

#[cfg(test)]
#[path = "floor_route_tests.rs"]
mod tests;
