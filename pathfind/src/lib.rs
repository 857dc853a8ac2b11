//! # pathfind
//!
//! Shortest paths on spot-nav's bit-packed occupancy grid ([`slam_core::BitGrid`]) under the
//! Moving AI movement model: 8-connected, diagonal cost sqrt(2), no corner cutting.
//!
//! - [`Dijkstra`] and [`AStar`] (octile heuristic): the references.
//! - [`JumpPointSearch`]: online JPS (Harabor & Grastien, AAAI 2011) with pruning rules derived
//!   for no corner cutting; straight jumps scan 64 cells per word (Harabor & Grastien, ICAPS
//!   2014), or one cell at a time with [`JumpPointSearch::with_cell_scans`].
//! - [`JumpPointSearchPlus`]: JPS+ (Harabor & Grastien, ICAPS 2014), the same search with jump
//!   distances precomputed per grid, O(1) per jump.
//! - [`CellCostAStar`]: A* on per-cell cost multipliers (each at least 1, so the octile heuristic
//!   stays admissible): least-cost paths for a clearance cost from a distance field, the
//!   thesis' future work f = g + h + o. With every multiplier 1 it returns `AStar`'s lengths.
//! - [`filter_path`]: the thesis' path filter, keeping only the waypoints a straight
//!   collision-free segment cannot skip ([`line_of_sight`] walks every touched cell).
//! - [`movingai`]: readers for the Moving AI `.map` and `.scen` benchmark files.
//!
//! Every planner labels the grid's connected components at construction, so an unreachable goal
//! is answered without a search. That answer is `Ok(None)`, not an error:
//! [`Planner::plan`](slam_core::Planner::plan) fails only for a start or goal off the grid or on
//! a blocked cell ([`PlanError`](slam_core::PlanError)).
//!
//! ```
//! use pathfind::{AStar, JumpPointSearchPlus, filter_path};
//! use slam_core::{BitGrid, Cell, Planner};
//!
//! // A 20 x 10 room with a wall that has a gap at the top.
//! let grid = BitGrid::from_fn(20, 10, |x, y| x == 10 && y < 8)?;
//! let (start, goal) = (Cell::new(2, 2), Cell::new(17, 2));
//! let mut jps = JumpPointSearchPlus::new(&grid)?;
//! let path = jps.plan(start, goal)?.expect("the gap joins the two halves");
//! let reference = AStar::new(&grid).plan(start, goal)?.expect("the same answer");
//! assert!((path.length - reference.length).abs() < 1e-9);
//! let filtered = filter_path(&grid, &path);
//! assert!(filtered.waypoints.len() <= 4);
//! // A wall without a gap: the goal is unreachable, an answer and not an error.
//! let walled = BitGrid::from_fn(20, 10, |x, _| x == 10)?;
//! assert_eq!(AStar::new(&walled).plan(start, goal)?, None);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! When not to use it: for any-angle optimal paths (Theta*, Anya) these planners give
//! grid-optimal paths only; the filter shortens them but does not make them any-angle optimal.
//! Per-cell costs are for [`CellCostAStar`] alone (the jump-point planners search binary grids),
//! and costs below the step length (multipliers under 1) are not supported.

mod astar;
mod best_first;
mod block_scan;
mod bucket_ring;
mod cell_cost_astar;
mod closed_set;
mod components;
mod cost;
mod cost_ring;
mod dijkstra;
mod error;
mod jps;
mod jps_plus;
mod jump_search;
mod jump_tables;
mod line_of_sight;
pub mod movement;
pub mod movingai;
mod open_list;
mod path_filter;
mod search_space;

pub use astar::AStar;
pub use best_first::BestFirstMemory;
pub use cell_cost_astar::{CellCostAStar, CellCostMemory, CostedPath};
pub use components::Components;
pub use dijkstra::Dijkstra;
pub use error::PathfindError;
pub use jps::{JumpPointSearch, JumpPointSearchMemory};
pub use jps_plus::JumpPointSearchPlus;
pub use jump_tables::MAX_JUMP_TABLE_CELLS;
pub use line_of_sight::{line_of_sight, supercover_cells};
pub use path_filter::{FilteredPath, filter_path};
