//! The drive to a goal on another floor: a route over the floors' grids and their stairs
//! ([`FloorGraph`]), walked leg by leg: a [`Navigator`] on each floor's map to the next flight's
//! end, a [`StairsClimb`] over the flight, and the next floor's navigator from the pose the
//! climb arrives at, localising against that floor's map.

use nalgebra::{Point3, Vector2};
use slam_core::{PointCloud, Pose3, Registrator};

use crate::nav::config::NavigatorConfig;
use crate::nav::drive::{DriveOutcome, drive};
use crate::nav::floor_maps::FloorMaps;
use crate::nav::floor_route::{FloorCell, FloorGraph, FloorRoute, RouteLeg};
use crate::nav::navigator::Navigator;
use crate::nav::stairs_climb::{ClimbStep, StairsClimb, StairsClimbConfig};
use crate::nav::{DriveError, NavError};
use crate::robot::Robot;

/// Scans a floor's navigator localises on, standing, after a climb: the localiser's
/// confirmation of a large correction (3 scans) and two more.
const SETTLE_CYCLES: usize = 3;
/// After a climb the first scan is searched for within this of the dead-reckoned pose
/// (metres; odometry slips on steps: 2-3 % of a 6 m flight)...
const ARRIVAL_SEARCH: f64 = 0.3;
/// ... at seeds this far apart, within a registration's reach of each other.
const ARRIVAL_SEARCH_STEP: f64 = 0.1;

/// `cycles` samples into `navigator` with the robot standing (its commands not sent).
fn settle<R: Robot, G: Registrator, P: crate::nav::NavPlanner>(
    robot: &mut R,
    navigator: &mut Navigator<G, P>,
    target: Vector2<f64>,
    cycles: usize,
) -> Result<(), DriveError<R::Error>> {
    robot.stop().map_err(DriveError::Robot)?;
    for k in 0..cycles {
        let sample = robot.next_sample().map_err(DriveError::Robot)?;
        if k == 0 {
            navigator.relocalise_near(&sample, ARRIVAL_SEARCH, ARRIVAL_SEARCH_STEP);
        }
        navigator
            .step(&sample, target)
            .map_err(DriveError::Navigation)?;
    }
    Ok(())
}

/// A place on a floor: the floor (an index into the floors of a [`FloorMaps`]) and a plan-view
/// point of the map frame (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FloorPoint {
    /// The floor.
    pub floor: usize,
    /// The point.
    pub at: Vector2<f64>,
}

/// How a drive across floors ended.
#[derive(Clone, Debug, PartialEq)]
pub struct FloorsDriveReport {
    /// How it ended ([`DriveOutcome::NoPath`] before moving when no route joins the start and
    /// the goal).
    pub outcome: DriveOutcome,
    /// The route walked (`None` when there was none).
    pub route: Option<FloorRoute>,
    /// Samples taken.
    pub cycles: usize,
    /// The floor the robot ended on, by the route's legs walked.
    pub floor: usize,
    /// Its estimate of the body pose at the end (map frame).
    pub pose: Pose3,
    /// Flights climbed or descended.
    pub flights: usize,
}

/// Drive `robot`, whose body is at `map_t_body` on floor `start_floor`, to `goal`, over the
/// floors of `maps` (each floor's localisation cloud `clouds[k]`, map frame), localising with
/// `registrator` and navigating each floor with `config`, climbing with `climb`; at most
/// `max_cycles` samples in all. The robot is stopped however the drive ends.
///
/// # Errors
/// [`DriveError::Navigation`] with [`NavError::NoSuchFloor`] for a start or goal floor (or a
/// cloud) that the maps do not have or that has no map, [`NavError::OffFloorMap`] for a start
/// or goal off its floor's grid, [`NavError::NonFiniteGoal`] for one not finite, or what a floor's navigator or the climb refuses;
/// [`DriveError::Robot`] when the robot fails.
#[allow(clippy::too_many_arguments)] // the parts of one drive
pub fn drive_across_floors<R: Robot, G: Registrator + Clone>(
    robot: &mut R,
    maps: &FloorMaps,
    clouds: &[PointCloud],
    registrator: &G,
    config: &NavigatorConfig,
    climb: StairsClimbConfig,
    (start_floor, map_t_body): (usize, Pose3),
    goal: FloorPoint,
    max_cycles: usize,
) -> Result<FloorsDriveReport, DriveError<R::Error>> {
    let nav = DriveError::Navigation;
    let floors = maps.floors().levels().len();
    let grids: Vec<_> = (0..floors)
        .map(|k| {
            maps.planning(k).ok_or(NavError::NoSuchFloor {
                what: "a floor with a map",
                floor: k,
                floors,
            })
        })
        .collect::<Result<_, _>>()
        .map_err(nav)?;
    if clouds.len() < floors {
        return Err(nav(NavError::NoSuchFloor {
            what: "a floor's localisation cloud",
            floor: clouds.len(),
            floors,
        }));
    }
    let cell_of = |what: &'static str, floor: usize, at: Vector2<f64>| {
        let grid = grids.get(floor).ok_or(NavError::NoSuchFloor {
            what,
            floor,
            floors,
        })?;
        if !(at.x.is_finite() && at.y.is_finite()) {
            return Err(NavError::NonFiniteGoal { x: at.x, y: at.y });
        }
        let cell = grid.cell_at(at).ok_or(NavError::OffFloorMap {
            what,
            floor,
            x: at.x,
            y: at.y,
        })?;
        Ok::<_, NavError>(FloorCell { floor, cell })
    };
    let start =
        cell_of("the start", start_floor, map_t_body.translation.vector.xy()).map_err(nav)?;
    let end = cell_of("the goal", goal.floor, goal.at).map_err(nav)?;
    let graph = FloorGraph::new(grids.clone(), maps.links().to_vec()).map_err(nav)?;
    let route = graph.route(start, end).map_err(nav)?;
    let report = FloorsDriveReport {
        outcome: DriveOutcome::NoPath,
        route: route.clone(),
        cycles: 0,
        floor: start_floor,
        pose: map_t_body,
        flights: 0,
    };
    let Some(route) = route else {
        robot.stop().map_err(DriveError::Robot)?;
        return Ok(report);
    };
    let mut legs = Legs {
        robot,
        maps,
        clouds,
        registrator,
        config,
        climb,
        max_cycles,
        report,
        odometry: None,
    };
    for (k, leg) in route.legs.iter().enumerate() {
        let done = match *leg {
            RouteLeg::Walk { floor, to, .. } => {
                let target = if k + 1 == route.legs.len() {
                    goal.at
                } else {
                    grids[floor].cell_center(to)
                };
                legs.walk(floor, target, k > 0)?
            }
            RouteLeg::Stairs { link, up } => legs.stairs(link, up)?,
        };
        if !done {
            return Ok(legs.report);
        }
    }
    legs.report.outcome = DriveOutcome::Arrived;
    Ok(legs.report)
}

/// A drive across floors under way: its parts, and the report so far.
struct Legs<'a, R: Robot, G> {
    robot: &'a mut R,
    maps: &'a FloorMaps,
    clouds: &'a [PointCloud],
    registrator: &'a G,
    config: &'a NavigatorConfig,
    climb: StairsClimbConfig,
    max_cycles: usize,
    report: FloorsDriveReport,
    /// The odometry when `report.pose` was taken (none before the first sample).
    odometry: Option<Pose3>,
}

impl<R: Robot, G: Registrator + Clone> Legs<'_, R, G> {
    /// Walk on `floor` to `target` with that floor's navigator from the pose so far, after a
    /// search near it and a few scans standing when `after_stairs`. Whether it arrived (the
    /// report's outcome says why not).
    fn walk(
        &mut self,
        floor: usize,
        target: Vector2<f64>,
        after_stairs: bool,
    ) -> Result<bool, DriveError<R::Error>> {
        let nav = DriveError::Navigation;
        let Some(Ok(map)) = self.maps.map(floor) else {
            return Err(nav(NavError::NoSuchFloor {
                what: "a floor with a map",
                floor,
                floors: self.maps.floors().levels().len(),
            }));
        };
        let mut navigator = Navigator::new(
            self.registrator.clone(),
            &self.clouds[floor],
            map,
            self.report.pose,
            self.robot.description(),
            self.config.clone(),
        )
        .map_err(nav)?;
        if let Some(odom) = self.odometry {
            navigator = navigator.with_start_odometry(odom).map_err(nav)?;
        }
        let left = self.max_cycles.saturating_sub(self.report.cycles);
        if after_stairs {
            // Off a flight: the climb's dead reckoning is centimetres off (odometry slips on
            // steps), more than the localiser takes from one scan and sometimes beyond a
            // registration's reach. Standing, a search near it finds the pose and the next
            // scans confirm it before the walk starts.
            let cycles = SETTLE_CYCLES.min(left);
            settle(self.robot, &mut navigator, target, cycles)?;
            self.report.cycles += cycles;
        }
        let left = self.max_cycles.saturating_sub(self.report.cycles);
        let mut odometry = self.odometry;
        let walked = drive(self.robot, &mut navigator, target, left, |c| {
            odometry = Some(c.sample.odom_t_body);
        })?;
        self.odometry = odometry;
        self.report.cycles += walked.cycles;
        self.report.pose = navigator.pose();
        self.report.floor = floor;
        self.report.outcome = walked.outcome;
        Ok(walked.outcome == DriveOutcome::Arrived)
    }

    /// Over the flight of `link`, up or down, with a [`StairsClimb`] from the pose so far.
    /// Whether it arrived at the far end.
    fn stairs(&mut self, link: usize, up: bool) -> Result<bool, DriveError<R::Error>> {
        let mut walk: Vec<Point3<f64>> = self.maps.link_walk(link).unwrap_or(&[]).to_vec();
        if !up {
            walk.reverse();
        }
        let odom = match self.odometry {
            Some(odom) => odom,
            None => {
                self.robot
                    .next_sample()
                    .map_err(DriveError::Robot)?
                    .odom_t_body
            }
        };
        let mut controller = StairsClimb::new(&walk, self.report.pose, odom, self.climb)
            .map_err(DriveError::Navigation)?;
        let left = self.max_cycles.saturating_sub(self.report.cycles);
        let mut arrived = false;
        let mut latest = odom;
        let result = (|| {
            for _ in 0..left {
                let sample = self.robot.next_sample().map_err(DriveError::Robot)?;
                self.report.cycles += 1;
                latest = sample.odom_t_body;
                match controller.step(&latest) {
                    ClimbStep::Walk(command) => {
                        self.robot.send(&command).map_err(DriveError::Robot)?;
                    }
                    ClimbStep::Arrived => {
                        arrived = true;
                        break;
                    }
                }
            }
            Ok(())
        })();
        let stopped = self.robot.stop().map_err(DriveError::Robot);
        result?;
        stopped?;
        self.odometry = Some(latest);
        if !arrived {
            self.report.pose = controller.pose(&latest);
            self.report.outcome = DriveOutcome::GaveUp;
            return Ok(false);
        }
        self.report.pose = controller.level_pose(&latest);
        let l = self.maps.links()[link];
        self.report.floor = if up { l.top.floor } else { l.foot.floor };
        self.report.flights += 1;
        Ok(true)
    }
}
