//! The exploration loop: a [`Robot`] with no map and no route, the Graph-SLAM engine mapping
//! live, and the [`Explorer`] sending the [`Navigator`] to one frontier after another until no
//! reachable frontier is left.

use std::time::Instant;

use gridmap::{OccupancyGrid, PlanningGrid};
use nalgebra::Vector2;
use slam_core::{GraphSlam, MapRegistrator, Optimizer, PointCloud, Pose3, Registrator};

use crate::nav::NavError;
use crate::nav::config::NavigatorConfig;
use crate::nav::error::ExplorationError;
use crate::nav::explorer::{
    Explorer, FrontierDecision, FrontierGoal, GiveUpReason, GivenUpFrontier,
};
use crate::nav::explorer_config::ExplorerConfig;
use crate::nav::frontier::is_frontier_cell;
use crate::nav::growing_map::GrowingMap;
use crate::nav::navigation_map::NavigationMap;
use crate::nav::navigator::{Leftovers, Navigator};
use crate::nav::step::NavigationStep;
use crate::robot::{MobilityCommand, Robot, Sample};

/// How an exploration ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum ExplorationOutcome {
    /// No reachable frontier is left.
    Complete,
    /// The cycle budget ran out first.
    GaveUp,
}

/// What an exploration did.
#[derive(Clone, Debug)]
pub struct ExplorationReport {
    /// How it ended.
    pub outcome: ExplorationOutcome,
    /// Samples taken.
    pub cycles: usize,
    /// Frontier decisions made (each on the map grown by the keyframes since the last one, or
    /// rendered afresh: see `full_renders`).
    pub decisions: usize,
    /// Milliseconds of each decision that started a walk: rendering the map, picking the
    /// frontier and making the navigator on that map.
    pub decision_ms: Vec<f64>,
    /// Milliseconds of every decision by stage, summed over the exploration.
    pub decision_stages: DecisionStages,
    /// Decisions whose map was rendered afresh from every keyframe kept (the first, after a
    /// loop closure moved the keyframes, and when the map has grown by half since the last);
    /// the others added only the keyframes that came since.
    pub full_renders: usize,
    /// Length of the body's path as the engine estimated it (metres).
    pub walked: f64,
    /// The frontiers given up on the way, and why.
    pub given_up: Vec<GivenUpFrontier>,
    /// The last decision: the frontiers left and why none was reachable.
    pub last_decision: FrontierDecision,
    /// The map at the end (occupancy from every keyframe at its optimised pose).
    pub navigation: NavigationMap,
    /// The engine's estimate of the body at the end (map frame).
    pub map_t_body: Pose3,
}

/// Where the decisions' time went (milliseconds, summed over every decision).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DecisionStages {
    /// The grid and the map cloud brought up to date with the engine's keyframes.
    pub map: f64,
    /// The planning grid (inflation, clearance cost) made from it.
    pub planning: f64,
    /// The explorer's choice: frontiers, what each would reveal, the walks to them.
    pub choice: f64,
    /// The walk's navigator set up on the map (its localisation target, its live layer).
    pub navigator: f64,
}

/// One cycle of an exploration, as [`explore`] shows it to its observer.
#[derive(Clone, Copy, Debug)]
pub struct ExplorationCycle<'a> {
    /// The sample the cycle ran on.
    pub sample: &'a Sample,
    /// The frontier goal being walked to (metres, map frame).
    pub goal: Vector2<f64>,
    /// What the navigator decided.
    pub step: &'a NavigationStep,
    /// The engine's estimate of the body after the scan (map frame), when it has one.
    pub map_t_body: Option<Pose3>,
    /// Milliseconds the engine and the navigator took on the sample, without the robot's own
    /// time (the decisions between walks are in [`ExplorationReport::decision_ms`]).
    pub compute_ms: f64,
    /// Floor known free on the grid of the decision that started the walk (square metres):
    /// how far the exploration has got.
    pub known_free_m2: f64,
}

/// Explore with `robot` from where it stands: each sample goes into `slam` (a fresh engine: its
/// map frame is the first scan's odometry frame); after every
/// [`ExplorerConfig::decide_every`] new keyframes, a closed loop, or the end of a walk, the
/// occupancy grid is brought up to date (the keyframes since the last decision added to it, or
/// all of them rendered afresh at their current poses when a loop moved one by more than half a
/// cell or the map grew by half since the last such render), the [`Explorer`]
/// picks a frontier, and a [`Navigator`] on that map (localising with `localiser` against the
/// map within [`ExplorerConfig::localise_within`] of the robot, settings `navigator` with its
/// goal tolerance set to [`ExplorerConfig::arrive_within`]) walks toward it (it does not wait
/// for what newly blocks the way: that is unknown space turning out to be wall) until the
/// robot is half that distance from where it started, or one of the above. The second walk near the same goal that ends with no path, blocked or lost gives its
/// frontier up, and so does standing at its goal with the frontier still there; the report
/// lists them. Stops when no reachable frontier is left, or after `max_cycles` samples; the
/// robot is sent a stop on every way out.
///
/// # Errors
/// [`ExplorationError::Robot`] when the robot fails, [`ExplorationError::Navigation`] for
/// invalid settings or when the navigator or the map fails, [`ExplorationError::Map`] when the
/// engine's map cloud cannot be made, [`ExplorationError::NoMap`] when the engine kept none of
/// the scans within the budget; the robot was sent a stop first.
pub fn explore<Rb, R, C, O, L>(
    robot: &mut Rb,
    slam: &mut GraphSlam<R, C, O>,
    localiser: &L,
    navigator: &NavigatorConfig,
    config: &ExplorerConfig,
    max_cycles: usize,
    mut observe: impl FnMut(&ExplorationCycle<'_>),
) -> Result<ExplorationReport, ExplorationError<Rb::Error>>
where
    Rb: Robot,
    R: MapRegistrator,
    C: MapRegistrator,
    O: Optimizer<Pose3>,
    L: Registrator + Clone,
{
    let result = Exploration::new(navigator, config)
        .and_then(|mut e| e.run(robot, slam, localiser, max_cycles, &mut observe));
    let stopped = robot.stop().map_err(ExplorationError::Robot);
    let report = result?;
    stopped?;
    Ok(report)
}

/// The loop's state between walks.
struct Exploration {
    navigator: NavigatorConfig,
    explorer: Explorer,
    cycles: usize,
    decisions: usize,
    decision_ms: Vec<f64>,
    stages: DecisionStages,
    walked: f64,
    last_position: Option<Vector2<f64>>,
    /// The goal of the last walk, when it ended there.
    arrived_at: Option<Vector2<f64>>,
    /// Goals a walk failed to once.
    failures: Vec<Vector2<f64>>,
    /// The odometry of the last sample the engine took.
    last_odometry: Option<Pose3>,
    /// The last decision's occupancy grid and its planning layer: the next decision's layer is
    /// that one refreshed over the cells that changed, when the grid kept its size and place
    /// (a whole layer of the large building cost 16 ms a decision).
    planned_on: Option<(OccupancyGrid, PlanningGrid)>,
    /// What the last walk's navigator left (its live layer, planning grids and planner
    /// memories), for the next walk's to copy its map into: per-cell memory allocated once and
    /// grown with the map, not afresh for every walk among the keyframes the walks add (which
    /// left holes in the heap that the larger grid's no longer fitted).
    leftovers: Option<Leftovers>,
}

/// One walk toward a frontier: where to and from, and how much floor the decision's grid knew
/// free.
struct Walk<'a> {
    target: &'a FrontierGoal,
    known_free_m2: f64,
    /// Where the robot stood at the decision (metres, map frame).
    from: Vector2<f64>,
}

/// Milliseconds from `a` to `b`.
fn ms_between(a: Instant, b: Instant) -> f64 {
    b.duration_since(a).as_secs_f64() * 1e3
}

/// The floor `occupancy` knows free (square metres).
fn known_free_area(occupancy: &OccupancyGrid) -> f64 {
    occupancy.counts().0 as f64 * occupancy.geometry().resolution.powi(2)
}

/// How one walk toward a frontier ended.
enum WalkEnd {
    /// Time to look at the map again (new keyframes, a closed loop, or arrived with the
    /// frontier gone).
    Decide,
    /// At the goal: the next decision shows whether the frontier went.
    Arrived,
    /// The frontier is given up.
    GiveUp(GiveUpReason),
    /// The cycle budget ran out.
    OutOfCycles,
}

impl Exploration {
    fn new<E: std::error::Error + Send + Sync + 'static>(
        navigator: &NavigatorConfig,
        config: &ExplorerConfig,
    ) -> Result<Self, ExplorationError<E>> {
        let navigator = NavigatorConfig {
            goal_tolerance: config.arrive_within,
            // What newly blocks the way to a frontier is unknown space turning out to be wall,
            // not a person passing: not waited for (the next decision sees it).
            detour_patience: 0,
            ..navigator.clone()
        };
        navigator.validate().map_err(ExplorationError::Navigation)?;
        Ok(Self {
            navigator,
            explorer: Explorer::new(config.clone()).map_err(ExplorationError::Navigation)?,
            cycles: 0,
            decisions: 0,
            decision_ms: Vec::new(),
            stages: DecisionStages::default(),
            walked: 0.0,
            last_position: None,
            arrived_at: None,
            failures: Vec::new(),
            last_odometry: None,
            planned_on: None,
            leftovers: None,
        })
    }

    fn run<Rb, R, C, O, L>(
        &mut self,
        robot: &mut Rb,
        slam: &mut GraphSlam<R, C, O>,
        localiser: &L,
        max_cycles: usize,
        observe: &mut impl FnMut(&ExplorationCycle<'_>),
    ) -> Result<ExplorationReport, ExplorationError<Rb::Error>>
    where
        Rb: Robot,
        R: MapRegistrator,
        C: MapRegistrator,
        O: Optimizer<Pose3>,
        L: Registrator + Clone,
    {
        let geometry = &robot.description().geometry;
        let lidar_height = geometry.body_height + geometry.body_t_lidar.translation.z;
        // The first scans, standing: the engine needs one to start its map.
        let mut body_t_lidar = geometry.body_t_lidar;
        while slam.current_lidar_pose().is_none() {
            if self.cycles >= max_cycles {
                return Err(ExplorationError::NoMap {
                    cycles: self.cycles,
                });
            }
            let sample = robot.next_sample().map_err(ExplorationError::Robot)?;
            self.cycles += 1;
            body_t_lidar = sample.body_t_lidar;
            slam.process(&sample.scan_input());
            self.last_odometry = Some(sample.odom_t_body);
        }
        let explorer = self.explorer.config();
        let mut map = GrowingMap::new(
            self.navigator.map_config(),
            lidar_height,
            explorer.keyframe_spacing,
            explorer.map_voxel,
            explorer.sensor_range,
        );
        loop {
            let started = Instant::now();
            let map_t_body = slam
                .current_lidar_pose()
                .map_or_else(Pose3::identity, |p| p * body_t_lidar.inverse());
            let navigation = map.update(slam)?;
            let position = map_t_body.translation.vector.xy();
            let cloud = map.cloud_within(position, self.explorer.config().localise_within);
            let mapped = Instant::now();
            self.stages.map += ms_between(started, mapped);
            let (planned_on, planning) = self
                .planning_layer(navigation.occupancy())
                .map_err(|e| ExplorationError::Navigation(NavError::NavigationGrid(e)))?;
            let planned = Instant::now();
            self.stages.planning += ms_between(mapped, planned);
            let decision = self
                .explorer
                .decide(navigation.occupancy(), &planning, position);
            self.decisions += 1;
            let chosen_at = Instant::now();
            self.stages.choice += ms_between(planned, chosen_at);
            // The robot stood at this goal and the frontier is still there: what lies behind
            // it cannot be seen from where the robot can stand.
            let arrived_at = self.arrived_at.take();
            if let (Some(at), Some(chosen)) = (arrived_at, &decision.chosen)
                && (chosen.goal - at).norm() <= self.explorer.config().give_up_radius
            {
                self.explorer
                    .give_up(chosen.goal, GiveUpReason::StillUnknownFromGoal);
                self.planned_on = Some((planned_on, planning));
                continue;
            }
            let Some(chosen) = decision.chosen.clone() else {
                return Ok(self.report(
                    ExplorationOutcome::Complete,
                    decision,
                    navigation,
                    map_t_body,
                    map.full_renders(),
                ));
            };
            if self.cycles >= max_cycles {
                return Ok(self.report(
                    ExplorationOutcome::GaveUp,
                    decision,
                    navigation,
                    map_t_body,
                    map.full_renders(),
                ));
            }
            let walker = self.walker(localiser, &cloud, &navigation, &planning, map_t_body, robot);
            self.planned_on = Some((planned_on, planning));
            let mut walker = walker.map_err(ExplorationError::Navigation)?;
            self.stages.navigator += chosen_at.elapsed().as_secs_f64() * 1e3;
            self.decision_ms.push(started.elapsed().as_secs_f64() * 1e3);
            let walk = Walk {
                target: &chosen,
                known_free_m2: known_free_area(navigation.occupancy()),
                from: position,
            };
            let end = self.walk(robot, slam, &mut walker, &walk, max_cycles, observe)?;
            self.leftovers = Some(walker.into_leftovers());
            match end {
                WalkEnd::Decide => {}
                WalkEnd::Arrived => self.arrived_at = Some(chosen.goal),
                WalkEnd::GiveUp(reason) => self.failed(chosen.goal, reason),
                WalkEnd::OutOfCycles => {
                    robot.stop().map_err(ExplorationError::Robot)?;
                    return Ok(self.report(
                        ExplorationOutcome::GaveUp,
                        decision,
                        navigation,
                        map_t_body,
                        map.full_renders(),
                    ));
                }
            }
        }
    }

    /// The planning layer of `occupancy` with `occupancy` (taken out of `planned_on`, to be put
    /// back when the decision is done with it): the last decision's refreshed over the cells
    /// that changed since (the same layer as one built whole: `PlanningGrid::refresh`), or
    /// built whole when the grid grew or moved.
    fn planning_layer(
        &mut self,
        occupancy: &OccupancyGrid,
    ) -> Result<(OccupancyGrid, PlanningGrid), gridmap::GridMapError> {
        if let Some((mut earlier, mut layer)) = self.planned_on.take()
            && let Ok(changed) = occupancy.changed_from(&earlier)
        {
            layer.refresh(occupancy, changed)?;
            earlier.clone_from(occupancy);
            return Ok((earlier, layer));
        }
        let layer = PlanningGrid::new(occupancy, self.navigator.planning.clone())?;
        Ok((occupancy.clone(), layer))
    }

    /// The navigator of a walk from `map_t_body`: on the planning grid the frontier was picked
    /// on, localising against `cloud`, the map's points within
    /// [`ExplorerConfig::localise_within`] of the robot (the walk is re-decided before it
    /// leaves that), from the odometry of the last sample.
    fn walker<L: Registrator + Clone, Rb: Robot>(
        &mut self,
        localiser: &L,
        cloud: &PointCloud,
        navigation: &NavigationMap,
        planning: &PlanningGrid,
        map_t_body: Pose3,
        robot: &Rb,
    ) -> Result<Navigator<L>, NavError> {
        let walker = Navigator::planned(
            localiser.clone(),
            cloud,
            navigation,
            planning,
            self.leftovers.take(),
            map_t_body,
            robot.description(),
            self.navigator.clone(),
        )?;
        // The pose is the last sample's: the walk from there on is the odometry's.
        match self.last_odometry {
            Some(odom_t_body) => walker.with_start_odometry(odom_t_body),
            None => Ok(walker),
        }
    }

    /// A walk to `goal` failed for `reason`: the second failure near the same goal gives its
    /// frontier up. Once is not enough: the goal of a frontier sits on the edge of what is
    /// known, and the first scans of a walk often show a wall there that makes the next
    /// decision pick another goal anyway.
    fn failed(&mut self, goal: Vector2<f64>, reason: GiveUpReason) {
        let radius = self.explorer.config().give_up_radius;
        if let Some(k) = self
            .failures
            .iter()
            .position(|f| (f - goal).norm() <= radius)
        {
            self.failures.swap_remove(k);
            self.explorer.give_up(goal, reason);
        } else {
            self.failures.push(goal);
        }
    }

    /// Walk toward `walk.target`'s goal until it is time to decide again.
    fn walk<Rb, R, C, O, L>(
        &mut self,
        robot: &mut Rb,
        slam: &mut GraphSlam<R, C, O>,
        navigator: &mut Navigator<L>,
        walk: &Walk<'_>,
        max_cycles: usize,
        observe: &mut impl FnMut(&ExplorationCycle<'_>),
    ) -> Result<WalkEnd, ExplorationError<Rb::Error>>
    where
        Rb: Robot,
        R: MapRegistrator,
        C: MapRegistrator,
        O: Optimizer<Pose3>,
        L: Registrator,
    {
        let keyframes = slam.keyframe_count();
        let loops = slam.report().loops_closed;
        let target = walk.target;
        let goal = target.goal;
        let min_cells = self.explorer.config().min_frontier_cells;
        while self.cycles < max_cycles {
            let sample = robot.next_sample().map_err(ExplorationError::Robot)?;
            self.cycles += 1;
            let started = Instant::now();
            slam.process(&sample.scan_input());
            self.last_odometry = Some(sample.odom_t_body);
            let step = navigator
                .step(&sample, goal)
                .map_err(ExplorationError::Navigation)?;
            let compute_ms = started.elapsed().as_secs_f64() * 1e3;
            let map_t_body = slam
                .current_lidar_pose()
                .map(|p| p * sample.body_t_lidar.inverse());
            if let Some(p) = map_t_body {
                let here = p.translation.vector.xy();
                self.walked += self.last_position.map_or(0.0, |l| (here - l).norm());
                self.last_position = Some(here);
            }
            observe(&ExplorationCycle {
                sample: &sample,
                goal,
                step: &step,
                map_t_body,
                compute_ms,
                known_free_m2: walk.known_free_m2,
            });
            let end = match step {
                NavigationStep::Walk(command) => {
                    robot
                        .send(&MobilityCommand::Velocity(command))
                        .map_err(ExplorationError::Robot)?;
                    None
                }
                NavigationStep::Hold => {
                    robot.stop().map_err(ExplorationError::Robot)?;
                    None
                }
                NavigationStep::Arrived => Some(WalkEnd::Arrived),
                NavigationStep::NoPath => Some(WalkEnd::GiveUp(GiveUpReason::NoPath)),
                NavigationStep::Blocked => Some(WalkEnd::GiveUp(GiveUpReason::Blocked)),
                NavigationStep::Lost => Some(WalkEnd::GiveUp(GiveUpReason::Lost)),
            };
            if let Some(end) = end {
                robot.stop().map_err(ExplorationError::Robot)?;
                return Ok(end);
            }
            // The frontier seen on the way (the navigator's live layer fuses every scan): no
            // need to walk on to it.
            let left = target
                .frontier
                .cells
                .iter()
                .filter(|&&c| is_frontier_cell(navigator.live().combined(), c))
                .count();
            if left < min_cells {
                return Ok(WalkEnd::Decide);
            }
            let grown = slam.keyframe_count() >= keyframes + self.explorer.config().decide_every;
            // Half the navigator's map behind: its far side would soon be out of sight.
            let far = map_t_body.is_some_and(|p| {
                (p.translation.vector.xy() - walk.from).norm()
                    > 0.5 * self.explorer.config().localise_within
            });
            if grown || far || slam.report().loops_closed != loops {
                return Ok(WalkEnd::Decide);
            }
        }
        Ok(WalkEnd::OutOfCycles)
    }

    fn report(
        &self,
        outcome: ExplorationOutcome,
        last_decision: FrontierDecision,
        navigation: NavigationMap,
        map_t_body: Pose3,
        full_renders: usize,
    ) -> ExplorationReport {
        ExplorationReport {
            outcome,
            cycles: self.cycles,
            decisions: self.decisions,
            decision_ms: self.decision_ms.clone(),
            decision_stages: self.stages,
            full_renders,
            walked: self.walked,
            given_up: self.explorer.given_up().to_vec(),
            last_decision,
            navigation,
            map_t_body,
        }
    }
}
