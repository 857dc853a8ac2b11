//! A simulated Spot driven by motion commands: the closed-loop counterpart of
//! [`SimulatedSpot`](crate::sim::SimulatedSpot), which walks a route fixed in advance.

use nalgebra::{Point3, Translation3, UnitQuaternion, Vector2};
use slam_core::{Pose2, Pose3};

use crate::robot::{
    MobilityCommand, Robot, RobotDescription, Sample, Se2Trajectory, TrajectoryFrame,
    VelocityCommand,
};
use crate::sim::SimError;
use crate::sim::building::Building;
use crate::sim::lidar::SpinningLidar;
use crate::sim::odometry::OdometryModel;
use crate::sim::rng::SimRng;
use crate::sim::simulated_spot::SimulationConfig;
use crate::sim::solid_box::{BoxId, BoxKind, SolidBox};
use crate::sim::stairs_gait::stairs_ground;

/// A box that walks to and fro along a segment (a person crossing a corridor), moved each
/// LiDAR turn.
#[derive(Clone, Debug)]
struct Walker {
    id: BoxId,
    from: Vector2<f64>,
    to: Vector2<f64>,
    speed: f64,
    half_size: Vector2<f64>,
    height: f64,
    /// Arc length travelled, modulo a round trip.
    travelled: f64,
}

impl Walker {
    /// The box where the walker is after `travelled` metres.
    fn solid(&self) -> SolidBox {
        let length = (self.to - self.from).norm();
        let s = self.travelled.rem_euclid(2.0 * length);
        let along = if s <= length { s } else { 2.0 * length - s };
        let c = self.from + (self.to - self.from) * (along / length);
        SolidBox {
            min: Point3::new(c.x - self.half_size.x, c.y - self.half_size.y, 0.0),
            max: Point3::new(c.x + self.half_size.x, c.y + self.half_size.y, self.height),
            kind: BoxKind::Obstacle,
        }
    }
}

/// The command a [`CommandedSpot`] is carrying out.
#[derive(Clone, Debug)]
enum Active {
    /// A velocity, with the stairs mode on or off.
    Velocity(VelocityCommand, bool),
    /// A trajectory in the odometry frame, with the stamp it was sent at.
    Trajectory(Se2Trajectory, f64),
}

/// A simulated Spot that walks where it is told: each [`CommandedSpot::step`] holds a velocity
/// command for one LiDAR turn (0.2 s at 5 Hz), moves the true body, integrates the drifting
/// odometry and casts the next scan. A step that would put the body centre closer than
/// `half_width` to an obstacle (the building's own or one added later) leaves the body where
/// it stands, except for its turn, and counts a collision: a real Spot turns in place where it
/// cannot walk, and its own obstacle avoidance stops it short of a wall.
///
/// It is a [`Robot`]: [`Robot::next_sample`] gives the scan where it stands on the first call
/// and then advances one LiDAR turn under the command in force; [`Robot::send`] takes velocity
/// commands and trajectories in the `odom` frame, which it tracks with its own (drifting)
/// odometry as a real Spot does.
///
/// ```
/// use spot_adapter::robot::VelocityCommand;
/// use spot_adapter::sim::{Building, BuildingConfig, CommandedSpot, SimulationConfig};
///
/// let building = Building::generate(3, &BuildingConfig::default())?;
/// let start = building.corridor_loop()[0];
/// let mut spot = CommandedSpot::new(building, start, 0.0, &SimulationConfig::default())?;
/// let sample = spot.step(VelocityCommand::new(0.5, 0.0));
/// assert!(sample.cloud.len() > 20_000);
/// assert!((spot.position() - start).norm() > 0.09);
/// # Ok::<(), spot_adapter::sim::SimError>(())
/// ```
#[derive(Clone, Debug)]
pub struct CommandedSpot {
    building: Building,
    lidar: SpinningLidar,
    odometry: OdometryModel,
    noise: SimRng,
    description: RobotDescription,
    period: f64,
    stamp: f64,
    world_t_body: Pose2,
    /// The odometry the robot reported last (`odom_T_body`).
    odom_t_body: Pose3,
    collisions: usize,
    active: Active,
    sensed: bool,
    walkers: Vec<Walker>,
    /// The floor the robot stands on (the lower one while on a flight).
    floor: usize,
    /// Height of the ground under the body (metres) and the body's pitch (radians, nose up
    /// positive) on a flight.
    ground: f64,
    pitch: f64,
}

/// Where a step puts the robot: the floor it is on, the ground under it and its pitch.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Footing {
    floor: usize,
    ground: f64,
    pitch: f64,
}

/// On a flight, the body's centre keeps this far inside the flight's sides (metres): its feet
/// stay on the steps.
const FLIGHT_SIDE_MARGIN: f64 = 0.2;

impl CommandedSpot {
    /// Spot standing at plan-view `position` (metres) facing `yaw` (radians) in `building`, with
    /// `config`'s LiDAR, odometry drift, geometry, motion limits and seed.
    ///
    /// # Errors
    /// [`SimError::InvalidConfig`] for invalid LiDAR, odometry or limit settings or a yaw
    /// that is not finite; [`SimError::BlockedEndpoint`] when the start is not free floor
    /// for the robot.
    pub fn new(
        building: Building,
        position: Vector2<f64>,
        yaw: f64,
        config: &SimulationConfig,
    ) -> Result<Self, SimError> {
        let lidar = SpinningLidar::new(config.lidar.clone())?;
        config.limits.validate()?;
        if !yaw.is_finite() {
            return Err(SimError::invalid("yaw", yaw, "finite (radians)"));
        }
        let half_width = config.spot.half_width;
        if !(position.iter().all(|v| v.is_finite()) && building.clearance(position) >= half_width) {
            return Err(SimError::BlockedEndpoint {
                which: "start",
                x: position.x,
                y: position.y,
            });
        }
        Ok(Self {
            building,
            odometry: OdometryModel::new(config.odometry.clone(), config.seed)?,
            noise: SimRng::new(config.seed, 0xc0_4a4d),
            description: RobotDescription::new(config.spot.clone(), config.limits.clone()),
            period: 1.0 / config.lidar.rotation_rate,
            stamp: 0.0,
            world_t_body: Pose2::new(position, yaw),
            odom_t_body: Pose3::identity(),
            collisions: 0,
            active: Active::Velocity(VelocityCommand::default(), false),
            sensed: false,
            walkers: Vec::new(),
            floor: 0,
            ground: 0.0,
            pitch: 0.0,
            lidar,
        })
    }

    /// The scan and odometry where the robot stands now, without moving it (the first sample
    /// of a run).
    pub fn sense(&mut self) -> Sample {
        let world_t_body = self.body_pose();
        self.odom_t_body = self.odometry.step(&world_t_body);
        let body_t_lidar = self.description.geometry.body_t_lidar;
        let world_t_lidar = world_t_body * body_t_lidar;
        self.sensed = true;
        Sample {
            stamp: self.stamp,
            odom_t_body: self.odom_t_body,
            body_t_lidar,
            cloud: self
                .lidar
                .scan_at_rest(&self.building, &world_t_lidar, &mut self.noise),
            ground_truth: Some(world_t_body),
            gyro_orientation: None,
        }
    }

    /// Holds `command` for one LiDAR turn (each component clamped to the motion limits; a
    /// non-finite command stops the robot), then senses. The body moves along the arc the
    /// command describes, unless that would bring it closer than half its width to an
    /// obstacle: then it only turns and a collision is counted.
    pub fn step(&mut self, command: VelocityCommand) -> Sample {
        self.step_with(command, false)
    }

    /// [`CommandedSpot::step`] with the stairs mode on: the robot may walk onto a flight of
    /// stairs rising from or arriving at its floor, facing along it, its body centre at least
    /// 0.2 m inside the flight's sides; on the flight its body rises with the
    /// steps and pitches with them, and past the flight's top (or foot) it stands on the floor
    /// there.
    pub fn step_on_stairs(&mut self, command: VelocityCommand) -> Sample {
        self.step_with(command, true)
    }

    fn step_with(&mut self, command: VelocityCommand, stairs: bool) -> Sample {
        let limits = &self.description.limits;
        let (v, u, w) = if command.is_finite() {
            (
                command
                    .forward
                    .clamp(-limits.max_forward_speed, limits.max_forward_speed),
                command
                    .lateral
                    .clamp(-limits.max_lateral_speed, limits.max_lateral_speed),
                command
                    .yaw_rate
                    .clamp(-limits.max_yaw_rate, limits.max_yaw_rate),
            )
        } else {
            (0.0, 0.0, 0.0)
        };
        let dt = self.period;
        // Exact arc of a constant body velocity: the heading turns by w dt, and the forward
        // and sideways chords follow the mean heading.
        let (yaw, dyaw) = (self.world_t_body.rotation.angle(), w * dt);
        let chord = |speed: f64| {
            if dyaw.abs() < 1e-9 {
                speed * dt
            } else {
                2.0 * speed / w * (0.5 * dyaw).sin()
            }
        };
        let mid = yaw + 0.5 * dyaw;
        let (c, s) = (mid.cos(), mid.sin());
        let next = self.world_t_body.translation.vector
            + chord(v) * Vector2::new(c, s)
            + chord(u) * Vector2::new(-s, c);
        let half_width = self.description.geometry.half_width;
        let footing = if self.building.floors() > 1 {
            self.footing(next, stairs)
        } else {
            (self.building.clearance(next) >= half_width).then_some(Footing {
                floor: 0,
                ground: 0.0,
                pitch: 0.0,
            })
        };
        if let Some(footing) = footing {
            self.world_t_body = Pose2::new(next, yaw + dyaw);
            self.floor = footing.floor;
            self.ground = footing.ground;
            // The body pitches with the slope along its heading.
            self.pitch = footing.pitch;
        } else {
            self.world_t_body = Pose2::new(self.world_t_body.translation.vector, yaw + dyaw);
            self.collisions += 1;
        }
        if !self.walkers.is_empty() {
            for walker in &mut self.walkers {
                walker.travelled += walker.speed * dt;
                // The walker exists (added with its id): moving it cannot fail.
                let _ = self.building.move_box(walker.id, walker.solid());
            }
            // A walker that walks into the robot is a collision too.
            if self.building.clearance(self.position()) < half_width {
                self.collisions += 1;
            }
        }
        self.stamp += dt;
        self.sense()
    }

    /// Where the robot stands at plan-view `next` in a building of several floors, or `None`
    /// when it cannot stand there: on a flight (stairs mode only) or on its floor, clear of the
    /// floor's obstacles by half its width.
    fn footing(&self, next: Vector2<f64>, stairs: bool) -> Option<Footing> {
        let half_width = self.description.geometry.half_width;
        let heading = self.world_t_body.rotation.angle();
        if stairs {
            for (i, f) in self.building.staircases().iter().enumerate() {
                let lower = self.building.floor_of_height(f.base_z);
                let upper = lower + 1;
                if self.floor != lower && self.floor != upper {
                    continue;
                }
                let across = Vector2::new(-f.up.y, f.up.x);
                let d = next - f.foot;
                let (u, side) = (d.dot(&f.up), d.dot(&across));
                // Up to a body length before the foot and past the top: walking onto it.
                if side.abs() > 0.5 * f.width - FLIGHT_SIDE_MARGIN || u < -1.0 || u > f.run() + 1.0
                {
                    continue;
                }
                let on_floor = if u <= 0.0 {
                    lower
                } else if u >= f.run() {
                    upper
                } else {
                    lower
                };
                let clear = if u > 0.0 && u < f.run() {
                    true
                } else {
                    self.building.clearance_on(on_floor, next, Some(i)) >= half_width
                };
                if !clear {
                    return None;
                }
                // The ground follows a line through the step tops, from half a tread before
                // the foot to half a tread past the top (as the floors tour's walk does),
                // With the jolts and the nod of a body taking the steps.
                let ground = stairs_ground(f, u);
                let along = Vector2::new(heading.cos(), heading.sin()).dot(&f.up);
                return Some(Footing {
                    floor: if u >= f.run() + 0.5 * f.tread {
                        upper
                    } else {
                        on_floor
                    },
                    ground: ground.height,
                    pitch: (ground.slope * along).atan() + ground.nod * along,
                });
            }
        }
        (self.building.clearance_on(self.floor, next, None) >= half_width).then(|| Footing {
            floor: self.floor,
            ground: self.building.floor_height(self.floor),
            pitch: 0.0,
        })
    }

    /// The floor the robot stands on (the lower one while on a flight).
    #[must_use]
    pub fn floor(&self) -> usize {
        self.floor
    }

    /// A person-sized box (`half_size` half extents in x and y, `height` tall) that walks to and
    /// fro between `from` and `to` at `speed` m/s, starting at `from`, moved each LiDAR turn;
    /// the LiDAR sees it and the collision check counts it (also when it walks into the robot).
    ///
    /// # Errors
    /// [`SimError::InvalidConfig`] for a speed that is not finite and positive or ends less
    /// than 1 cm apart; [`SimError::InvalidBox`] for a malformed size.
    pub fn add_walker(
        &mut self,
        from: Vector2<f64>,
        to: Vector2<f64>,
        speed: f64,
        half_size: Vector2<f64>,
        height: f64,
    ) -> Result<BoxId, SimError> {
        if !(speed.is_finite() && speed > 0.0) {
            return Err(SimError::invalid(
                "speed",
                speed,
                "finite and positive (m/s)",
            ));
        }
        let length = (to - from).norm();
        if !(length.is_finite() && length >= 0.01) {
            return Err(SimError::invalid(
                "walker path length",
                length,
                "finite and at least 0.01 m",
            ));
        }
        let mut walker = Walker {
            id: BoxId(0),
            from,
            to,
            speed,
            half_size,
            height,
            travelled: 0.0,
        };
        walker.id = self.building.add_box(walker.solid())?;
        let id = walker.id;
        self.walkers.push(walker);
        Ok(id)
    }

    /// The body velocity that brings the reported odometry onto `trajectory`'s pose one turn
    /// from now (sent at `sent`).
    fn track(&self, trajectory: &Se2Trajectory, sent: f64) -> VelocityCommand {
        let target = trajectory.pose_at(self.stamp + self.period - sent);
        let yaw = self.odom_t_body.rotation.euler_angles().2;
        let here = Pose2::new(self.odom_t_body.translation.vector.xy(), yaw);
        let error = here.inverse() * target;
        VelocityCommand {
            forward: error.translation.x / self.period,
            lateral: error.translation.y / self.period,
            yaw_rate: error.rotation.angle() / self.period,
        }
    }

    /// The true body pose in the world (3D, at the body height).
    #[must_use]
    pub fn body_pose(&self) -> Pose3 {
        let p = self.world_t_body.translation.vector;
        // Nose up is a negative turn about the body's y axis.
        Pose3::from_parts(
            Translation3::new(
                p.x,
                p.y,
                self.ground + self.description.geometry.body_height,
            ),
            UnitQuaternion::from_euler_angles(0.0, 0.0, self.world_t_body.rotation.angle())
                * UnitQuaternion::from_euler_angles(0.0, -self.pitch, 0.0),
        )
    }

    /// The true plan-view position (metres).
    #[must_use]
    pub fn position(&self) -> Vector2<f64> {
        self.world_t_body.translation.vector
    }

    /// Steps whose walk was refused because it would have hit an obstacle.
    #[must_use]
    pub fn collisions(&self) -> usize {
        self.collisions
    }

    /// The building walked in.
    #[must_use]
    pub fn building(&self) -> &Building {
        &self.building
    }

    /// The building, to add or remove obstacles while the robot walks.
    pub fn building_mut(&mut self) -> &mut Building {
        &mut self.building
    }

    /// The LiDAR's pose in the body frame.
    #[must_use]
    pub fn body_t_lidar(&self) -> Pose3 {
        self.description.geometry.body_t_lidar
    }
}

impl Robot for CommandedSpot {
    type Error = SimError;

    fn description(&self) -> &RobotDescription {
        &self.description
    }

    fn next_sample(&mut self) -> Result<Sample, SimError> {
        if !self.sensed {
            return Ok(self.sense());
        }
        let (command, stairs) = match &self.active {
            Active::Velocity(command, stairs) => (*command, *stairs),
            Active::Trajectory(trajectory, sent) => (self.track(trajectory, *sent), false),
        };
        Ok(self.step_with(command, stairs))
    }

    fn send(&mut self, command: &MobilityCommand) -> Result<(), SimError> {
        self.active = match command {
            MobilityCommand::Velocity(v) => Active::Velocity(*v, false),
            MobilityCommand::Stairs(v) => Active::Velocity(*v, true),
            MobilityCommand::Trajectory(t) => match t.frame() {
                TrajectoryFrame::Odom => Active::Trajectory(t.clone(), self.stamp),
                other => {
                    return Err(SimError::UnsupportedFrame {
                        frame: other.name(),
                    });
                }
            },
        };
        Ok(())
    }

    fn stop(&mut self) -> Result<(), SimError> {
        self.active = Active::Velocity(VelocityCommand::default(), false);
        Ok(())
    }
}
