//! `Explorer`: picks the next frontier to walk to on the growing map, and remembers the ones it
//! gave up.

use gridmap::{CellState, OccupancyGrid, PlanningGrid};
use nalgebra::Vector2;
use pathfind::line_of_sight;
use slam_core::{BitGrid, Cell};

use crate::nav::NavError;
use crate::nav::explorer_config::{ExplorerConfig, FrontierChoice};
use crate::nav::frontier::{Frontier, find_frontiers};
use crate::nav::frontier_tour::{FrontierTour, TourCosts};
use crate::nav::travel_costs::TravelCosts;

/// A frontier the explorer could walk to.
#[derive(Clone, Debug, PartialEq)]
pub struct FrontierGoal {
    /// Where the robot would stand (metres, map frame): the reachable cell nearest the
    /// frontier's middle, or when none is within reach of it, the reachable cell nearest the
    /// frontier.
    pub goal: Vector2<f64>,
    /// The frontier.
    pub frontier: Frontier,
    /// The walk there (metres, on the planning grid).
    pub cost: f64,
    /// Unknown area within sensor range of the frontier's middle (square metres).
    pub gain: f64,
}

/// Why a frontier was given up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum GiveUpReason {
    /// The navigator found no path to its goal on the map with the live obstacles.
    NoPath,
    /// The robot made no progress toward it though it tried to get free.
    Blocked,
    /// Localisation failed on the way.
    Lost,
    /// The robot stood at its goal and the frontier was still there: what lies behind it
    /// cannot be seen from where the robot can stand.
    StillUnknownFromGoal,
}

impl GiveUpReason {
    /// A short name for reports: `no_path`, `blocked`, `lost`, `still_unknown_from_goal`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::NoPath => "no_path",
            Self::Blocked => "blocked",
            Self::Lost => "lost",
            Self::StillUnknownFromGoal => "still_unknown_from_goal",
        }
    }
}

/// A frontier goal given up, and why.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GivenUpFrontier {
    /// The goal it was walked to (metres, map frame).
    pub goal: Vector2<f64>,
    /// Why it was given up.
    pub reason: GiveUpReason,
}

/// What the explorer saw on one map and what it picked.
#[derive(Clone, Debug, PartialEq)]
pub struct FrontierDecision {
    /// The frontier to walk to; `None` when no reachable frontier is left (exploration done).
    pub chosen: Option<FrontierGoal>,
    /// Frontiers with a goal the robot can reach, not given up (the chosen one included).
    pub reachable: usize,
    /// Frontiers with no reachable cell within [`ExplorerConfig::goal_reach`].
    pub unreachable: Vec<Frontier>,
    /// Frontiers whose goal lies where one was given up.
    pub given_up: usize,
}

/// Picks frontiers (known-free cells next to unknown ones) to explore by
/// [`ExplorerConfig::choice`]: [`FrontierChoice::NearestRevealing`] (the default) takes the
/// nearest that would reveal enough to be worth a walk, [`FrontierChoice::InformationGain`]
/// weighs what a frontier would reveal against the walk to it,
/// [`FrontierChoice::GreedyNearestFrontier`] takes the nearest, [`FrontierChoice::Tour`] the
/// first of the shortest walk through them all.
///
/// It keeps no map of its own: each [`Explorer::decide`] looks at the occupancy grid and the
/// planning grid as they are (the map grows and is re-rendered when a loop closes), with one
/// Dijkstra search from the robot for the walks to every frontier (and, for the tour, one from
/// each frontier goal for the walks between them).
#[derive(Clone, Debug)]
pub struct Explorer {
    config: ExplorerConfig,
    given_up: Vec<GivenUpFrontier>,
    /// Per give-up: the decision from which it lapses (a first `NoPath`), or `None` (for good).
    lapses_at: Vec<Option<usize>>,
    /// Decisions made.
    decisions: usize,
    /// The goal of the last decision (metres, map frame), kept by [`FrontierChoice::Tour`].
    heading_for: Option<Vector2<f64>>,
}

impl Explorer {
    /// An explorer with `config`.
    ///
    /// # Errors
    /// [`NavError::InvalidConfig`] naming the first bad setting.
    pub fn new(config: ExplorerConfig) -> Result<Self, NavError> {
        config.validate()?;
        Ok(Self {
            config,
            given_up: Vec::new(),
            lapses_at: Vec::new(),
            decisions: 0,
            heading_for: None,
        })
    }

    /// The next frontier on `occupancy` for a robot at `position` (metres, map frame),
    /// walking on `blocked` (the planning grid over `occupancy`: unknown cells and the hard
    /// inflation blocked). The tour rule remembers the goal it picked.
    #[must_use]
    pub fn decide(
        &mut self,
        occupancy: &OccupancyGrid,
        planning: &PlanningGrid,
        position: Vector2<f64>,
    ) -> FrontierDecision {
        self.decisions += 1;
        let decision = self.choose(occupancy, planning, position);
        if decision.chosen.is_some() || !self.expire_pending_lapses() {
            return decision;
        }
        // Nothing else left: a frontier given up for a first `NoPath` is tried again now, not
        // left behind when the exploration ends before its lapse came.
        self.choose(occupancy, planning, position)
    }

    /// [`Explorer::decide`]'s choice, on the give-ups as they stand.
    fn choose(
        &mut self,
        occupancy: &OccupancyGrid,
        planning: &PlanningGrid,
        position: Vector2<f64>,
    ) -> FrontierDecision {
        let blocked = planning.blocked();
        let frontiers = find_frontiers(occupancy, self.config.min_frontier_cells);
        let start = nearest_free(blocked, position, self.config.goal_reach);
        let costs = start.map(|s| TravelCosts::from_start(blocked, s));
        let mut decision = FrontierDecision {
            chosen: None,
            reachable: 0,
            unreachable: Vec::new(),
            given_up: 0,
        };
        let mut best: Option<((f64, f64), FrontierGoal)> = None;
        let mut candidates = Vec::new();
        let mut goal_cells = Vec::new();
        for frontier in frontiers {
            let Some((goal_cell, cost)) = costs
                .as_ref()
                .and_then(|c| self.goal_of(occupancy, blocked, c, &frontier))
            else {
                decision.unreachable.push(frontier);
                continue;
            };
            let goal = blocked.geometry().cell_center(goal_cell);
            if self.is_given_up(goal) {
                decision.given_up += 1;
                continue;
            }
            decision.reachable += 1;
            goal_cells.push(goal_cell);
            candidates.push(FrontierGoal {
                goal,
                frontier,
                cost,
                gain: f64::NAN,
            });
        }
        let nearest = candidates
            .iter()
            .map(|c| c.cost)
            .fold(f64::INFINITY, f64::min);
        // The gain (a few thousand cells along rays) only where it can decide: within the
        // detour of the information-gain rule; the chosen frontier's below for the others.
        if let FrontierChoice::InformationGain { detour } = self.config.choice {
            for c in &mut candidates {
                if c.cost <= nearest + detour {
                    c.gain = self.gain(occupancy, c.frontier.middle);
                }
            }
        }
        let score = |c: &FrontierGoal| match self.config.choice {
            FrontierChoice::InformationGain { detour } => {
                if c.cost <= nearest + detour {
                    // Within the detour: the least revealing first, the shorter walk on a tie.
                    (-c.gain, -c.cost)
                } else {
                    (f64::NEG_INFINITY, -c.cost)
                }
            }
            FrontierChoice::GreedyNearestFrontier
            | FrontierChoice::Tour { .. }
            | FrontierChoice::NearestRevealing { .. } => (0.0, -c.cost),
        };
        if let FrontierChoice::NearestRevealing { min_gain } = self.config.choice {
            // Nearest first, the gain (rays) only until one reveals enough.
            candidates.sort_by(|a, b| a.cost.total_cmp(&b.cost));
            decision.chosen = candidates.into_iter().find_map(|mut c| {
                c.gain = self.gain(occupancy, c.frontier.middle);
                (c.gain >= min_gain).then_some(c)
            });
            return decision;
        }
        if let FrontierChoice::Tour { keep_margin } = self.config.choice
            && candidates.len() > 1
        {
            // The frontier walked to shrinks as it is seen: its goal moves, a little.
            let kept = self.heading_for.and_then(|h| {
                candidates
                    .iter()
                    .position(|c| (c.goal - h).norm() <= KEPT_GOAL_MOVES)
            });
            let first = tour_first(blocked, &candidates, &goal_cells, kept, keep_margin);
            let mut chosen = candidates.swap_remove(first);
            chosen.gain = self.gain(occupancy, chosen.frontier.middle);
            self.heading_for = Some(chosen.goal);
            decision.chosen = Some(chosen);
            return decision;
        }
        for c in candidates {
            let s = score(&c);
            if best.as_ref().is_none_or(|(b, _)| s > *b) {
                best = Some((s, c));
            }
        }
        decision.chosen = best.map(|(_, mut g)| {
            if g.gain.is_nan() {
                g.gain = self.gain(occupancy, g.frontier.middle);
            }
            g
        });
        decision
    }

    /// Give up the frontier whose goal is `goal` (metres, map frame): frontiers with a goal
    /// within [`ExplorerConfig::give_up_radius`] of it are not picked again.
    pub fn give_up(&mut self, goal: Vector2<f64>, reason: GiveUpReason) {
        // A first `NoPath` lapses after a while: the map it was planned on has grown since (a
        // gap seen closed from one side can be open from the other, a wall's inflation seen
        // early narrower than it first looked).
        let again = self.given_up.iter().any(|g| {
            g.reason == GiveUpReason::NoPath && (g.goal - goal).norm() <= self.config.give_up_radius
        });
        let lapses = reason == GiveUpReason::NoPath && !again;
        self.given_up.push(GivenUpFrontier { goal, reason });
        self.lapses_at
            .push(lapses.then_some(self.decisions + NO_PATH_LAPSES_AFTER));
    }

    /// The frontiers given up so far, in order.
    #[must_use]
    pub fn given_up(&self) -> &[GivenUpFrontier] {
        &self.given_up
    }

    /// Its settings.
    #[must_use]
    pub fn config(&self) -> &ExplorerConfig {
        &self.config
    }

    /// Lets every first `NoPath` that has not lapsed yet lapse now; whether there was one.
    fn expire_pending_lapses(&mut self) -> bool {
        let mut any = false;
        for at in self.lapses_at.iter_mut().flatten() {
            if *at > self.decisions {
                *at = self.decisions;
                any = true;
            }
        }
        any
    }

    /// Whether a frontier with its goal at `goal` was given up, and not for a first `NoPath`
    /// [`NO_PATH_LAPSES_AFTER`] decisions ago or more.
    fn is_given_up(&self, goal: Vector2<f64>) -> bool {
        self.given_up
            .iter()
            .zip(&self.lapses_at)
            .any(|(g, &lapses_at)| {
                (g.goal - goal).norm() <= self.config.give_up_radius
                    && lapses_at.is_none_or(|at| self.decisions < at)
            })
    }

    /// The reachable cell nearest the frontier's middle within the goal reach (ties: the
    /// shorter walk), and the walk there; when none is, the reachable cell nearest any of its
    /// cells. A long frontier (a corridor's side seen from its far end) can have its middle on a
    /// strip of free cells the inflation cuts off while its ends lie by the walkable floor:
    /// walking to an end shows more of it, and the rest is decided again. (A goal kept 0.2 m
    /// inside the free space, away from the inflation's edge, was blocked less often by the
    /// wall found beyond, but often could not see its frontier: more walks and more walking.)
    fn goal_of(
        &self,
        occupancy: &OccupancyGrid,
        blocked: &BitGrid,
        costs: &TravelCosts,
        frontier: &Frontier,
    ) -> Option<(Cell, f64)> {
        let r = (self.config.goal_reach / blocked.geometry().resolution).ceil() as i64;
        // A goal that sees the frontier: the nearest reachable cell behind a wall from it (a
        // strip of free cells seen through a door, running along the far side of a wall) shows
        // nothing of it when the robot stands there.
        if let Some((_, cost, cell)) = nearest_reachable(costs, frontier.middle, r, occupancy) {
            return Some((cell, cost));
        }
        // Every few cells of the frontier: discs half a reach apart cover what every cell's
        // would, at a fraction of the lookups.
        let stride = usize::try_from(r / 2).unwrap_or(1).max(1);
        frontier
            .cells
            .iter()
            .step_by(stride)
            .filter_map(|&c| nearest_reachable(costs, c, r, occupancy))
            .min_by(|a, b| {
                (a.0, a.1)
                    .partial_cmp(&(b.0, b.1))
                    .unwrap_or(std::cmp::Ordering::Equal)
            })
            .map(|(_, cost, cell)| (cell, cost))
    }

    /// Unknown area (square metres) a sensor at `middle` would see within sensor range: the
    /// unknown cells along rays every 2 degrees, each ray stopped by the first occupied cell
    /// (an unknown room behind a wall is not what this frontier reveals).
    fn gain(&self, occupancy: &OccupancyGrid, middle: Cell) -> f64 {
        let resolution = occupancy.geometry().resolution;
        let r = (self.config.sensor_range / resolution).round() as i64;
        let side = (2 * r + 1) as usize;
        let mut counted = vec![false; side * side];
        let mut unknown = 0usize;
        let (mx, my) = (i64::from(middle.x), i64::from(middle.y));
        for k in 0..180 {
            let angle = f64::from(k) * std::f64::consts::PI / 90.0;
            let (dx, dy) = (angle.cos(), angle.sin());
            // Half-cell steps: no cell on the ray is skipped.
            for step in 1..=2 * r {
                let t = 0.5 * step as f64;
                let (ox, oy) = ((dx * t).round() as i64, (dy * t).round() as i64);
                let (Ok(x), Ok(y)) = (u32::try_from(mx + ox), u32::try_from(my + oy)) else {
                    break;
                };
                let state = occupancy.state(Cell::new(x, y));
                if state == CellState::Occupied {
                    break;
                }
                let i = (oy + r) as usize * side + (ox + r) as usize;
                if state == CellState::Unknown && !counted[i] {
                    counted[i] = true;
                    unknown += 1;
                }
            }
        }
        unknown as f64 * resolution * resolution
    }
}

/// The reachable cell nearest `centre` within `r` cells (ties: the shorter walk) with no
/// occupied cell of `occupancy` touched by the segment between them, with its squared distance in
/// cells and the walk there.
fn nearest_reachable(
    costs: &TravelCosts,
    centre: Cell,
    r: i64,
    occupancy: &OccupancyGrid,
) -> Option<(i64, f64, Cell)> {
    let r2 = r * r;
    let mut best: Option<(i64, f64, Cell)> = None;
    for dy in -r..=r {
        for dx in -r..=r {
            let d2 = dx * dx + dy * dy;
            if d2 > r2 {
                continue;
            }
            let (x, y) = (i64::from(centre.x) + dx, i64::from(centre.y) + dy);
            let (Ok(x), Ok(y)) = (u32::try_from(x), u32::try_from(y)) else {
                continue;
            };
            let cell = Cell::new(x, y);
            if let Some(cost) = costs.to(cell)
                && best
                    .as_ref()
                    .is_none_or(|&(bd, bc, _)| (d2, cost) < (bd, bc))
                && line_of_sight(occupancy.occupied(), cell, centre)
            {
                best = Some((d2, cost, cell));
            }
        }
    }
    best
}

/// Decisions after which a frontier given up for a first `NoPath` may be tried again (on the
/// small buildings, about 25 m of walk).
const NO_PATH_LAPSES_AFTER: usize = 20;

/// How far (metres) the goal of the frontier walked to may move between decisions and still be
/// taken for the same frontier: a frontier seen from nearer shrinks, and its middle moves.
const KEPT_GOAL_MOVES: f64 = 1.0;

/// The index in `candidates` of the first goal of the shortest open tour from the robot through
/// all of them (goals at `goal_cells`), the walks between goals by one Dijkstra search from each
/// (stopped once it has reached the others);
/// `kept` instead, when the shortest tour starting there is at most `keep_margin` metres longer.
fn tour_first(
    blocked: &BitGrid,
    candidates: &[FrontierGoal],
    goal_cells: &[Cell],
    kept: Option<usize>,
    keep_margin: f64,
) -> usize {
    let from_goal: Vec<Vec<f64>> = goal_cells
        .iter()
        .map(|&from| {
            TravelCosts::between(blocked, from, goal_cells)
                .into_iter()
                .map(|walk| walk.unwrap_or(f64::INFINITY))
                .collect()
        })
        .collect();
    let costs = TourCosts::new(candidates.iter().map(|c| c.cost).collect(), |i, j| {
        from_goal[i][j]
    });
    let best = FrontierTour::plan(&costs);
    let first = best.order.first().copied().unwrap_or(0);
    let Some(k) = kept.filter(|&k| k != first) else {
        return first;
    };
    let from_kept = TourCosts::new(
        candidates
            .iter()
            .enumerate()
            .map(|(j, c)| if j == k { c.cost } else { f64::INFINITY })
            .collect(),
        |i, j| from_goal[i][j],
    );
    if FrontierTour::plan(&from_kept).length <= best.length + keep_margin {
        k
    } else {
        first
    }
}

/// The free cell of `blocked` nearest `position` within `reach` metres: the robot's own cell,
/// or the nearest one outside the hard inflation when it stands inside it (close to a wall).
fn nearest_free(blocked: &BitGrid, position: Vector2<f64>, reach: f64) -> Option<Cell> {
    let geometry = blocked.geometry();
    let (cx, cy) = geometry.cell_coords(position);
    let r = (reach / geometry.resolution).ceil() as i64;
    let mut best: Option<(i64, Cell)> = None;
    for dy in -r..=r {
        for dx in -r..=r {
            let (x, y) = (cx + dx, cy + dy);
            let d2 = dx * dx + dy * dy;
            if blocked.is_free_signed(x, y) && best.is_none_or(|(bd, _)| d2 < bd) {
                best = Some((d2, Cell::new(x as u32, y as u32)));
            }
        }
    }
    best.map(|(_, c)| c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use gridmap::PlanningGridConfig;
    use slam_core::GridGeometry;

    /// A corridor 4 m long and 1.9 m wide, walled on three sides and open to the east (a
    /// frontier of 19 cells), and a patch of floor seen far off beyond unknown space (a
    /// frontier no walk reaches).
    fn corridor_and_patch() -> (OccupancyGrid, PlanningGrid) {
        let geometry = GridGeometry::try_new(Vector2::zeros(), 0.1).unwrap();
        let mut g = OccupancyGrid::new(70, 21, geometry, CellState::Unknown).unwrap();
        for y in 0..=20 {
            for x in 0..40 {
                let wall = x == 0 || y == 0 || y == 20;
                let state = if wall {
                    CellState::Occupied
                } else {
                    CellState::Free
                };
                g.set(Cell::new(x, y), state).unwrap();
            }
        }
        for y in 5..10 {
            for x in 60..65 {
                g.set(Cell::new(x, y), CellState::Free).unwrap();
            }
        }
        let planning = PlanningGrid::new(&g, PlanningGridConfig::default()).unwrap();
        (g, planning)
    }

    #[test]
    fn the_reachable_frontier_is_chosen_and_the_other_reported_unreachable() {
        let (g, planning) = corridor_and_patch();
        for choice in [
            FrontierChoice::default(),
            FrontierChoice::GreedyNearestFrontier,
            FrontierChoice::Tour { keep_margin: 2.0 },
            FrontierChoice::NearestRevealing { min_gain: 1.0 },
        ] {
            let mut explorer = Explorer::new(ExplorerConfig {
                choice,
                ..ExplorerConfig::default()
            })
            .unwrap();
            let decision = explorer.decide(&g, &planning, Vector2::new(1.0, 1.0));
            let chosen = decision.chosen.unwrap();
            assert_eq!(chosen.frontier.size(), 19);
            // The goal: the reachable cell nearest the frontier's middle (39, 10), beyond the
            // 0.3 m inflation of the unknown space east of it.
            assert!(
                (chosen.goal - Vector2::new(3.65, 1.05)).norm() < 1e-9,
                "{chosen:?}"
            );
            // Straight east from the robot's cell (10, 10) to (36, 10).
            assert!((chosen.cost - 2.6).abs() < 1e-9, "{}", chosen.cost);
            assert!(chosen.gain > 0.0);
            assert_eq!(decision.reachable, 1);
            assert_eq!(decision.unreachable.len(), 1);
            assert_eq!(decision.unreachable[0].size(), 16, "the patch's rim");
        }
    }

    /// A walled room 2 m square with a gap in its east wall, and through the gap a strip of
    /// free cells 0.3 m wide and 4 m long (a corridor seen down its length from the room): the
    /// strip's rim is one frontier whose middle lies 2 m out on cells the inflation blocks, more
    /// than the goal reach from any reachable cell, while its near end is within reach.
    #[test]
    fn a_frontier_whose_middle_is_cut_off_is_reached_at_its_end() {
        let geometry = GridGeometry::try_new(Vector2::zeros(), 0.1).unwrap();
        let mut g = OccupancyGrid::new(70, 25, geometry, CellState::Unknown).unwrap();
        for y in 0..=21 {
            for x in 0..=60 {
                let wall = (x <= 21 && (y == 0 || y == 21))
                    || x == 0
                    || (x == 21 && !(9..=11).contains(&y));
                let state = if wall {
                    CellState::Occupied
                } else if x < 21 || (9..=11).contains(&y) {
                    CellState::Free
                } else {
                    continue;
                };
                g.set(Cell::new(x, y), state).unwrap();
            }
        }
        let planning = PlanningGrid::new(&g, PlanningGridConfig::default()).unwrap();
        let blocked = planning.blocked();
        let reach = ExplorerConfig::default().goal_reach;
        let mut explorer = Explorer::new(ExplorerConfig::default()).unwrap();
        let decision = explorer.decide(&g, &planning, Vector2::new(1.0, 1.0));
        let chosen = decision.chosen.unwrap();
        assert!(
            decision.unreachable.is_empty(),
            "{:?}",
            decision.unreachable
        );
        assert!(chosen.frontier.size() > 70, "{chosen:?}");
        // The oracle, by brute force over the grid: no cell the robot can reach lies within
        // the goal reach of the frontier's middle, so the old rule found it unreachable ...
        let costs =
            TravelCosts::from_start(blocked, blocked.cell_at(Vector2::new(1.0, 1.0)).unwrap());
        let middle = geometry.cell_center(chosen.frontier.middle);
        let mut reachable = Vec::new();
        for y in 0..blocked.height() {
            for x in 0..blocked.width() {
                if costs.to(Cell::new(x, y)).is_some() {
                    reachable.push(geometry.cell_center(Cell::new(x, y)));
                }
            }
        }
        assert!(reachable.iter().all(|c| (c - middle).norm() > reach));
        // ... and the goal is a reachable cell within the reach of one of its cells.
        assert!(reachable.iter().any(|c| (c - chosen.goal).norm() < 1e-9));
        let near_a_cell = chosen
            .frontier
            .cells
            .iter()
            .any(|&c| (geometry.cell_center(c) - chosen.goal).norm() <= reach + 1e-9);
        assert!(near_a_cell, "{chosen:?}");
    }

    #[test]
    fn a_frontier_given_up_is_not_chosen_again_and_is_reported() {
        let (g, planning) = corridor_and_patch();
        let mut explorer = Explorer::new(ExplorerConfig::default()).unwrap();
        let goal = explorer
            .decide(&g, &planning, Vector2::new(1.0, 1.0))
            .chosen
            .unwrap()
            .goal;
        explorer.give_up(goal, GiveUpReason::Blocked);
        let decision = explorer.decide(&g, &planning, Vector2::new(1.0, 1.0));
        assert_eq!(decision.chosen, None, "nothing left to explore");
        assert_eq!((decision.reachable, decision.given_up), (0, 1));
        assert_eq!(
            explorer.given_up(),
            [GivenUpFrontier {
                goal,
                reason: GiveUpReason::Blocked
            }]
        );
    }

    /// A frontier given up for a first `NoPath` is tried again once the map has been decided
    /// on `NO_PATH_LAPSES_AFTER` more times, or at once when nothing else is left to explore; a
    /// second `NoPath` there, or any other reason, is for good.
    #[test]
    fn a_first_no_path_lapses_and_a_second_does_not() {
        let at = Vector2::new(1.0, 1.0);
        let greedy = || {
            Explorer::new(ExplorerConfig {
                choice: FrontierChoice::GreedyNearestFrontier,
                ..ExplorerConfig::default()
            })
            .unwrap()
        };
        // Two frontiers: the niche (nearer) and the corridor's open end.
        let (g, planning) = corridor_with_a_niche(false);
        for (reason, lapses) in [
            (GiveUpReason::NoPath, true),
            (GiveUpReason::Blocked, false),
            (GiveUpReason::StillUnknownFromGoal, false),
        ] {
            let mut explorer = greedy();
            let niche = explorer.decide(&g, &planning, at).chosen.unwrap().goal;
            explorer.give_up(niche, reason);
            let other = explorer.decide(&g, &planning, at).chosen.unwrap().goal;
            assert!((other - niche).norm() > 1.0, "{reason:?}");
            for _ in 2..NO_PATH_LAPSES_AFTER {
                let goal = explorer.decide(&g, &planning, at).chosen.map(|c| c.goal);
                assert_eq!(goal, Some(other), "{reason:?}");
            }
            let again = explorer.decide(&g, &planning, at).chosen.unwrap().goal;
            assert_eq!(again, if lapses { niche } else { other }, "{reason:?}");
            if lapses {
                explorer.give_up(niche, GiveUpReason::NoPath);
                for _ in 0..3 * NO_PATH_LAPSES_AFTER {
                    let goal = explorer.decide(&g, &planning, at).chosen.map(|c| c.goal);
                    assert_eq!(goal, Some(other));
                }
            }
        }
        // One frontier: a first `NoPath` is tried again at once, a second is for good.
        let (g, planning) = corridor_and_patch();
        for (reason, lapses) in [
            (GiveUpReason::NoPath, true),
            (GiveUpReason::Blocked, false),
            (GiveUpReason::StillUnknownFromGoal, false),
        ] {
            let mut explorer = greedy();
            let goal = explorer.decide(&g, &planning, at).chosen.unwrap().goal;
            explorer.give_up(goal, reason);
            let again = explorer.decide(&g, &planning, at).chosen.map(|c| c.goal);
            assert_eq!(again, lapses.then_some(goal), "{reason:?}");
            if lapses {
                explorer.give_up(goal, GiveUpReason::NoPath);
            }
            for _ in 0..3 * NO_PATH_LAPSES_AFTER {
                assert_eq!(
                    explorer.decide(&g, &planning, at).chosen,
                    None,
                    "{reason:?}"
                );
            }
        }
    }

    /// A closed room 3.8 m x 1.9 m and, behind its north wall, a strip of floor two cells deep
    /// running along it (seen through a door elsewhere) with unknown space beyond: `hole` opens
    /// one cell of that wall.
    fn room_and_strip_behind_its_wall(hole: Option<u32>) -> (OccupancyGrid, PlanningGrid) {
        let geometry = GridGeometry::try_new(Vector2::zeros(), 0.1).unwrap();
        let mut g = OccupancyGrid::new(40, 26, geometry, CellState::Unknown).unwrap();
        for y in 0..=20 {
            for x in 0..40 {
                let wall = x == 0 || x == 39 || y == 0 || (y == 20 && hole != Some(x));
                let state = if wall {
                    CellState::Occupied
                } else {
                    CellState::Free
                };
                g.set(Cell::new(x, y), state).unwrap();
            }
        }
        for y in 21..=22 {
            for x in 5..=35 {
                g.set(Cell::new(x, y), CellState::Free).unwrap();
            }
        }
        let planning = PlanningGrid::new(&g, PlanningGridConfig::default()).unwrap();
        (g, planning)
    }

    /// A frontier's goal must see it: the reachable cells nearest the strip lie under the wall,
    /// from where the robot would see nothing of it, so the strip has no goal; through a hole in
    /// the wall in line with the frontier's middle, the cell below the hole is its goal.
    #[test]
    fn a_frontier_behind_a_wall_is_not_given_a_goal_that_cannot_see_it() {
        let at = Vector2::new(1.0, 1.0);
        let (g, planning) = room_and_strip_behind_its_wall(None);
        let mut explorer = Explorer::new(ExplorerConfig::default()).unwrap();
        let decision = explorer.decide(&g, &planning, at);
        assert_eq!(decision.chosen, None, "{decision:?}");
        assert_eq!(decision.unreachable.len(), 1);
        let middle = decision.unreachable[0].middle;
        assert!(middle.y >= 21, "{middle:?}");

        let (g, planning) = room_and_strip_behind_its_wall(Some(middle.x));
        let decision = Explorer::new(ExplorerConfig::default())
            .unwrap()
            .decide(&g, &planning, at);
        let chosen = decision.chosen.expect("a goal below the hole");
        let goal = g.occupied().cell_at(chosen.goal).unwrap();
        assert_eq!(goal.x, middle.x, "{chosen:?}");
        assert!(line_of_sight(g.occupied(), goal, middle));
    }

    #[test]
    fn a_robot_with_no_free_cell_near_it_reaches_nothing() {
        let (g, planning) = corridor_and_patch();
        let mut explorer = Explorer::new(ExplorerConfig::default()).unwrap();
        // In the unknown space between the corridor and the patch.
        let decision = explorer.decide(&g, &planning, Vector2::new(5.4, 1.5));
        assert_eq!(decision.chosen, None);
        assert_eq!(decision.unreachable.len(), 2);
    }

    /// A corridor 6 m long and 1.9 m wide, walled on three sides and open to the east unless
    /// `east_closed`, with a niche in its north wall near the robot: a gap of 6 cells opening on
    /// an unknown pocket 6 cells wide and 2 deep, walled all round (a scrap behind furniture).
    fn corridor_with_a_niche(east_closed: bool) -> (OccupancyGrid, PlanningGrid) {
        let geometry = GridGeometry::try_new(Vector2::zeros(), 0.1).unwrap();
        let mut g = OccupancyGrid::new(80, 26, geometry, CellState::Unknown).unwrap();
        for y in 0..=20 {
            for x in 0..60 {
                let gap = y == 20 && (10..16).contains(&x);
                let wall = x == 0 || y == 0 || (y == 20 && !gap) || (east_closed && x == 59);
                let state = if wall {
                    CellState::Occupied
                } else {
                    CellState::Free
                };
                g.set(Cell::new(x, y), state).unwrap();
            }
        }
        // The pocket (y 21-22, x 10-15) stays unknown; its walls.
        for x in 9..=16 {
            g.set(Cell::new(x, 23), CellState::Occupied).unwrap();
        }
        for y in 21..=22 {
            g.set(Cell::new(9, y), CellState::Occupied).unwrap();
            g.set(Cell::new(16, y), CellState::Occupied).unwrap();
        }
        let planning = PlanningGrid::new(&g, PlanningGridConfig::default()).unwrap();
        (g, planning)
    }

    fn decide_with(
        choice: FrontierChoice,
        g: &OccupancyGrid,
        p: &PlanningGrid,
    ) -> FrontierDecision {
        Explorer::new(ExplorerConfig {
            choice,
            ..ExplorerConfig::default()
        })
        .unwrap()
        .decide(g, p, Vector2::new(1.0, 1.0))
    }

    /// The niche is nearer, so the nearest-first rule walks to it; it can reveal at most its 12
    /// unknown cells (0.12 m², the oracle: the pocket is walled all round), so the rule that
    /// asks for 1 m² walks to the corridor's open end instead, and with that end closed it
    /// stops (nothing worth a walk) where the nearest-first rule still walks to the niche.
    #[test]
    fn the_nearest_revealing_rule_leaves_a_scrap_and_takes_the_open_end() {
        let revealing = FrontierChoice::NearestRevealing { min_gain: 1.0 };
        let pocket = 12.0 * 0.1 * 0.1;
        let (g, planning) = corridor_with_a_niche(false);
        let greedy = decide_with(FrontierChoice::GreedyNearestFrontier, &g, &planning);
        let scrap = greedy.chosen.unwrap();
        assert_eq!(scrap.frontier.size(), 6, "{scrap:?}");
        assert!(scrap.gain <= pocket + 1e-9, "{}", scrap.gain);
        let decision = decide_with(revealing, &g, &planning);
        assert_eq!(decision.reachable, 2);
        let open_end = decision.chosen.unwrap();
        assert_eq!(open_end.frontier.size(), 19, "{open_end:?}");
        assert!(open_end.cost > scrap.cost);
        assert!(open_end.gain >= 1.0, "{}", open_end.gain);

        let (g, planning) = corridor_with_a_niche(true);
        let greedy = decide_with(FrontierChoice::GreedyNearestFrontier, &g, &planning);
        assert_eq!(greedy.chosen.unwrap().frontier.size(), 6);
        let decision = decide_with(revealing, &g, &planning);
        assert_eq!(decision.chosen, None, "only the scrap is left");
        assert_eq!(decision.reachable, 1);
    }

    /// Random rooms of free, occupied and unknown blocks: the rule's choice is the oracle's, the
    /// nearest-first rule asked again and again with each frontier it picks that reveals too
    /// little given up, until one reveals enough or none is left; with no minimum, the two rules
    /// are the same. (Where two frontiers share a goal, giving one up takes the other too: those
    /// cases are left out.)
    #[test]
    fn the_nearest_revealing_rule_is_nearest_first_without_the_scraps() {
        let mut next = crate::nav::test_lcg::lcg(0x853c_49e6_748f_ea9bu64);
        let geometry = GridGeometry::try_new(Vector2::zeros(), 0.1).unwrap();
        let (mut chosen, mut shared_goals) = (0, 0);
        for _ in 0..60 {
            // 4x4-cell blocks: mostly free near the robot's corner, unknown and walls beyond.
            let mut g = OccupancyGrid::new(60, 48, geometry, CellState::Unknown).unwrap();
            for by in 0..12 {
                for bx in 0..15 {
                    let state = match next() % 10 {
                        _ if bx < 3 && by < 3 => CellState::Free,
                        0..=5 => CellState::Free,
                        6 | 7 => CellState::Unknown,
                        _ => CellState::Occupied,
                    };
                    for y in 4 * by..4 * by + 4 {
                        for x in 4 * bx..4 * bx + 4 {
                            g.set(Cell::new(x, y), state).unwrap();
                        }
                    }
                }
            }
            let planning = PlanningGrid::new(&g, PlanningGridConfig::default()).unwrap();
            let at = Vector2::new(0.6, 0.6);
            for min_gain in [0.0, 0.5, 2.0, 6.0] {
                let config = |choice| ExplorerConfig {
                    choice,
                    // Only the goal given up: frontiers with goals nearby stay.
                    give_up_radius: 1e-6,
                    ..ExplorerConfig::default()
                };
                let mut rule =
                    Explorer::new(config(FrontierChoice::NearestRevealing { min_gain })).unwrap();
                let got = rule.decide(&g, &planning, at).chosen;
                let mut greedy =
                    Explorer::new(config(FrontierChoice::GreedyNearestFrontier)).unwrap();
                let mut gave_up = 0;
                let want = loop {
                    let decision = greedy.decide(&g, &planning, at);
                    if decision.given_up > gave_up {
                        // Two frontiers with one goal: giving one up took the other too.
                        break None;
                    }
                    match decision.chosen {
                        Some(c) if c.gain < min_gain => {
                            greedy.give_up(c.goal, GiveUpReason::Blocked);
                            gave_up += 1;
                        }
                        other => break Some(other),
                    }
                };
                let Some(want) = want else {
                    shared_goals += 1;
                    continue;
                };
                assert_eq!(got, want, "min gain {min_gain}");
                chosen += usize::from(got.is_some());
            }
        }
        assert!(
            chosen > 60 && shared_goals < 60,
            "{chosen} choices, {shared_goals} left out: the grids must leave frontiers to pick"
        );
    }
}
