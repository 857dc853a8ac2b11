//! `StairsClimb`: the stairs controller a cross-floor drive hands over to at a flight's end. It
//! follows the walk the map was made on over the flight (the robot's own way up or down it), in
//! the stairs mode, steering on its odometry from the pose it was handed; the navigator of the
//! floor it reaches takes over with the pose it arrives at.

use nalgebra::{Point3, Vector2};
use slam_core::{InvalidSetting, Pose3};

use crate::nav::NavError;
use crate::robot::{MobilityCommand, VelocityCommand};

/// Settings of a [`StairsClimb`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct StairsClimbConfig {
    /// Plan-view speed on the flight, 0.3 m/s (Spot's stairs mode climbs at 0.3-0.5 m/s
    /// along the slope).
    pub speed: f64,
    /// The point of the walk steered at lies this far ahead, 0.3 m (short: the walk turns on
    /// the landings, beside the stairwell).
    pub lookahead: f64,
    /// Done within this plan-view distance of the walk's end, 0.15 m, once at or past it.
    pub arrive: f64,
    /// The walk is followed this far past its end, straight on, 0.3 m: its end is where the
    /// map's walk first stood clear of the flight's inflation, and a robot stopping short of
    /// it would start the next floor's walk inside that inflation.
    pub run_out: f64,
    /// Before it walks, the robot turns in place until it faces the walk within this, 0.3 rad:
    /// it climbs facing along the flight.
    pub face: f64,
    /// Turn rate per radian of heading error, 1.5 /s, at most `max_yaw_rate`, 0.6 rad/s.
    pub yaw_gain: f64,
    /// The fastest turn (rad/s).
    pub max_yaw_rate: f64,
}

impl Default for StairsClimbConfig {
    fn default() -> Self {
        Self {
            speed: 0.3,
            lookahead: 0.3,
            arrive: 0.15,
            run_out: 0.3,
            face: 0.3,
            yaw_gain: 1.5,
            max_yaw_rate: 0.6,
        }
    }
}

impl StairsClimbConfig {
    /// Every setting finite and positive.
    ///
    /// # Errors
    /// [`InvalidSetting`] naming the first that is not.
    pub fn validate(&self) -> Result<(), InvalidSetting> {
        for (setting, v) in [
            ("StairsClimbConfig::speed", self.speed),
            ("StairsClimbConfig::lookahead", self.lookahead),
            ("StairsClimbConfig::arrive", self.arrive),
            ("StairsClimbConfig::run_out", self.run_out),
            ("StairsClimbConfig::face", self.face),
            ("StairsClimbConfig::yaw_gain", self.yaw_gain),
            ("StairsClimbConfig::max_yaw_rate", self.max_yaw_rate),
        ] {
            InvalidSetting::check(v.is_finite() && v > 0.0, setting, v, "finite and positive")?;
        }
        Ok(())
    }
}

/// What a [`StairsClimb`] does next.
#[derive(Clone, Debug, PartialEq)]
pub enum ClimbStep {
    /// Send this command (a turn in place on the floor, then the walk in the stairs mode).
    Walk(MobilityCommand),
    /// At the walk's end (or past it): stop; the body's estimate is [`StairsClimb::pose`].
    Arrived,
}

/// The stairs controller: follows a walk over a flight by pure pursuit on the odometry.
///
/// ```
/// use nalgebra::Point3;
/// use slam_core::Pose3;
/// use spot_adapter::nav::{ClimbStep, StairsClimb, StairsClimbConfig};
/// use spot_adapter::robot::MobilityCommand;
///
/// // A walk 3 m along x rising 1.7 m; the robot at its start facing along it.
/// let walk: Vec<Point3<f64>> =
///     (0..=30).map(|i| Point3::new(0.1 * i as f64, 0.0, 0.8 + 0.057 * i as f64)).collect();
/// let mut climb =
///     StairsClimb::new(&walk, Pose3::identity(), Pose3::identity(), StairsClimbConfig::default())?;
/// let ClimbStep::Walk(MobilityCommand::Stairs(v)) = climb.step(&Pose3::identity()) else {
///     panic!("walks up in the stairs mode");
/// };
/// assert!(v.forward > 0.0);
/// # Ok::<(), spot_adapter::nav::NavError>(())
/// ```
#[derive(Clone, Debug)]
pub struct StairsClimb {
    path: Vec<Vector2<f64>>,
    map_t_odom: Pose3,
    passed: usize,
    walking: bool,
    config: StairsClimbConfig,
}

impl StairsClimb {
    /// A climb along `walk` (the map frame, in walking order; its plan view is followed) for a
    /// robot whose body is at `map_t_body` when its odometry reads `odom_t_body`.
    ///
    /// # Errors
    /// [`NavError::InvalidConfig`] for bad settings, or naming `StairsClimb walk` for a walk of
    /// fewer than two positions or one that is not finite.
    pub fn new(
        walk: &[Point3<f64>],
        map_t_body: Pose3,
        odom_t_body: Pose3,
        config: StairsClimbConfig,
    ) -> Result<Self, NavError> {
        config.validate()?;
        InvalidSetting::check(
            walk.len() >= 2,
            "StairsClimb walk",
            walk.len() as f64,
            "at least two positions",
        )?;
        if let Some(bad) = walk.iter().find(|p| !p.iter().all(|v| v.is_finite())) {
            return Err(NavError::InvalidConfig(InvalidSetting {
                setting: "StairsClimb walk",
                value: bad.x + bad.y + bad.z,
                expected: "finite positions",
            }));
        }
        let mut path: Vec<Vector2<f64>> = walk.iter().map(|p| p.xy().coords).collect();
        // Straight on past the end, along the walk's last step that moved.
        let end = path[path.len() - 1];
        if let Some(from) = path.iter().rev().find(|p| (end - *p).norm() > 1e-6) {
            path.push(end + (end - from).normalize() * config.run_out);
        }
        Ok(Self {
            path,
            map_t_odom: map_t_body * odom_t_body.inverse(),
            passed: 0,
            walking: false,
            config,
        })
    }

    /// The body's pose in the map when the odometry reads `odom_t_body`: the pose it was handed
    /// carried along the odometry's motion since.
    #[must_use]
    pub fn pose(&self, odom_t_body: &Pose3) -> Pose3 {
        self.map_t_odom * odom_t_body
    }

    /// [`StairsClimb::pose`] levelled (roll and pitch zero, the heading and position kept): the
    /// pose the next floor's navigator starts from, the robot standing on that floor.
    #[must_use]
    pub fn level_pose(&self, odom_t_body: &Pose3) -> Pose3 {
        let pose = self.pose(odom_t_body);
        let yaw = pose.rotation.euler_angles().2;
        Pose3::from_parts(
            pose.translation,
            nalgebra::UnitQuaternion::from_euler_angles(0.0, 0.0, yaw),
        )
    }

    /// The next command for a robot whose odometry reads `odom_t_body`.
    pub fn step(&mut self, odom_t_body: &Pose3) -> ClimbStep {
        let pose = self.pose(odom_t_body);
        let here = pose.translation.vector.xy();
        let yaw = pose.rotation.euler_angles().2;
        let c = &self.config;
        // The nearest point of the walk, never going back along it.
        while self.passed + 1 < self.path.len()
            && (self.path[self.passed + 1] - here).norm() <= (self.path[self.passed] - here).norm()
        {
            self.passed += 1;
        }
        // Done at the walk's end or past it, not short of it: the end is where the map's walk
        // first stood clear of the flight on the floor it reached.
        let end = self.path[self.path.len() - 1];
        let last = end - self.path[self.path.len() - 2];
        if (end - here).norm() <= c.arrive && (here - end).dot(&last) >= 0.0 {
            return ClimbStep::Arrived;
        }
        let target = self.path[self.passed..]
            .iter()
            .copied()
            .find(|p| (p - here).norm() >= c.lookahead)
            .unwrap_or(end);
        let to = target - here;
        let error = wrap(to.y.atan2(to.x) - yaw);
        let yaw_rate = (c.yaw_gain * error).clamp(-c.max_yaw_rate, c.max_yaw_rate);
        if !self.walking && error.abs() > c.face {
            return ClimbStep::Walk(MobilityCommand::Velocity(VelocityCommand::new(
                0.0, yaw_rate,
            )));
        }
        self.walking = true;
        let forward = c.speed * error.cos().max(0.0);
        ClimbStep::Walk(MobilityCommand::Stairs(VelocityCommand::new(
            forward, yaw_rate,
        )))
    }
}

/// `a` wrapped into (-pi, pi].
fn wrap(a: f64) -> f64 {
    let t = (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU);
    t - std::f64::consts::PI
}
