//! `Navigator`: walks the robot to a goal in a mapped building. Each cycle it localises the live
//! scan against the map, fuses the scan into a live layer over the map's occupancy, replans
//! when the path is blocked (or every few seconds), and turns the path into a velocity command.

use gridmap::{CellRect, CellState, LiveLayer, PlanningGrid};
use nalgebra::Vector2;
use slam_core::{BitGrid, Cell, PointCloud, Pose3, Registrator, wrap_angle};

use crate::nav::NavError;
use crate::nav::config::{NavigatorConfig, PlannerKind};
use crate::nav::controller::Controller;
use crate::nav::detour::{DetourPolicy, Wait};
use crate::nav::floor_levelling::level_on_floor;
use crate::nav::localiser::{LocalisationHealth, LocalisationStatus, Localiser};
use crate::nav::navigation_map::NavigationMap;
use crate::nav::path::{Plan, dense_path};
use crate::nav::planner::{NavPlanner, PlannerMemory};
use crate::nav::step::{Goal, NavigationStep};
use crate::nav::stuck::{StuckMonitor, StuckState};
use crate::nav::unseen::unseen_blockers;
use crate::robot::{MotionLimits, RobotDescription, Sample, VelocityCommand};

/// Walks the robot to goals in a mapped building (map frame = the map cloud's frame).
///
/// Each [`Navigator::step`]:
/// 1. predicts the body pose from the odometry since the previous scan and corrects it by
///    registering the scan against the map (prepared once; the localiser tracks its health,
///    takes a large correction only once consecutive scans confirm it, and searches wide when
///    the robot seems lost);
/// 2. levels the scan on the map's floor (its floor returns correct the estimate's height and
///    tilt), fuses its obstacle band into a live layer over the map's occupancy (fresh
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
///
/// It localises with any [`Registrator`] `R` and plans with any [`NavPlanner`] `P`: by default
/// one of ours, chosen by [`NavigatorConfig::planner`]; your own through
/// [`Navigator::with_planner`].
///
/// A runnable example is in the [module docs](crate::nav).
pub struct Navigator<R: Registrator, P: NavPlanner = PlannerKind> {
    config: NavigatorConfig,
    limits: MotionLimits,
    localiser: Localiser<R>,
    map: NavigationMap,
    live: LiveLayer,
    planning: PlanningGrid,
    /// The planning grid of the map alone, without the live layer's changes: how far the way
    /// would be if what is new moved away.
    static_planning: PlanningGrid,
    /// The planner ...
    planner: P,
    /// ... and its memory on `planning` and on `static_planning`, kept from plan to plan.
    memory: P::Memory,
    static_memory: P::Memory,
    /// The path being followed and its waypoints.
    plan: Plan,
    /// The goal the path leads to.
    planned_for: Option<Vector2<f64>>,
    cycles_since_plan: usize,
    /// Whether to wait for what newly blocks the way or go round.
    detour: DetourPolicy,
    replans: usize,
    recoveries: usize,
    stuck: StuckMonitor,
}

/// What a walk's navigator leaves for the next one of an exploration
/// ([`Navigator::into_leftovers`], [`Navigator::planned`]): its live layer, its two planning
/// grids and its planner's memories. The next navigator copies its map into them (about 50
/// bytes a cell of the grid in all) instead of allocating them afresh among the keyframes the
/// walks add, which left holes in the heap that the next, larger grid's did not fit.
pub(crate) struct Leftovers {
    live: LiveLayer,
    planning: PlanningGrid,
    /// The map's own planning grid.
    static_planning: PlanningGrid,
    /// The planner's memories on `planning` and on `static_planning`.
    memories: [PlannerMemory; 2],
}

impl Leftovers {
    /// A navigator's parts made afresh for `navigation` and its planning grid `planning`.
    fn new(
        navigation: &NavigationMap,
        planning: PlanningGrid,
        config: &NavigatorConfig,
    ) -> Result<Self, NavError> {
        // The live layer starts equal to the map, so its planning grid is the map's.
        let live = LiveLayer::new(navigation.occupancy().clone(), config.live.clone())
            .map_err(NavError::NavigationGrid)?;
        Ok(Self {
            live,
            static_planning: planning.clone(),
            planning,
            memories: Default::default(),
        })
    }
}

impl<R: Registrator> Navigator<R> {
    /// A navigator for `robot` on `map` (a map cloud to localise against, e.g.
    /// [`slam_core::GraphSlam::map`]) and `navigation` (its occupancy and floor, a
    /// [`NavigationMap`]), localising with `registrator`, starting from `map_t_body`. Its
    /// commands keep to the robot's motion limits.
    ///
    /// # Errors
    /// [`NavError::InvalidConfig`] for invalid settings or limits,
    /// [`NavError::NavigationGrid`] for grid settings gridmap refuses,
    /// [`NavError::LocalisationMap`] (with the registrator's error as its source) for a
    /// map the registrator refuses.
    pub fn new(
        registrator: R,
        map: &PointCloud,
        navigation: &NavigationMap,
        map_t_body: Pose3,
        robot: &RobotDescription,
        config: NavigatorConfig,
    ) -> Result<Self, NavError> {
        // Settings refused by name before the grid is built from them.
        config.validate()?;
        let planning = PlanningGrid::new(navigation.occupancy(), config.planning.clone())
            .map_err(NavError::NavigationGrid)?;
        Self::planned(
            registrator,
            map,
            navigation,
            &planning,
            None,
            map_t_body,
            robot,
            config,
        )
    }

    /// [`Navigator::new`] with `planning`, the planning grid of `navigation`'s occupancy with
    /// `config.planning`, made already (the explorer's, which it picked its frontier on), in
    /// the memory of `leftovers` when given (the last walk's navigator's: the same navigator as
    /// one made afresh).
    #[expect(
        clippy::too_many_arguments,
        reason = "Navigator::new's, and what to reuse"
    )]
    pub(crate) fn planned(
        registrator: R,
        map: &PointCloud,
        navigation: &NavigationMap,
        planning: &PlanningGrid,
        leftovers: Option<Leftovers>,
        map_t_body: Pose3,
        robot: &RobotDescription,
        config: NavigatorConfig,
    ) -> Result<Self, NavError> {
        config.validate()?;
        robot.limits.validate()?;
        let target = registrator
            .prepare_target(map)
            .map_err(NavError::LocalisationMap)?;
        let parts = match leftovers {
            Some(mut parts) => {
                parts
                    .live
                    .renew(navigation.occupancy(), config.live.clone())
                    .map_err(NavError::NavigationGrid)?;
                parts.planning.clone_from(planning);
                parts.static_planning.clone_from(planning);
                parts
            }
            None => Leftovers::new(navigation, planning.clone(), &config)?,
        };
        Self::assembled(
            registrator,
            target,
            navigation,
            parts,
            map_t_body,
            robot,
            config,
        )
    }

    /// The navigator of `new` and `planned` from its parts.
    fn assembled(
        registrator: R,
        target: R::Target,
        navigation: &NavigationMap,
        parts: Leftovers,
        map_t_body: Pose3,
        robot: &RobotDescription,
        config: NavigatorConfig,
    ) -> Result<Self, NavError> {
        let Leftovers {
            live,
            planning,
            static_planning,
            memories: [memory, static_memory],
        } = parts;
        let planner = config.planner;
        Ok(Self {
            localiser: Localiser::new(registrator, target, map_t_body, config.localiser.clone())?,
            stuck: StuckMonitor::new(config.stuck.clone()),
            detour: DetourPolicy::new(&config),
            map: navigation.clone(),
            live,
            planning,
            static_planning,
            config,
            limits: robot.limits.clone(),
            planner,
            memory,
            static_memory,
            plan: Plan::default(),
            planned_for: None,
            cycles_since_plan: 0,
            replans: 0,
            recoveries: 0,
        })
    }

    /// What this navigator leaves for the next walk's ([`Navigator::planned`]).
    pub(crate) fn into_leftovers(self) -> Leftovers {
        Leftovers {
            live: self.live,
            planning: self.planning,
            static_planning: self.static_planning,
            memories: [self.memory, self.static_memory],
        }
    }

    /// This navigator told the robot's odometry at the instant its starting pose `map_t_body`
    /// was taken, so that its first step carries that pose along the odometry's motion since
    /// (by default the motion is counted from the first step's sample on). A navigator made
    /// while the robot walks needs it: without it, the walk between the pose and the first step
    /// (12 cm at 0.6 m/s and 5 Hz) reaches the localiser as a correction too large to take at
    /// once, and in a corridor the estimate then lagged until a wide search put it 3 m off.
    ///
    /// # Errors
    /// [`NavError::NonFiniteOdometry`] for a pose that is not finite.
    pub fn with_start_odometry(mut self, odom_t_body: Pose3) -> Result<Self, NavError> {
        if !slam_core::pose3_is_finite(&odom_t_body) {
            return Err(NavError::NonFiniteOdometry);
        }
        self.localiser.set_odometry(odom_t_body);
        Ok(self)
    }

    /// This navigator planning with `planner` instead of [`NavigatorConfig::planner`] (which
    /// it then ignores): any [`NavPlanner`], e.g. your own planner built on each planning grid.
    /// Call it before the first [`Navigator::step`] (a path already planned is kept until the
    /// next replan).
    ///
    /// ```no_run
    /// # use gridmap::PlanningGrid;
    /// # use slam_core::{Cell, GridPath, PlanError, Planner, PointCloud, Pose3};
    /// # use spot_adapter::nav::{NavPlanner, NavigationMap, Navigator, NavigatorConfig};
    /// # use spot_adapter::robot::RobotDescription;
    /// /// Dijkstra's algorithm (pathfind's), built on each grid it is given.
    /// #[derive(Debug)]
    /// struct MyDijkstra;
    ///
    /// impl NavPlanner for MyDijkstra {
    ///     type Memory = ();
    ///
    ///     fn plan(
    ///         &mut self,
    ///         grid: &PlanningGrid,
    ///         _: &mut (),
    ///         start: Cell,
    ///         goal: Cell,
    ///     ) -> Result<Option<GridPath>, PlanError> {
    ///         pathfind::Dijkstra::new(grid.blocked()).plan(start, goal)
    ///     }
    /// }
    ///
    /// # fn run(map: &PointCloud, navigation: &NavigationMap, start: Pose3, robot: &RobotDescription)
    /// # -> Result<(), spot_adapter::nav::NavError> {
    /// let localiser = spot_adapter::pipelines::point_to_plane_localiser();
    /// let config = NavigatorConfig::default();
    /// let navigator = Navigator::new(localiser, map, navigation, start, robot, config)?
    ///     .with_planner(MyDijkstra);
    /// assert_eq!(navigator.replans(), 0);
    /// # Ok(())
    /// # }
    /// ```
    pub fn with_planner<Q: NavPlanner>(self, planner: Q) -> Navigator<R, Q> {
        Navigator {
            config: self.config,
            limits: self.limits,
            localiser: self.localiser,
            map: self.map,
            live: self.live,
            planning: self.planning,
            static_planning: self.static_planning,
            planner,
            memory: Q::Memory::default(),
            static_memory: Q::Memory::default(),
            plan: self.plan,
            planned_for: self.planned_for,
            cycles_since_plan: self.cycles_since_plan,
            detour: self.detour,
            replans: self.replans,
            recoveries: self.recoveries,
            stuck: self.stuck,
        }
    }
}

impl<R: Registrator, P: NavPlanner> Navigator<R, P> {
    /// Localise on `sample` by a search of the seeds within `radius` metres of the estimate in
    /// x and y, `step` apart, at its heading, with the full scan; the best match is taken when
    /// it is good enough. For a start known to be off by up to `radius`, such as the pose a
    /// climb over a flight of stairs arrives at by dead reckoning. Returns whether a pose was
    /// taken.
    pub fn relocalise_near(&mut self, sample: &Sample, radius: f64, step: f64) -> bool {
        radius.is_finite()
            && step.is_finite()
            && step > 0.0
            && self.localiser.search_near(sample, radius.max(0.0), step)
    }

    /// One cycle for the scan and odometry in `sample`, toward `goal` (map frame: a position,
    /// or a [`Goal`] with a final heading).
    ///
    /// # Errors
    /// [`NavError::NonFiniteGoal`] for a goal that is not a finite point or heading
    /// (checked before anything else); [`NavError::Planner`] when the planner fails,
    /// [`NavError::InvalidPath`] or [`NavError::PathEndpoints`] when its path cannot be walked
    /// from here to the goal, and [`NavError::NavigationGrid`] when the live layer refuses the scan
    /// (out-of-order stamps), which the navigator's own checks rule out in normal use.
    pub fn step(
        &mut self,
        sample: &Sample,
        goal: impl Into<Goal>,
    ) -> Result<NavigationStep, NavError> {
        let goal = goal.into();
        let target = goal.position;
        if !(target.x.is_finite()
            && target.y.is_finite()
            && goal.heading.is_none_or(f64::is_finite))
        {
            return Err(NavError::NonFiniteGoal {
                x: target.x,
                y: target.y,
            });
        }
        if self.planned_for != Some(target) {
            self.stuck.reset();
            self.plan.clear();
            self.detour.new_goal();
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
                self.plan.clear_waypoints();
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
        let heading_error = goal.heading.map_or(0.0, |h| wrap_angle(h - yaw));
        if distance <= self.config.goal_tolerance
            && heading_error.abs() <= self.config.heading_tolerance
        {
            self.plan.clear_waypoints();
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
                self.plan.clear_path();
                let command = VelocityCommand::new(-self.config.stuck.backoff_speed, 0.0);
                return Ok(NavigationStep::Walk(command));
            }
            StuckState::Blocked => {
                self.plan.clear_waypoints();
                self.stuck.reset();
                return Ok(NavigationStep::Blocked);
            }
        }
        if let Some(answer) =
            self.replan_if_needed(position, target, fused.then_some(sample.stamp))?
        {
            return Ok(answer);
        }
        self.plan.pass(position, 0.5 * self.config.goal_tolerance);
        let controller = Controller {
            config: &self.config,
            limits: &self.limits,
        };
        let command = if distance <= self.config.goal_tolerance {
            // In place: only the heading is left.
            controller.turn(heading_error)
        } else if distance <= self.config.approach_distance && self.plan.waypoints().len() == 1 {
            controller.approach(&pose, target)
        } else {
            controller.follow(
                self.planning.blocked(),
                self.plan.waypoints(),
                position,
                yaw,
            )
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
    ) -> Result<Option<NavigationStep>, NavError> {
        self.cycles_since_plan += 1;
        let path = &self.plan.path().cells;
        let blocked = self.plan.has_path() && self.planning.blocks_any(path);
        let replan =
            !self.plan.has_path() || blocked || self.cycles_since_plan >= self.config.replan_every;
        if !replan {
            self.detour.path_clear();
            return Ok(None);
        }
        if blocked {
            self.detour.remember_blockage(self.planning.blocked(), path);
        }
        let mut plan = self.search(position, target)?;
        // A periodic replan back through a place that blocked an earlier path to this goal:
        // the current path, still clear, stands (its waypoints made afresh from here).
        if !blocked
            && self.plan.has_path()
            && plan.as_ref().is_some_and(|p| {
                self.detour
                    .passes_blockage(self.planning.blocked(), &p.path().cells)
            })
        {
            // Joined from here by a short plan to the path's nearest cell (none: the path is
            // out of reach from here, and the fresh plan is taken).
            if let Some((at, centre)) = self.plan.nearest_cell(self.planning.blocked(), position)
                && let Some(connection) = dense_path(
                    &self.planning,
                    &mut self.planner,
                    &mut self.memory,
                    position,
                    centre,
                )?
            {
                let clearance = self.config.shortcut_clearance;
                self.plan
                    .follow_on(&self.planning, clearance, connection, at, target);
                self.cycles_since_plan = 0;
                self.detour.path_clear();
                return Ok(None);
            }
        }
        let mut waiting = self.waiting_for(position, target, plan.as_ref())?;
        // What blocks the way and this scan does not see (a person who walked past close by,
        // under the lowest beam: nothing clears those cells from here) is not waited for: it
        // is forgotten and the way planned again. Anything still there is seen again.
        if let (Some(wait), Some(stamp)) = (&waiting, fused_at)
            && let Some(blockers) = unseen_blockers(
                &self.live,
                &wait.cells,
                (
                    self.config.planning.inflation,
                    self.config.planning.point_margin,
                ),
            )
        {
            self.forget(&blockers, stamp)?;
            plan = self.search(position, target)?;
            waiting = self.waiting_for(position, target, plan.as_ref())?;
        }
        // Something new stands in the way and the way around is far longer (or there is
        // none): wait for it to move on, while it moves. The next cycle plans again.
        if let Some(wait) = waiting
            && self
                .detour
                .keeps_waiting(wait.blockage, target, plan.is_some())
        {
            self.stuck.commanded(&VelocityCommand::new(0.0, 0.0));
            return Ok(Some(NavigationStep::Hold));
        }
        self.detour.stop_waiting();
        if let Some(plan) = plan {
            self.plan = plan;
            self.planned_for = Some(target);
            self.cycles_since_plan = 0;
            self.replans += 1;
            return Ok(None);
        }
        self.plan.clear();
        // "No path" from an estimate the last scan did not confirm may be the estimate's
        // fault: stand and localise first.
        if self.localiser.health().consecutive_failures > 0 {
            return Ok(Some(NavigationStep::Hold));
        }
        Ok(Some(NavigationStep::NoPath))
    }

    /// A plan from `position` to `goal` on the live planning grid (see [`Plan::search`]).
    fn search(
        &mut self,
        position: Vector2<f64>,
        goal: Vector2<f64>,
    ) -> Result<Option<Plan>, NavError> {
        Plan::search(
            &self.planning,
            &mut self.planner,
            &mut self.memory,
            self.config.shortcut_clearance,
            position,
            goal,
        )
    }

    /// What there is to wait for on the way to `target`, given the live `plan` (see
    /// [`DetourPolicy::waiting_for`]).
    fn waiting_for(
        &mut self,
        position: Vector2<f64>,
        target: Vector2<f64>,
        plan: Option<&Plan>,
    ) -> Result<Option<Wait>, NavError> {
        self.detour.waiting_for(
            &self.planning,
            &self.static_planning,
            (&mut self.planner, &mut self.static_memory),
            position,
            target,
            plan,
        )
    }

    /// Return `cells` to the static map's state in the live layer (at `stamp`, seconds) and
    /// refresh the planning grid there.
    fn forget(&mut self, cells: &[Cell], stamp: f64) -> Result<(), NavError> {
        self.mark(cells, stamp, |live, c| live.static_map().state(c))
    }

    /// Fuse the scan (at the corrected `pose`) into the live layer and refresh the planning grid
    /// where it changed.
    fn fuse(&mut self, sample: &Sample, pose: &Pose3) -> Result<(), NavError> {
        // Levelled on the map's floor: the estimate's height (and tilt, without the odometry's
        // gravity) are its weakest part, and the live layer tells obstacles from floor by height.
        let map_t_lidar = level_on_floor(
            &sample.cloud,
            &(pose * sample.body_t_lidar),
            self.map.floor(),
            self.config.localiser.odometry_gravity,
        );
        let update = self
            .live
            .update(&sample.cloud, &map_t_lidar, self.map.floor(), sample.stamp)
            .map_err(NavError::NavigationGrid)?;
        if let Some(changed) = update.changed {
            self.refresh(changed)?;
        }
        Ok(())
    }

    fn refresh(&mut self, changed: CellRect) -> Result<(), NavError> {
        self.planning
            .refresh(self.live.combined(), changed)
            .map_err(NavError::NavigationGrid)?;
        Ok(())
    }

    /// Mark the cells just ahead of the body (0.3-0.6 m ahead, 0.5 m wide) as occupied in the
    /// live layer: what the robot could not walk through.
    fn mark_ahead(&mut self, pose: &Pose3, stamp: f64) -> Result<(), NavError> {
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
        self.mark(&cells, stamp, |_, _| CellState::Occupied)
    }

    /// Set each of `cells` to its `state` in the live layer (at `stamp`, seconds) and refresh
    /// the planning grid where that changed it.
    fn mark(
        &mut self,
        cells: &[Cell],
        stamp: f64,
        state: impl Fn(&LiveLayer, Cell) -> CellState,
    ) -> Result<(), NavError> {
        let mut changed = CellRect {
            x0: 0,
            y0: 0,
            x1: 0,
            y1: 0,
        };
        for &c in cells {
            let update = self
                .live
                .mark(c, state(&self.live, c), stamp)
                .map_err(NavError::NavigationGrid)?;
            if let Some(r) = update.changed {
                changed = changed.union(&r);
            }
        }
        self.refresh(changed)
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
        self.plan.waypoints()
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

    /// The planner it plans with.
    #[must_use]
    pub fn planner(&self) -> &P {
        &self.planner
    }

    /// The planner it plans with, to change between goals (its memory on the grids stays).
    #[must_use]
    pub fn planner_mut(&mut self) -> &mut P {
        &mut self.planner
    }

    /// The registrator it localises with.
    #[must_use]
    pub fn registrator(&self) -> &R {
        self.localiser.registrator()
    }

    /// Its settings.
    #[must_use]
    pub fn config(&self) -> &NavigatorConfig {
        &self.config
    }

    /// The map it was given (occupancy and floor), without what the scans changed since (see
    /// [`Navigator::live`]).
    #[must_use]
    pub fn navigation_map(&self) -> &NavigationMap {
        &self.map
    }

    /// The planning grid it plans on: the live occupancy hard-inflated, with each cell's
    /// clearance and step cost ([`Navigator::grid`] is its blocked cells).
    #[must_use]
    pub fn planning_grid(&self) -> &PlanningGrid {
        &self.planning
    }
}

/// The settings, the backends, the estimate and the plan's progress; not the grids and the map.
impl<R, P> std::fmt::Debug for Navigator<R, P>
where
    R: Registrator + std::fmt::Debug,
    P: NavPlanner + std::fmt::Debug,
{
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Navigator")
            .field("config", &self.config)
            .field("registrator", self.localiser.registrator())
            .field("planner", &self.planner)
            .field("pose", &self.pose())
            .field("localisation", &self.localisation())
            .field("goal", &self.planned_for)
            .field("waypoints", &self.waypoints())
            .field("replans", &self.replans)
            .field("recoveries", &self.recoveries)
            .finish_non_exhaustive()
    }
}
