//! Wait or go round: when something new blocks the path and the way around is far longer (or
//! there is none), the robot stands and waits for it to move on (a person crossing, a door
//! held), but not for ever, not for what stays put, and not twice on the way to one goal.

use gridmap::PlanningGrid;
use nalgebra::Vector2;
use slam_core::{BitGrid, Cell};

use crate::nav::NavError;
use crate::nav::config::NavigatorConfig;
use crate::nav::path::{Plan, dense_path};
use crate::nav::planner::NavPlanner;

/// A periodic replan may not lead back within this distance (metres) of where an earlier path
/// to the same goal was blocked: about a box's half width plus the hard inflation.
const BLOCKAGE_RADIUS: f64 = 0.6;

/// Waiting cycles with the blocked way unchanged after which the blockage counts as still (a
/// box, not a person walking): 10 (2 s).
const STILL_BLOCKAGE_CYCLES: usize = 10;

/// The blocked stretch of the map's own path: its first and last blocked cells and how many
/// are blocked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Blockage {
    first: Cell,
    last: Cell,
    count: usize,
}

/// What the robot would wait for: the blocked stretch of the map's own path and its blocked
/// cells.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Wait {
    pub(crate) blockage: Blockage,
    pub(crate) cells: Vec<Cell>,
}

/// The waiting so far, and where paths to the current goal were blocked.
#[derive(Clone, Debug)]
pub(crate) struct DetourPolicy {
    /// Wait when the way around is this much longer than the blocked way (metres) ...
    extra: f64,
    /// ... for at most this many cycles.
    patience: usize,
    /// Cycles waited so far for the current path's blockage to clear.
    waited: usize,
    /// Which cells of the map's own path were blocked when last waiting ...
    blockage: Option<Blockage>,
    /// ... and for how many cycles in a row they stayed the same (what blocks the way does not
    /// move).
    unchanged_for: usize,
    /// The goal for which the robot already waited its patience out: it does not wait again on
    /// the way there (a box that stays would have it turn back and forth).
    waited_out_for: Option<Vector2<f64>>,
    /// Where paths to the current goal were blocked (cell centres, metres): a periodic replan
    /// that would lead back through one of them keeps the current path instead. What blocked
    /// a path seen from close by can look clear from a few metres off (the edge cells of a
    /// box are hit by fewer beams), and without this the robot turned back and forth between
    /// the way past it and the way round.
    blocked_at: Vec<Vector2<f64>>,
}

impl DetourPolicy {
    /// With `config`'s `detour_extra` and `detour_patience`.
    pub(crate) fn new(config: &NavigatorConfig) -> Self {
        Self {
            extra: config.detour_extra,
            patience: config.detour_patience,
            waited: 0,
            blockage: None,
            unchanged_for: 0,
            waited_out_for: None,
            blocked_at: Vec::new(),
        }
    }

    /// A new goal: where earlier paths were blocked no longer matters.
    pub(crate) fn new_goal(&mut self) {
        self.blocked_at.clear();
    }

    /// The path is clear this cycle: a later wait counts its patience afresh.
    pub(crate) fn path_clear(&mut self) {
        self.waited = 0;
    }

    /// Record where the path through `cells` is blocked on `grid` (its first and last blocked
    /// cells).
    pub(crate) fn remember_blockage(&mut self, grid: &BitGrid, cells: &[Cell]) {
        let first = cells.iter().find(|c| grid.is_blocked(**c)).copied();
        let last = cells.iter().rfind(|c| grid.is_blocked(**c)).copied();
        for c in first.into_iter().chain(last) {
            let at = grid.cell_center(c);
            if !self
                .blocked_at
                .iter()
                .any(|b| (b - at).norm() < BLOCKAGE_RADIUS)
            {
                self.blocked_at.push(at);
            }
        }
    }

    /// Whether the path through `cells` (on `grid`) passes within [`BLOCKAGE_RADIUS`] of a
    /// place that blocked an earlier path to the current goal.
    pub(crate) fn passes_blockage(&self, grid: &BitGrid, cells: &[Cell]) -> bool {
        cells.iter().any(|&c| {
            let at = grid.cell_center(c);
            self.blocked_at
                .iter()
                .any(|b| (b - at).norm() < BLOCKAGE_RADIUS)
        })
    }

    /// What blocks the way from `position` to `target` given `plan`, the path on the `live`
    /// planning grid (see [`DetourPolicy::worth_waiting`]); `map_only` is the planning grid of
    /// the map alone, `planner` the one to search it with and its memory there. With no way
    /// round at all, something new blocking the way is waited for again (a person met twice):
    /// only once the patience runs out is the answer `NoPath`.
    pub(crate) fn waiting_for<P: NavPlanner>(
        &self,
        live: &PlanningGrid,
        map_only: &PlanningGrid,
        planner: (&mut P, &mut P::Memory),
        position: Vector2<f64>,
        target: Vector2<f64>,
        plan: Option<&Plan>,
    ) -> Result<Option<Wait>, NavError> {
        if self.waited_out_for == Some(target) && plan.is_some() {
            return Ok(None);
        }
        let resolution = live.blocked().geometry().resolution;
        let live_length = plan.map(|p| p.path().length * resolution);
        self.worth_waiting(live, map_only, planner, position, target, live_length)
    }

    /// What blocks the way, when the live path (its length `live_length` in metres, `None`
    /// when there is none) is more than `extra` longer than the path on the map alone,
    /// which exists: something new stands on the map's path. With it the blocked cells of the
    /// map's path. `None` when there is nothing to wait for.
    fn worth_waiting<P: NavPlanner>(
        &self,
        live: &PlanningGrid,
        map_only: &PlanningGrid,
        (planner, memory): (&mut P, &mut P::Memory),
        position: Vector2<f64>,
        goal: Vector2<f64>,
        live_length: Option<f64>,
    ) -> Result<Option<Wait>, NavError> {
        let resolution = live.blocked().geometry().resolution;
        let extra = self.extra;
        // No path can be shorter than the straight line: most plans need no second search.
        if live_length.is_some_and(|l| l <= (goal - position).norm() + extra) {
            return Ok(None);
        }
        let Some(map_path) = dense_path(map_only, planner, memory, position, goal)? else {
            return Ok(None);
        };
        let map_length = map_path.length * resolution;
        if live_length.is_some_and(|l| l <= map_length + extra) {
            return Ok(None);
        }
        let map_only = &map_path.cells;
        let grid = live.blocked();
        let mut blocked = map_only
            .iter()
            .enumerate()
            .filter(|(_, c)| grid.is_blocked(**c))
            .map(|(k, _)| k);
        let Some(first) = blocked.next() else {
            // The map's path is clear on the live grid yet the planner went round: nothing new
            // stands on it to wait for.
            return Ok(None);
        };
        let (last, count) = blocked.fold((first, 1), |(_, n), k| (k, n + 1));
        let cells = map_only[first..=last]
            .iter()
            .filter(|c| grid.is_blocked(**c))
            .copied()
            .collect();
        Ok(Some(Wait {
            blockage: Blockage {
                first: map_only[first],
                last: map_only[last],
                count,
            },
            cells,
        }))
    }

    /// Wait another cycle for `blockage` on the way to `goal`? Yes while the patience lasts and
    /// it moves (or, with no `way_round`, even when it stays put). Once the answer is no, the
    /// robot goes round and does not wait again on the way to this goal.
    pub(crate) fn keeps_waiting(
        &mut self,
        blockage: Blockage,
        goal: Vector2<f64>,
        way_round: bool,
    ) -> bool {
        let unchanged = self.blockage == Some(blockage);
        self.unchanged_for = if unchanged { self.unchanged_for + 1 } else { 0 };
        self.blockage = Some(blockage);
        self.waited += 1;
        // A blockage that stays put is given up on early only when there is a way round.
        if self.waited < self.patience && (self.unchanged_for < STILL_BLOCKAGE_CYCLES || !way_round)
        {
            return true;
        }
        self.waited_out_for = Some(goal);
        false
    }

    /// Not (or no longer) waiting: the next wait starts afresh.
    pub(crate) fn stop_waiting(&mut self) {
        self.blockage = None;
        self.unchanged_for = 0;
        self.waited = 0;
    }
}

#[cfg(test)]
mod tests {
    use slam_core::GridGeometry;

    use super::*;

    fn policy(patience: usize) -> DetourPolicy {
        DetourPolicy::new(&NavigatorConfig {
            detour_patience: patience,
            ..NavigatorConfig::default()
        })
    }

    fn blockage(x: u32) -> Blockage {
        Blockage {
            first: Cell::new(x, 0),
            last: Cell::new(x + 3, 0),
            count: 4,
        }
    }

    #[test]
    fn a_moving_blockage_is_waited_for_until_the_patience_runs_out() {
        let goal = Vector2::new(5.0, 0.0);
        let mut detour = policy(30);
        // Moving (a different stretch each cycle): 29 cycles of waiting, then go round.
        for k in 0..29 {
            assert!(detour.keeps_waiting(blockage(k), goal, true), "cycle {k}");
        }
        assert!(!detour.keeps_waiting(blockage(29), goal, true));
        assert_eq!(detour.waited_out_for, Some(goal));
    }

    #[test]
    fn a_still_blockage_is_given_up_on_early_only_with_a_way_round() {
        let goal = Vector2::new(5.0, 0.0);
        let mut detour = policy(40);
        let waits = (0..40)
            .take_while(|_| detour.keeps_waiting(blockage(1), goal, true))
            .count();
        assert_eq!(waits, STILL_BLOCKAGE_CYCLES);
        let mut detour = policy(40);
        let waits = (0..40)
            .take_while(|_| detour.keeps_waiting(blockage(1), goal, false))
            .count();
        assert_eq!(waits, 39);
        detour.stop_waiting();
        assert_eq!(
            (detour.blockage, detour.unchanged_for, detour.waited),
            (None, 0, 0)
        );
    }

    #[test]
    fn a_path_near_a_remembered_blockage_passes_it() {
        // 0.1 m cells, a blocked cell at (10, 10).
        let grid = BitGrid::from_fn(40, 40, |x, y| (x, y) == (10, 10))
            .unwrap()
            .with_geometry(GridGeometry {
                origin: Vector2::zeros(),
                resolution: 0.1,
            });
        let mut detour = policy(40);
        let row = |y: u32| (0..40).map(move |x| Cell::new(x, y)).collect::<Vec<_>>();
        detour.remember_blockage(&grid, &row(10));
        assert!(detour.passes_blockage(&grid, &row(13)));
        assert!(!detour.passes_blockage(&grid, &row(17)));
        detour.new_goal();
        assert!(!detour.passes_blockage(&grid, &row(10)));
    }
}
