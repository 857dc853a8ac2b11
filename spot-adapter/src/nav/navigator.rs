//! `Navigator`: walks the robot to a goal in a mapped building. Each cycle it localises the live
//! scan against the map, replans on the map's occupancy grid, and turns the first leg of the
//! filtered path into a velocity command.

use gridmap::{OccupancyGridBuilder, OccupancyGridConfig, inflate};
use nalgebra::Vector2;
use pathfind::{AStar, JumpPointSearch, filter_path};
use slam_core::{BitGrid, Cell, Planner, PointCloud, Pose3, Registrator};

use crate::error::AdapterError;
use crate::nav::localiser::{LocalisationHealth, LocalisationStatus, Localiser, LocaliserConfig};
use crate::nav::stuck::{StuckConfig, StuckMonitor, StuckState};
use crate::robot::{MotionLimits, RobotDescription, Sample, VelocityCommand};

/// Settings of [`Navigator`]. Lengths in metres, angles in radians, speeds per second.
#[derive(Clone, Debug, PartialEq)]
pub struct NavigatorConfig {
    /// The occupancy grid of the map (0.10 m cells, the slice 0.2 m either side of the LiDAR).
    pub grid: OccupancyGridConfig,
    /// Obstacles are inflated by this much: the robot's half width (0.25 m) and a margin for
    /// localisation and control error, 0.40 m.
    pub clearance: f64,
    /// Arrived when the estimated body is this close to the goal, 0.05 m (localisation is good
    /// to a few centimetres, so the true body ends within 0.10 m).
    pub goal_tolerance: f64,
    /// ... and, for a goal with a heading, faces it this closely, 0.1 rad.
    pub heading_tolerance: f64,
    /// Within this distance of the goal, with nothing in between, the robot walks straight at it
    /// sideways and forwards without turning (Spot walks in any direction), 0.6 m.
    pub approach_distance: f64,
    /// Speed of that final approach per metre still to go, 1.5 /s, ...
    pub approach_gain: f64,
    /// ... and at most this, 0.3 m/s.
    pub approach_speed: f64,
    /// Turn in place while the heading error to the next waypoint exceeds this, 0.5 (29°).
    pub turn_in_place_above: f64,
    /// Walking speed, 0.6 m/s (the simulated Spot's).
    pub speed: f64,
    /// Turn rate per radian of heading error, 1.5 /s (capped at the robot's limit).
    pub heading_gain: f64,
    /// The planner on the navigation grid (Jump Point Search).
    pub planner: PlannerKind,
    /// Localisation against the map: corrections, health, the wide search when lost.
    pub localiser: LocaliserConfig,
    /// What counts as stuck and how the robot gets free.
    pub stuck: StuckConfig,
}

impl Default for NavigatorConfig {
    fn default() -> Self {
        Self {
            grid: OccupancyGridConfig::default(),
            clearance: 0.40,
            goal_tolerance: 0.05,
            heading_tolerance: 0.1,
            approach_distance: 0.6,
            approach_gain: 1.5,
            approach_speed: 0.3,
            turn_in_place_above: 0.5,
            speed: 0.6,
            heading_gain: 1.5,
            planner: PlannerKind::default(),
            localiser: LocaliserConfig::default(),
            stuck: StuckConfig::default(),
        }
    }
}

impl NavigatorConfig {
    /// Every length, angle, speed and gain finite and positive; the localiser's and the stuck
    /// monitor's settings valid.
    ///
    /// # Errors
    /// [`AdapterError::InvalidConfig`] naming the first bad setting.
    pub fn validate(&self) -> Result<(), AdapterError> {
        for (setting, value) in [
            ("clearance", self.clearance),
            ("goal_tolerance", self.goal_tolerance),
            ("heading_tolerance", self.heading_tolerance),
            ("approach_distance", self.approach_distance),
            ("approach_gain", self.approach_gain),
            ("approach_speed", self.approach_speed),
            ("turn_in_place_above", self.turn_in_place_above),
            ("speed", self.speed),
            ("heading_gain", self.heading_gain),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(AdapterError::invalid(setting, value, "finite and positive"));
            }
        }
        self.localiser.validate()?;
        self.stuck.validate()
    }
}

/// The grid a [`Navigator`] plans on: the occupancy of `map` (a map cloud whose LiDAR sits
/// `lidar_height` above the frame's origin) with obstacles inflated by `config.clearance`. Built
/// once per map; the navigator borrows it, so its planner labels the grid once, not per cycle.
///
/// # Errors
/// [`AdapterError::InvalidConfig`] for invalid settings, [`AdapterError::NavigationGrid`]
/// (with the grid builder's error as its source) for a grid that cannot be built.
pub fn navigation_grid(
    map: &PointCloud,
    lidar_height: f64,
    config: &NavigatorConfig,
) -> Result<BitGrid, AdapterError> {
    config.validate()?;
    let occupancy = OccupancyGridBuilder::new(config.grid.clone())
        .and_then(|b| b.build(map, lidar_height))
        .map_err(AdapterError::NavigationGrid)?;
    Ok(inflate(occupancy.occupied(), config.clearance))
}

/// The shortest-path planner a [`Navigator`] uses; both are optimal on the grid, Jump Point
/// Search is the faster (pathfind/README.md).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum PlannerKind {
    /// [`JumpPointSearch`] with word scans.
    #[default]
    JumpPointSearch,
    /// [`AStar`] with the octile heuristic.
    AStar,
}

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
/// Each [`Navigator::step`] predicts the body pose from the odometry since the previous scan and
/// corrects it by registering the scan against the map (prepared once; the localiser tracks its
/// health, takes a large correction only once consecutive scans confirm it, and searches wide
/// when the robot seems lost), replans with [`JumpPointSearch`] on the map's inflated occupancy
/// grid and keeps the turning points that a straight collision-free segment cannot skip
/// ([`filter_path`]); then it turns in place while the heading error to the next waypoint is
/// large, walks toward it steering proportionally otherwise, and near the goal walks straight
/// at it (sideways too) ever slower. A robot that makes no progress backs off and tries again,
/// and is reported [`NavigationStep::Blocked`] after a few attempts. A goal that cannot be
/// reached is answered with [`NavigationStep::NoPath`]; nothing loops forever.
pub struct Navigator<'g, R: Registrator> {
    config: NavigatorConfig,
    limits: MotionLimits,
    localiser: Localiser<R>,
    grid: &'g BitGrid,
    planner: Box<dyn Planner + 'g>,
    waypoints: Vec<Vector2<f64>>,
    stuck: StuckMonitor,
}

impl<'g, R: Registrator> Navigator<'g, R> {
    /// A navigator for `robot` on `map` (a map cloud, e.g. [`slam_core::GraphSlam::map`]) and
    /// its `grid` ([`navigation_grid`]), localising with `registrator`, starting from
    /// `map_t_body`. Its commands keep to the robot's motion limits.
    ///
    /// # Errors
    /// [`AdapterError::InvalidConfig`] for invalid settings or limits,
    /// [`AdapterError::LocalisationMap`] (with the registrator's error as its source) for a
    /// map the registrator refuses.
    pub fn new(
        registrator: R,
        map: &PointCloud,
        grid: &'g BitGrid,
        map_t_body: Pose3,
        robot: &RobotDescription,
        config: NavigatorConfig,
    ) -> Result<Self, AdapterError> {
        config.validate()?;
        robot.limits.validate()?;
        let target = registrator
            .prepare_target(map)
            .map_err(AdapterError::LocalisationMap)?;
        Ok(Self {
            localiser: Localiser::new(registrator, target, map_t_body, config.localiser.clone()),
            stuck: StuckMonitor::new(config.stuck.clone()),
            planner: match config.planner {
                PlannerKind::JumpPointSearch => Box::new(JumpPointSearch::new(grid)),
                PlannerKind::AStar => Box::new(AStar::new(grid)),
            },
            config,
            limits: robot.limits.clone(),
            grid,
            waypoints: Vec::new(),
        })
    }

    /// One cycle for the scan and odometry in `sample`, toward `goal` (map frame: a position,
    /// or a [`Goal`] with a final heading).
    ///
    /// # Errors
    /// [`AdapterError::NonFiniteGoal`] for a goal that is not a finite point or heading
    /// (checked before anything else); [`AdapterError::Planner`] when the planner refuses its
    /// arguments, which the navigator's own checks rule out (a defect, not an answer).
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
        match self.localiser.update(sample) {
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
                let command = VelocityCommand::new(-self.config.stuck.backoff_speed, 0.0);
                return Ok(NavigationStep::Walk(command));
            }
            StuckState::Blocked => {
                self.waypoints.clear();
                self.stuck.reset();
                return Ok(NavigationStep::Blocked);
            }
        }
        let Some(waypoints) = self.plan(position, target)? else {
            self.waypoints.clear();
            // "No path" from an estimate the last scan did not confirm may be the estimate's
            // fault: stand and localise first.
            if self.localiser.health().consecutive_failures > 0 {
                return Ok(NavigationStep::Hold);
            }
            return Ok(NavigationStep::NoPath);
        };
        self.waypoints = waypoints;
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

    /// Waypoints (metres) from `position` to `goal` after the start, or `None` when none joins
    /// them (the goal off the map or blocked, the robot off the map, or no path). A start
    /// inside the inflated obstacles (the robot brushed a wall) plans from the nearest free
    /// cell.
    fn plan(
        &mut self,
        position: Vector2<f64>,
        goal: Vector2<f64>,
    ) -> Result<Option<Vec<Vector2<f64>>>, AdapterError> {
        let Some(goal_cell) = self
            .grid
            .cell_at(goal)
            .filter(|&c| !self.grid.is_blocked(c))
        else {
            return Ok(None);
        };
        let Some(start) = self
            .grid
            .cell_at(position)
            .and_then(|c| nearest_free(self.grid, c))
        else {
            return Ok(None);
        };
        let Some(path) = self
            .planner
            .plan(start, goal_cell)
            .map_err(AdapterError::Planner)?
        else {
            return Ok(None);
        };
        let filtered = filter_path(self.grid, &path);
        let mut waypoints: Vec<Vector2<f64>> = filtered
            .waypoints
            .iter()
            .skip(1)
            .map(|&c| self.grid.cell_center(c))
            .collect();
        // The goal itself, not its cell's centre, ends the path.
        if let Some(last) = waypoints.last_mut() {
            *last = goal;
        } else {
            waypoints.push(goal);
        }
        Ok(Some(waypoints))
    }

    /// The command toward the first waypoint that is not already underfoot.
    fn command(&self, position: Vector2<f64>, yaw: f64) -> VelocityCommand {
        let near = 0.5 * self.config.goal_tolerance;
        let target = self
            .waypoints
            .iter()
            .find(|w| (*w - position).norm() > near)
            .or(self.waypoints.last())
            .copied()
            .unwrap_or(position);
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

    /// The planning grid: the map's occupancy with obstacles inflated by the clearance.
    #[must_use]
    pub fn grid(&self) -> &BitGrid {
        self.grid
    }

    /// Cycles whose registration failed, did not converge, matched too little or was an
    /// unconfirmed jump (the odometry's prediction stood).
    #[must_use]
    pub fn localisation_failures(&self) -> usize {
        self.localiser.health().failures
    }
}

/// `angle` wrapped to (-pi, pi].
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
