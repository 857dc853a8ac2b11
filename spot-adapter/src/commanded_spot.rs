//! A simulated Spot driven by velocity commands: the closed-loop counterpart of
//! [`SimulatedSpot`](crate::SimulatedSpot), which walks a route fixed in advance.

use nalgebra::{Translation3, UnitQuaternion, Vector2};
use slam_core::{Pose2, Pose3};

use crate::building::Building;
use crate::error::AdapterError;
use crate::lidar::Vlp16;
use crate::odometry::OdometryModel;
use crate::rng::SimRng;
use crate::sample::Sample;
use crate::simulator::SimulationConfig;

/// A body velocity command, as Spot's mobility API takes it (it also takes a sideways speed,
/// which a planar path follower does not need).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VelocityCommand {
    /// Forward speed, m/s (negative walks backwards).
    pub forward: f64,
    /// Turn rate about the vertical, rad/s (positive turns left).
    pub yaw_rate: f64,
}

/// Spot's turn rate is capped here, rad/s.
pub const MAX_YAW_RATE: f64 = 1.0;

/// A simulated Spot that walks where it is told: each [`CommandedSpot::step`] holds a velocity
/// command for one LiDAR turn (0.2 s at 5 Hz), moves the true body, integrates the drifting
/// odometry and casts the next scan. A step that would put the body centre closer than
/// `half_width` to an obstacle leaves the robot where it stands and counts a collision, as
/// Spot's own obstacle avoidance would stop it.
///
/// ```
/// use nalgebra::Vector2;
/// use spot_adapter::{Building, BuildingConfig, CommandedSpot, SimulationConfig, VelocityCommand};
///
/// let building = Building::generate(3, &BuildingConfig::default())?;
/// let start = building.corridor_loop()[0];
/// let mut spot = CommandedSpot::new(building, start, 0.0, &SimulationConfig::default())?;
/// let sample = spot.step(VelocityCommand { forward: 0.5, yaw_rate: 0.0 });
/// assert!(sample.cloud.len() > 20_000);
/// assert!((spot.position() - start).norm() > 0.09);
/// # Ok::<(), spot_adapter::AdapterError>(())
/// ```
#[derive(Clone, Debug)]
pub struct CommandedSpot {
    building: Building,
    lidar: Vlp16,
    odometry: OdometryModel,
    noise: SimRng,
    body_t_lidar: Pose3,
    body_height: f64,
    half_width: f64,
    max_speed: f64,
    period: f64,
    stamp: f64,
    world_t_body: Pose2,
    collisions: usize,
}

impl CommandedSpot {
    /// Spot standing at plan-view `position` (metres) facing `yaw` (radians) in `building`, with
    /// `config`'s LiDAR, odometry drift, geometry and seed; `config.speed` caps the forward speed.
    ///
    /// # Errors
    /// [`AdapterError::InvalidConfig`] for invalid LiDAR, odometry or speed settings;
    /// [`AdapterError::BlockedEndpoint`] when the start is not free floor for the robot.
    pub fn new(
        building: Building,
        position: Vector2<f64>,
        yaw: f64,
        config: &SimulationConfig,
    ) -> Result<Self, AdapterError> {
        let lidar = Vlp16::new(config.lidar.clone())?;
        if !(config.speed.is_finite() && config.speed > 0.0 && yaw.is_finite()) {
            return Err(AdapterError::InvalidConfig(format!(
                "speed {} and yaw {yaw} must be finite, the speed positive",
                config.speed
            )));
        }
        let half_width = config.spot.half_width;
        if !(position.iter().all(|v| v.is_finite()) && building.clearance(position) >= half_width) {
            return Err(AdapterError::BlockedEndpoint {
                which: "start",
                x: position.x,
                y: position.y,
            });
        }
        Ok(Self {
            building,
            odometry: OdometryModel::new(config.odometry.clone(), config.seed)?,
            noise: SimRng::new(config.seed, 0xc0_4a4d),
            body_t_lidar: config.spot.body_t_lidar,
            body_height: config.spot.body_height,
            half_width,
            max_speed: config.speed,
            period: 1.0 / config.lidar.rotation_rate,
            stamp: 0.0,
            world_t_body: Pose2::new(position, yaw),
            collisions: 0,
            lidar,
        })
    }

    /// The scan and odometry where the robot stands now, without moving it (the first sample
    /// of a run).
    pub fn sense(&mut self) -> Sample {
        let world_t_body = self.body_pose();
        let odom_t_body = self.odometry.step(&world_t_body);
        let world_t_lidar = world_t_body * self.body_t_lidar;
        Sample {
            stamp: self.stamp,
            odom_t_body,
            body_t_lidar: self.body_t_lidar,
            cloud: self
                .lidar
                .scan_at_rest(&self.building, &world_t_lidar, &mut self.noise),
            ground_truth: Some(world_t_body),
        }
    }

    /// Holds `command` for one LiDAR turn (speed and turn rate clamped to Spot's limits; a
    /// non-finite command stops the robot), then senses. The body moves along the arc the
    /// command describes, unless that would bring it closer than half its width to an
    /// obstacle: then it stays and a collision is counted.
    pub fn step(&mut self, command: VelocityCommand) -> Sample {
        let finite = command.forward.is_finite() && command.yaw_rate.is_finite();
        let (v, w) = if finite {
            (
                command.forward.clamp(-self.max_speed, self.max_speed),
                command.yaw_rate.clamp(-MAX_YAW_RATE, MAX_YAW_RATE),
            )
        } else {
            (0.0, 0.0)
        };
        let dt = self.period;
        // Exact unicycle arc: heading turns by w dt, the chord follows the mean heading.
        let (yaw, dyaw) = (self.world_t_body.rotation.angle(), w * dt);
        let chord = if dyaw.abs() < 1e-9 {
            v * dt
        } else {
            2.0 * v / w * (0.5 * dyaw).sin()
        };
        let mid = yaw + 0.5 * dyaw;
        let next =
            self.world_t_body.translation.vector + chord * Vector2::new(mid.cos(), mid.sin());
        if self.building.clearance(next) >= self.half_width {
            self.world_t_body = Pose2::new(next, yaw + dyaw);
        } else {
            self.collisions += 1;
        }
        self.stamp += dt;
        self.sense()
    }

    /// The true body pose in the world (3D, at the body height).
    #[must_use]
    pub fn body_pose(&self) -> Pose3 {
        let p = self.world_t_body.translation.vector;
        Pose3::from_parts(
            Translation3::new(p.x, p.y, self.body_height),
            UnitQuaternion::from_euler_angles(0.0, 0.0, self.world_t_body.rotation.angle()),
        )
    }

    /// The true plan-view position (metres).
    #[must_use]
    pub fn position(&self) -> Vector2<f64> {
        self.world_t_body.translation.vector
    }

    /// Steps that were refused because they would have hit an obstacle.
    #[must_use]
    pub fn collisions(&self) -> usize {
        self.collisions
    }

    /// The building walked in.
    #[must_use]
    pub fn building(&self) -> &Building {
        &self.building
    }

    /// The LiDAR's pose in the body frame.
    #[must_use]
    pub fn body_t_lidar(&self) -> Pose3 {
        self.body_t_lidar
    }
}
