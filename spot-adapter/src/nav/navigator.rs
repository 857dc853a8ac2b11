//! `Navigator`: walks the robot to a goal in a mapped building. Each cycle it localises the live
//! scan against the map, fuses the scan into a live layer over the map's occupancy, replans
//! when the path is blocked (or every few seconds), and turns the path into a velocity command.

use gridmap::{CellRect, CellState, LiveLayer, PlanningGrid};
use nalgebra::Vector2;
use pathfind::{AStar, CellCostAStar, JumpPointSearch, filter_path, line_of_sight};
use slam_core::{BitGrid, Cell, GridPath, Planner, PointCloud, Pose3, Registrator};

use crate::error::AdapterError;
use crate::nav::config::{NavigatorConfig, PlannerKind};
use crate::nav::localiser::{LocalisationHealth, LocalisationStatus, Localiser};
use crate::nav::navigation_map::NavigationMap;
use crate::nav::stuck::{StuckMonitor, StuckState};
use crate::nav::unseen::unseen_blockers;
use crate::robot::{MotionLimits, RobotDescription, Sample, VelocityCommand};

/// A goal: a plan-view position (map frame, metres) and, optionally, the heading to end with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Goal {
    /// Where the body should end (metres, map frame).
    pub position: Vector2<f64>,
    /// The heading it should end with (radians, map frame), if any.
    pub heading: Option<f64>,
}

impl From<Vector2<f64>> for Goal {
    fn from(position: Vector2<f64>) -> Self {
        Self {
            position,
            heading: None,
        }
    }
}

/// What the navigator decided this cycle.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum NavigationStep {
    /// Walk: hold this command until the next scan.
    Walk(VelocityCommand),
    /// Stand still this cycle (searching for the robot's place on the map).
    Hold,
    /// The body is within the goal tolerance (and faces the goal's heading): stop.
    Arrived,
    /// No collision-free path joins the robot and the goal on the map (an answer, not a
    /// failure): stop.
    NoPath,
    /// The robot made no progress though it tried to get free several times: stop.
    Blocked,
    /// Localisation failed and the wide searches did not find the robot on the map: stop.
    Lost,
}

/// Walks the robot to goals in a mapped building (map frame = the map cloud's frame).
///
/// Each [`Navigator::step`]:
/// 1. predicts the body pose from the odometry since the previous scan and corrects it by
///    registering the scan against the map (prepared once; the localiser tracks its health,
///    takes a large correction only once consecutive scans confirm it, and searches wide when
///    the robot seems lost);
/// 2. fuses the scan's obstacle band into a live layer over the map's occupancy (fresh
///    obstacles in, cells seen clear taken out, unseen changes decaying back to the map) and
///    brings the planning grid (hard inflation, clearance cost) up to date where it changed;
/// 3. replans when there is no path yet, the path crosses a newly blocked cell, or every few
///    seconds, and keeps the turning points a straight segment with room to spare cannot skip;
/// 4. turns in place while the heading error to the next waypoint is large, walks toward it
///    steering proportionally otherwise, and near the goal walks straight at it (sideways too)
///    ever slower.
///
/// A robot that makes no progress marks what lies ahead of it as blocked, backs off and
/// replans, and is reported [`NavigationStep::Blocked`] after a few attempts. A goal that cannot
/// be reached is answered with [`NavigationStep::NoPath`]; nothing loops forever.
pub struct Navigator<R: Registrator> {
    config: NavigatorConfig,
    limits: MotionLimits,
    localiser: Localiser<R>,
    map: NavigationMap,
    live: LiveLayer,
    planning: PlanningGrid,
    /// The planning grid of the map alone, without the live layer's changes: how far the way
    /// would be if what is new moved away.
    static_planning: PlanningGrid,
    waypoints: Vec<Vector2<f64>>,
    /// Every cell of the current path, for the blocked-path test.
    path_cells: Vec<Cell>,
    /// The goal the path leads to.
    planned_for: Option<Vector2<f64>>,
    cycles_since_plan: usize,
    /// Cycles waited so far for the current path's blockage to clear.
    waited: usize,
    /// Which cells of the map's own path were blocked when last waiting, and for how many
    /// cycles in a row they stayed the same (what blocks the way does not move).
    waiting_on: (Option<Blockage>, usize),
    /// The goal for which the robot already waited its patience out: it does not wait again on
    /// the way there (a box that stays would have it turn back and forth).
    waited_out_for: Option<Vector2<f64>>,
    /// Where paths to the current goal were blocked (cell centres, metres): a periodic replan
    /// that would lead back through one of them keeps the current path instead. What blocked
    /// a path seen from close by can look clear from a few metres off (the edge cells of a
    /// box are hit by fewer beams), and without this the robot turned back and forth between
    /// the way past it and the way round.
    blocked_at: Vec<Vector2<f64>>,
    replans: usize,
    recoveries: usize,
    stuck: StuckMonitor,
}

impl<R: Registrator> Navigator<R> {
    /// A navigator for `robot` on `map` (a map cloud to localise against, e.g.
    /// [`slam_core::GraphSlam::map`]) and `navigation` (its occupancy and floor, a
    /// [`NavigationMap`]), localising with `registrator`, starting from `map_t_body`. Its
    /// commands keep to the robot's motion limits.
    ///
    /// # Errors
    /// [`AdapterError::InvalidConfig`] for invalid settings or limits,
    /// [`AdapterError::NavigationGrid`] for grid settings gridmap refuses,
    /// [`AdapterError::LocalisationMap`] (with the registrator's error as its source) for a
    /// map the registrator refuses.
    pub fn new(
        registrator: R,
        map: &PointCloud,
        navigation: &NavigationMap,
        map_t_body: Pose3,
        robot: &RobotDescription,
        config: NavigatorConfig,
    ) -> Result<Self, AdapterError> {
        config.validate()?;
        robot.limits.validate()?;
        let target = registrator
            .prepare_target(map)
            .map_err(AdapterError::LocalisationMap)?;
        let live = LiveLayer::new(navigation.occupancy().clone(), config.live.clone())
            .map_err(AdapterError::NavigationGrid)?;
        let planning = PlanningGrid::new(live.combined(), config.planning.clone())
            .map_err(AdapterError::NavigationGrid)?;
        let static_planning = planning.clone();
        Ok(Self {
            localiser: Localiser::new(registrator, target, map_t_body, config.localiser.clone())?,
            stuck: StuckMonitor::new(config.stuck.clone()),
            map: navigation.clone(),
            live,
            planning,
            static_planning,
            config,
            limits: robot.limits.clone(),
            waypoints: Vec::new(),
            path_cells: Vec::new(),
            planned_for: None,
            cycles_since_plan: 0,
            waited: 0,
            waiting_on: (None, 0),
            waited_out_for: None,
            blocked_at: Vec::new(),
            replans: 0,
            recoveries: 0,
        })
    }

    /// One cycle for the scan and odometry in `sample`, toward `goal` (map frame: a position,
    /// or a [`Goal`] with a final heading).
    ///
    /// # Errors
    /// [`AdapterError::NonFiniteGoal`] for a goal that is not a finite point or heading
    /// (checked before anything else); [`AdapterError::Planner`] when the planner refuses its
    /// arguments and [`AdapterError::NavigationGrid`] when the live layer refuses the scan
    /// (out-of-order stamps), which the navigator's own checks rule out in normal use.
    pub fn step(
        &mut self,
        sample: &Sample,
        goal: impl Into<Goal>,
    ) -> Result<NavigationStep, AdapterError> {
        let goal = goal.into();
        let target = goal.position;
        if !(target.x.is_finite()
            && target.y.is_finite()
            && goal.heading.is_none_or(f64::is_finite))
        {
            return Err(AdapterError::NonFiniteGoal {
                x: target.x,
                y: target.y,
            });
        }
        if self.planned_for != Some(target) {
            self.stuck.reset();
            self.waypoints.clear();
            self.path_cells.clear();
            self.blocked_at.clear();
        }
        let walking = (self.localiser.pose().translation.vector.xy() - target).norm()
            > self.config.localiser.full_scan_within;
        let status = self.localiser.update(sample, walking);
        match status {
            LocalisationStatus::Searching => {
                self.stuck.reset();
                return Ok(NavigationStep::Hold);
            }
            LocalisationStatus::Lost => {
                self.waypoints.clear();
                return Ok(NavigationStep::Lost);
            }
            _ => {}
        }
        let pose = self.localiser.pose();
        // Only scans the map confirmed go into the live layer: a scan placed wrongly would
        // paint obstacles where there are none.
        let fused = matches!(
            status,
            LocalisationStatus::Corrected | LocalisationStatus::Relocalised
        );
        if fused {
            self.fuse(sample, &pose)?;
        }
        let position = pose.translation.vector.xy();
        let yaw = pose.rotation.euler_angles().2;
        let distance = (target - position).norm();
        let heading_error = goal.heading.map_or(0.0, |h| wrap(h - yaw));
        if distance <= self.config.goal_tolerance
            && heading_error.abs() <= self.config.heading_tolerance
        {
            self.waypoints.clear();
            self.stuck.reset();
            return Ok(NavigationStep::Arrived);
        }
        match self.stuck.check(position) {
            StuckState::Free => {}
            StuckState::BackingOff => {
                if self.stuck.just_started() {
                    self.recoveries += 1;
                    self.mark_ahead(&pose, sample.stamp)?;
                }
                // Replan once free.
                self.path_cells.clear();
                let command = VelocityCommand::new(-self.config.stuck.backoff_speed, 0.0);
                return Ok(NavigationStep::Walk(command));
            }
            StuckState::Blocked => {
                self.waypoints.clear();
                self.stuck.reset();
                return Ok(NavigationStep::Blocked);
            }
        }
        if let Some(answer) =
            self.replan_if_needed(position, target, fused.then_some(sample.stamp))?
        {
            return Ok(answer);
        }
        let near = 0.5 * self.config.goal_tolerance;
        while self.waypoints.len() > 1 && (self.waypoints[0] - position).norm() <= near {
            self.waypoints.remove(0);
        }
        let command = if distance <= self.config.goal_tolerance {
            // In place: only the heading is left.
            let rate = (self.config.heading_gain * heading_error)
                .clamp(-self.limits.max_yaw_rate, self.limits.max_yaw_rate);
            VelocityCommand::new(0.0, rate)
        } else if distance <= self.config.approach_distance && self.waypoints.len() == 1 {
            self.approach(&pose, target)
        } else {
            self.command(position, yaw)
        };
        self.stuck.commanded(&command);
        Ok(NavigationStep::Walk(command))
    }

    /// Replan when there is no path, the path crosses a newly blocked cell, or the periodic
    /// replan is due; an answer when no path is left (`NoPath`, or `Hold` while the estimate is
    /// unconfirmed). `fused_at` is the stamp of this cycle's scan when it went into the live
    /// layer.
    fn replan_if_needed(
        &mut self,
        position: Vector2<f64>,
        target: Vector2<f64>,
        fused_at: Option<f64>,
    ) -> Result<Option<NavigationStep>, AdapterError> {
        self.cycles_since_plan += 1;
        let blocked = !self.path_cells.is_empty() && self.planning.blocks_any(&self.path_cells);
        let replan = self.path_cells.is_empty()
            || blocked
            || self.cycles_since_plan >= self.config.replan_every;
        if !replan {
            self.waited = 0;
            return Ok(None);
        }
        if blocked {
            self.remember_blockage();
        }
        let mut plan = self.plan(position, target)?;
        // A periodic replan back through a place that blocked an earlier path to this goal:
        // the current path, still clear, stands (its waypoints made afresh from here).
        if !blocked
            && !self.path_cells.is_empty()
            && plan
                .as_ref()
                .is_some_and(|(_, cells)| self.passes_blockage(cells))
        {
            self.follow_on(position, target);
            self.cycles_since_plan = 0;
            self.waited = 0;
            return Ok(None);
        }
        let mut waiting = self.waiting_for(position, target, plan.as_ref())?;
        // What blocks the way and this scan does not see (a person who walked past close by,
        // under the lowest beam: nothing clears those cells from here) is not waited for: it
        // is forgotten and the way planned again. Anything still there is seen again.
        if let (Some((_, cells)), Some(stamp)) = (&waiting, fused_at)
            && let Some(blockers) =
                unseen_blockers(&self.live, cells, self.config.planning.inflation)
        {
            self.forget(&blockers, stamp)?;
            plan = self.plan(position, target)?;
            waiting = self.waiting_for(position, target, plan.as_ref())?;
        }
        if let Some((blockage, _)) = waiting {
            // Something new stands in the way and the way around is far longer (or there is
            // none): wait for it to move on, while it moves. The next cycle plans again.
            let (last, same) = self.waiting_on;
            let unchanged = last == Some(blockage);
            self.waiting_on = (Some(blockage), if unchanged { same + 1 } else { 0 });
            self.waited += 1;
            // A blockage that stays put is given up on early only when there is a way round.
            if self.waited < self.config.detour_patience
                && (self.waiting_on.1 < STILL_BLOCKAGE_CYCLES || plan.is_none())
            {
                self.stuck.commanded(&VelocityCommand::new(0.0, 0.0));
                return Ok(Some(NavigationStep::Hold));
            }
            // Waited long enough, or what blocks does not move: go round, and do not wait
            // again on the way to this goal.
            self.waited_out_for = Some(target);
        }
        self.waiting_on = (None, 0);
        self.waited = 0;
        if let Some((waypoints, cells)) = plan {
            self.waypoints = waypoints;
            self.path_cells = cells;
            self.planned_for = Some(target);
            self.cycles_since_plan = 0;
            self.replans += 1;
            return Ok(None);
        }
        self.waypoints.clear();
        self.path_cells.clear();
        // "No path" from an estimate the last scan did not confirm may be the estimate's
        // fault: stand and localise first.
        if self.localiser.health().consecutive_failures > 0 {
            return Ok(Some(NavigationStep::Hold));
        }
        Ok(Some(NavigationStep::NoPath))
    }

    /// What blocks the way to `target` (see [`Self::worth_waiting`]) given the live `plan`. With
    /// no way round at all, something new blocking the way is waited for again (a person met
    /// twice): only once the patience runs out is the answer `NoPath`.
    #[allow(clippy::type_complexity)]
    fn waiting_for(
        &self,
        position: Vector2<f64>,
        target: Vector2<f64>,
        plan: Option<&(Vec<Vector2<f64>>, Vec<Cell>)>,
    ) -> Result<Option<(Blockage, Vec<Cell>)>, AdapterError> {
        if self.waited_out_for == Some(target) && plan.is_some() {
            return Ok(None);
        }
        let resolution = self.planning.blocked().geometry().resolution;
        let live_length = plan.map(|(_, cells)| cells_length(cells) * resolution);
        self.worth_waiting(position, target, live_length)
    }

    /// Return `cells` to the static map's state in the live layer (at `stamp`, seconds) and
    /// refresh the planning grid there.
    fn forget(&mut self, cells: &[Cell], stamp: f64) -> Result<(), AdapterError> {
        let mut changed = CellRect {
            x0: 0,
            y0: 0,
            x1: 0,
            y1: 0,
        };
        for &c in cells {
            let state = self.live.static_map().state(c);
            let update = self
                .live
                .mark(c, state, stamp)
                .map_err(AdapterError::NavigationGrid)?;
            if let Some(r) = update.changed {
                changed = changed.union(&r);
            }
        }
        self.refresh(changed)
    }

    /// Record where the current path is blocked (its first and last blocked cells).
    fn remember_blockage(&mut self) {
        let grid = self.planning.blocked();
        let first = self
            .path_cells
            .iter()
            .find(|c| grid.is_blocked(**c))
            .copied();
        let last = self
            .path_cells
            .iter()
            .rfind(|c| grid.is_blocked(**c))
            .copied();
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

    /// Whether the path through `cells` passes within [`BLOCKAGE_RADIUS`] of a place that
    /// blocked an earlier path to the current goal.
    fn passes_blockage(&self, cells: &[Cell]) -> bool {
        let grid = self.planning.blocked();
        cells.iter().any(|&c| {
            let at = grid.cell_center(c);
            self.blocked_at
                .iter()
                .any(|b| (b - at).norm() < BLOCKAGE_RADIUS)
        })
    }

    /// Fuse the scan (at the corrected `pose`) into the live layer and refresh the planning grid
    /// where it changed.
    fn fuse(&mut self, sample: &Sample, pose: &Pose3) -> Result<(), AdapterError> {
        let map_t_lidar = pose * sample.body_t_lidar;
        let update = self
            .live
            .update(&sample.cloud, &map_t_lidar, self.map.floor(), sample.stamp)
            .map_err(AdapterError::NavigationGrid)?;
        if let Some(changed) = update.changed {
            self.refresh(changed)?;
        }
        Ok(())
    }

    fn refresh(&mut self, changed: CellRect) -> Result<(), AdapterError> {
        self.planning
            .refresh(self.live.combined(), changed)
            .map_err(AdapterError::NavigationGrid)?;
        Ok(())
    }

    /// Mark the cells just ahead of the body (0.3-0.6 m ahead, 0.5 m wide) as occupied in the
    /// live layer: what the robot could not walk through.
    fn mark_ahead(&mut self, pose: &Pose3, stamp: f64) -> Result<(), AdapterError> {
        let yaw = pose.rotation.euler_angles().2;
        let (ahead, left) = (
            Vector2::new(yaw.cos(), yaw.sin()),
            Vector2::new(-yaw.sin(), yaw.cos()),
        );
        let at = pose.translation.vector.xy();
        let grid = self.live.combined();
        let mut cells = Vec::new();
        for f in [0.3, 0.4, 0.5, 0.6] {
            for s in [-0.25, -0.15, -0.05, 0.05, 0.15, 0.25] {
                if let Some(c) = grid.occupied().cell_at(at + ahead * f + left * s) {
                    cells.push(c);
                }
            }
        }
        let mut changed = CellRect {
            x0: 0,
            y0: 0,
            x1: 0,
            y1: 0,
        };
        for c in cells {
            let update = self
                .live
                .mark(c, CellState::Occupied, stamp)
                .map_err(AdapterError::NavigationGrid)?;
            if let Some(r) = update.changed {
                changed = changed.union(&r);
            }
        }
        self.refresh(changed)
    }

    /// The final approach: straight at the goal in the body frame (forward and sideways, no
    /// turn), at a speed proportional to the distance left.
    fn approach(&self, pose: &Pose3, target: Vector2<f64>) -> VelocityCommand {
        let to = target - pose.translation.vector.xy();
        let yaw = pose.rotation.euler_angles().2;
        let (c, s) = (yaw.cos(), yaw.sin());
        let body = Vector2::new(c * to.x + s * to.y, -s * to.x + c * to.y);
        let distance = body.norm();
        let speed = (self.config.approach_gain * distance)
            .min(self.config.approach_speed)
            .min(self.limits.max_lateral_speed);
        let v = body / distance.max(1e-9) * speed;
        VelocityCommand {
            forward: v.x,
            lateral: v.y,
            yaw_rate: 0.0,
        }
    }

    /// What blocks the way, when the live path (its length `live_length` in metres, `None`
    /// when there is none) is more than `detour_extra` longer than the path on the map alone,
    /// which exists: something new stands on the map's path. With it the blocked cells of the
    /// map's path. `None` when there is nothing to wait for.
    fn worth_waiting(
        &self,
        position: Vector2<f64>,
        goal: Vector2<f64>,
        live_length: Option<f64>,
    ) -> Result<Option<(Blockage, Vec<Cell>)>, AdapterError> {
        let resolution = self.planning.blocked().geometry().resolution;
        let extra = self.config.detour_extra;
        // No path can be shorter than the straight line: most plans need no second search.
        if live_length.is_some_and(|l| l <= (goal - position).norm() + extra) {
            return Ok(None);
        }
        let Some(map_only) =
            plan_cells(&self.static_planning, self.config.planner, position, goal)?
        else {
            return Ok(None);
        };
        let map_length = cells_length(&map_only) * resolution;
        if live_length.is_some_and(|l| l <= map_length + extra) {
            return Ok(None);
        }
        let grid = self.planning.blocked();
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
        Ok(Some((
            Blockage {
                first: map_only[first],
                last: map_only[last],
                count,
            },
            cells,
        )))
    }

    /// Waypoints (metres) from `position` to `goal` after the start and the dense cells of the
    /// path, or `None` when none joins them (the goal off the map or blocked, the robot off the
    /// map, or no path). A start inside the inflated obstacles (the robot brushed a wall) plans
    /// from the nearest free cell.
    #[allow(clippy::type_complexity)]
    fn plan(
        &mut self,
        position: Vector2<f64>,
        goal: Vector2<f64>,
    ) -> Result<Option<(Vec<Vector2<f64>>, Vec<Cell>)>, AdapterError> {
        let Some(cells) = plan_cells(&self.planning, self.config.planner, position, goal)? else {
            return Ok(None);
        };
        let waypoints = self.waypoints_along(&cells, goal);
        Ok(Some((waypoints, cells)))
    }

    /// Waypoints (metres) along the dense `cells` of a path to `goal`, after its first cell:
    /// the turning points a straight segment with room to spare cannot skip, then the goal.
    fn waypoints_along(&self, cells: &[Cell], goal: Vector2<f64>) -> Vec<Vector2<f64>> {
        let grid = self.planning.blocked();
        // Shortcuts only where they keep room to spare; in narrow places the path's cells.
        let roomy = self.roomy_grid();
        let filtered = filter_path(
            &roomy,
            &GridPath {
                length: cells_length(cells),
                expanded: 0,
                cells: cells.to_vec(),
            },
        );
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

    /// The current path from its cell nearest `position` on, its waypoints made afresh: the
    /// route kept, as a replan from here along it would give.
    fn follow_on(&mut self, position: Vector2<f64>, goal: Vector2<f64>) {
        let grid = self.planning.blocked();
        let nearest = self
            .path_cells
            .iter()
            .enumerate()
            .min_by(|a, b| {
                let d = |c: &Cell| (grid.cell_center(*c) - position).norm_squared();
                d(a.1).total_cmp(&d(b.1))
            })
            .map_or(0, |(k, _)| k);
        self.path_cells.drain(..nearest);
        let cells = std::mem::take(&mut self.path_cells);
        self.waypoints = self.waypoints_along(&cells, goal);
        self.path_cells = cells;
    }

    /// The planning grid with every cell closer than the shortcut clearance to an obstacle
    /// blocked too: the grid straight segments between waypoints must keep to.
    fn roomy_grid(&self) -> BitGrid {
        let grid = self.planning.blocked();
        let limit = self.config.shortcut_clearance as f32;
        let clearance = self.planning.clearance();
        let mut roomy = grid.clone();
        let w = grid.width() as usize;
        for (k, &d) in clearance.iter().enumerate() {
            if d < limit {
                let c = Cell::new((k % w) as u32, (k / w) as u32);
                // The cell exists: k indexes the grid's cells.
                let _ = roomy.set(c, true);
            }
        }
        roomy
    }

    /// The command toward the first waypoint that is not already underfoot.
    fn command(&self, position: Vector2<f64>, yaw: f64) -> VelocityCommand {
        let near = 0.5 * self.config.goal_tolerance;
        let next = self
            .waypoints
            .iter()
            .position(|w| (*w - position).norm() > near)
            .unwrap_or(self.waypoints.len().saturating_sub(1));
        // Look ahead along closely spaced waypoints (a path through a narrow place) to the
        // farthest one within reach that a straight, hard-inflation-free line joins: steering at
        // a cell 0.1 m ahead would turn the robot in place at every small offset.
        let grid = self.planning.blocked();
        let here = grid.cell_at(position);
        let mut target = self.waypoints.get(next).copied().unwrap_or(position);
        for w in self.waypoints.iter().skip(next + 1) {
            if (w - position).norm() > self.config.lookahead {
                break;
            }
            let visible = here
                .zip(grid.cell_at(*w))
                .is_some_and(|(a, b)| line_of_sight(grid, a, b));
            if !visible {
                break;
            }
            target = *w;
        }
        let to = target - position;
        let error = wrap(to.y.atan2(to.x) - yaw);
        let max_yaw_rate = self.limits.max_yaw_rate;
        let yaw_rate = (self.config.heading_gain * error).clamp(-max_yaw_rate, max_yaw_rate);
        if error.abs() > self.config.turn_in_place_above {
            return VelocityCommand::new(0.0, yaw_rate);
        }
        // Slow down for the last metre so that one 0.2 s step cannot overshoot the tolerance.
        let remaining: f64 = self.waypoints.last().map_or(0.0, |g| (g - position).norm());
        let speed = self.config.speed.min(self.limits.max_forward_speed);
        VelocityCommand::new(speed.min(remaining) * error.cos(), yaw_rate)
    }

    /// The current estimate of the body pose in the map frame.
    #[must_use]
    pub fn pose(&self) -> Pose3 {
        self.localiser.pose()
    }

    /// The health of localisation (last registration, failures, relocalisations).
    #[must_use]
    pub fn localisation(&self) -> LocalisationHealth {
        self.localiser.health()
    }

    /// The planned waypoints (metres) after the robot's position, ending at the goal.
    #[must_use]
    pub fn waypoints(&self) -> &[Vector2<f64>] {
        &self.waypoints
    }

    /// The planning grid: the occupancy with the live layer, hard-inflated.
    #[must_use]
    pub fn grid(&self) -> &BitGrid {
        self.planning.blocked()
    }

    /// The live layer (the static map with the scans' changes).
    #[must_use]
    pub fn live(&self) -> &LiveLayer {
        &self.live
    }

    /// Plans made so far (the first of each goal, blocked paths, the periodic ones).
    #[must_use]
    pub fn replans(&self) -> usize {
        self.replans
    }

    /// Times the robot was stuck and backed off, so far.
    #[must_use]
    pub fn recoveries(&self) -> usize {
        self.recoveries
    }

    /// Cycles whose registration failed, did not converge, matched too little or was an
    /// unconfirmed jump (the odometry's prediction stood).
    #[must_use]
    pub fn localisation_failures(&self) -> usize {
        self.localiser.health().failures
    }
}

/// `angle` wrapped to (-pi, pi].
/// The blocked stretch of the map's own path: its first and last blocked cells and how many
/// are blocked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Blockage {
    first: Cell,
    last: Cell,
    count: usize,
}

/// A periodic replan may not lead back within this distance (metres) of where an earlier path
/// to the same goal was blocked: about a box's half width plus the hard inflation.
const BLOCKAGE_RADIUS: f64 = 0.6;

/// Waiting cycles with the blocked way unchanged after which the blockage counts as still (a
/// box, not a person walking): 10 (2 s).
const STILL_BLOCKAGE_CYCLES: usize = 10;

/// The dense cells of a path on `planning` from `position` to `goal` by `planner`, or `None`
/// when none joins them (either end off the map, the goal blocked, or no path). A start inside
/// the inflated obstacles plans from the nearest free cell.
fn plan_cells(
    planning: &PlanningGrid,
    planner: PlannerKind,
    position: Vector2<f64>,
    goal: Vector2<f64>,
) -> Result<Option<Vec<Cell>>, AdapterError> {
    let grid = planning.blocked();
    let Some(goal_cell) = grid.cell_at(goal).filter(|&c| !grid.is_blocked(c)) else {
        return Ok(None);
    };
    let Some(start) = grid.cell_at(position).and_then(|c| nearest_free(grid, c)) else {
        return Ok(None);
    };
    let path: Option<GridPath> = match planner {
        PlannerKind::CellCostAStar => CellCostAStar::new(grid, planning.step_costs())
            .map_err(|_| AdapterError::invalid("planning costs", f64::NAN, "valid"))?
            .plan(start, goal_cell),
        PlannerKind::JumpPointSearch => JumpPointSearch::new(grid).plan(start, goal_cell),
        PlannerKind::AStar => AStar::new(grid).plan(start, goal_cell),
    }
    .map_err(AdapterError::Planner)?;
    Ok(path.map(|p| p.expand()))
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

fn wrap(angle: f64) -> f64 {
    let a = angle.rem_euclid(std::f64::consts::TAU);
    if a > std::f64::consts::PI {
        a - std::f64::consts::TAU
    } else {
        a
    }
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
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            return Some(Cell::new((cx + dx) as u32, (cy + dy) as u32));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angles_wrap_into_minus_pi_to_pi() {
        use std::f64::consts::PI;
        for (a, want) in [
            (0.0, 0.0),
            (PI, PI),
            (-PI, PI),
            (1.5 * PI, -0.5 * PI),
            (-1.5 * PI, 0.5 * PI),
            (7.0, 7.0 - 2.0 * PI),
        ] {
            assert!((wrap(a) - want).abs() < 1e-12, "{a} -> {}", wrap(a));
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
}
