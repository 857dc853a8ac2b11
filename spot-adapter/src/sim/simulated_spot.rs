//! The simulated Spot: walks a route through a [`Building`] (or a person carries its LiDAR
//! there), scanning with a spinning LiDAR and reporting drifting odometry, one [`Sample`] per
//! LiDAR sweep kept.

use slam_core::io::StampedPose;
use slam_core::{Pose3, interpolate};

use crate::record::{Recording, RecordingWriter};
use crate::robot::{MotionLimits, Sample, SpotGeometry};
use crate::sim::SimError;
use crate::sim::building::Building;
use crate::sim::building_config::BuildingConfig;
use crate::sim::floors_tour::FloorsTour;
use crate::sim::gait_sway::GaitSway;
use crate::sim::hand_shake::HandShake;
use crate::sim::lidar::{LidarConfig, SpinningLidar};
use crate::sim::motion_profile::MotionProfile;
use crate::sim::odometry::{OdometryDriftConfig, OdometryModel};
use crate::sim::rng::SimRng;
use crate::sim::route::Route;
use crate::sim::setting_checks::{require_non_negative, require_positive};
use crate::sim::timed_walk::{TimedWalk, WalkLimits};

/// Settings of a simulated run.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct SimulationConfig {
    /// Seeds the sensor noise and the odometry drift, and the building in
    /// [`SimulatedSpot::corridor_loop`] (a building made with [`Building::generate`] has its
    /// own seed).
    pub seed: u64,
    /// The building [`SimulatedSpot::corridor_loop`] generates.
    pub building: BuildingConfig,
    /// Spot's walking speed, 0.6 m/s (the thesis' runs); a handheld walk has its own.
    pub speed: f64,
    /// The LiDAR, a VLP-16 by default; Spot takes one sample per sweep, so its
    /// `rotation_rate` (5 Hz) is the sample rate.
    pub lidar: LidarConfig,
    /// How the robot (or a person carrying the LiDAR) moves along the route: Spot's
    /// walk by default.
    pub motion: MotionProfile,
    /// The odometry's drift.
    pub odometry: OdometryDriftConfig,
    /// Body height and LiDAR mounting.
    pub spot: SpotGeometry,
    /// How fast a [`CommandedSpot`](crate::sim::CommandedSpot) may be commanded to move.
    pub limits: MotionLimits,
    /// The body's sway while Spot walks (none by default; a handheld walk shakes by its own
    /// [`HandShake`]).
    pub gait_sway: GaitSway,
    /// Cast each column from the true pose at its firing time (Spot walks 12 cm during a
    /// sweep), as a real spinning LiDAR sees it; `false` (the default) casts the whole turn from
    /// the pose at the sample's stamp, so no deskewing is needed, and every point's `time` is 0.
    pub motion_distortion: bool,
    /// A gyro on the body: each sample carries the orientation integrated from it
    /// ([`Sample::gyro_orientation`]), the true one drifting at this rate (rad/s) about a fixed
    /// tilted axis, as an uncalibrated bias makes it drift. `None` (the default): no gyro.
    pub gyro_drift: Option<f64>,
}

/// The axis the simulated gyro drifts about (unit): tilted, so that the drift shows in roll and
/// pitch as well as heading.
const GYRO_DRIFT_AXIS: [f64; 3] = [0.36, -0.48, 0.8];

/// How many times faster the odometry drifts on a flight of stairs than on the flat: feet slip
/// on the step edges (the thesis saw Spot's odometry drift most on its stairs walk).
pub const STAIRS_SLIP: f64 = 3.0;

impl Default for SimulationConfig {
    fn default() -> Self {
        Self {
            seed: 0,
            building: BuildingConfig::default(),
            speed: 0.6,
            lidar: LidarConfig::default(),
            motion: MotionProfile::default(),
            odometry: OdometryDriftConfig::default(),
            spot: SpotGeometry::default(),
            limits: MotionLimits::default(),
            gait_sway: GaitSway::default(),
            motion_distortion: false,
            gyro_drift: None,
        }
    }
}

impl SimulationConfig {
    /// The defaults with `seed` for the noise, the drift and the corridor-loop building.
    #[must_use]
    pub fn with_seed(seed: u64) -> Self {
        Self {
            seed,
            ..Self::default()
        }
    }

    /// The hand-held walk with `seed`: an OS1-128 ([`LidarConfig::os1_128`]) carried by a
    /// walking person ([`MotionProfile::handheld`]: 2 Hz scans, turns of up to 50° between
    /// them), each 0.1 s sweep skewed by the motion during it (`motion_distortion`). The walk
    /// `simulate --sensor os1-128 --motion handheld --skewed` makes.
    ///
    /// ```
    /// use spot_adapter::sim::{MotionProfile, SimulationConfig};
    ///
    /// let config = SimulationConfig::handheld_os1_128(3);
    /// assert_eq!((config.seed, config.lidar.rings), (3, 128));
    /// assert!(matches!(config.motion, MotionProfile::Handheld(_)) && config.motion_distortion);
    /// ```
    #[must_use]
    pub fn handheld_os1_128(seed: u64) -> Self {
        Self {
            lidar: LidarConfig::os1_128(),
            motion: MotionProfile::handheld(),
            motion_distortion: true,
            ..Self::with_seed(seed)
        }
    }
}

/// A simulated run: an iterator of [`Sample`]s with ground truth attached.
///
/// ```
/// use spot_adapter::sim::{Building, BuildingConfig, Route, SimulatedSpot, SimulationConfig};
///
/// let building = Building::generate(3, &BuildingConfig::default())?;
/// let route = Route::corridor_loop(&building);
/// let sim = SimulatedSpot::new(building, &route, &SimulationConfig::default())?;
/// // 0.6 m/s at 5 Hz: a sample every 0.12 m.
/// assert_eq!(sim.len(), (route.length() / 0.12).ceil() as usize + 1);
/// for sample in sim.take(2) {
///     assert!(sample.cloud.len() > 20_000);
///     assert!(sample.ground_truth.is_some());
/// }
/// # Ok::<(), spot_adapter::sim::SimError>(())
/// ```
#[derive(Clone, Debug)]
pub struct SimulatedSpot {
    building: Building,
    lidar: SpinningLidar,
    odometry: OdometryModel,
    noise: SimRng,
    body_t_lidar: Pose3,
    motion: Motion,
    truth: Vec<StampedPose>,
    /// Whether each sample of `truth` is on a flight of stairs (empty: none is).
    on_stairs: Vec<bool>,
    next: usize,
    motion_distortion: bool,
    gyro_drift: Option<f64>,
}

/// How the body moves between the samples.
#[derive(Clone, Debug)]
enum Motion {
    /// Spot's walk: geodesic between the samples, which are one sweep apart.
    Sampled,
    /// Spot turning at corners, swaying as it walks.
    Spot { walk: TimedWalk, sway: GaitSway },
    /// A person carrying the LiDAR, with a shaking hand.
    Hand { walk: TimedWalk, shake: HandShake },
}

impl Motion {
    /// `world_T_body` at `t` seconds, for the timed motions.
    fn timed_pose(&self, t: f64) -> Option<Pose3> {
        match self {
            Self::Sampled => None,
            Self::Spot { walk, sway } => Some(walk.pose_at(t) * sway.offset(t)),
            Self::Hand { walk, shake } => Some(walk.pose_at(t) * shake.offset(t, walk.duration())),
        }
    }

    /// The samples of a timed motion at `rate` hertz from its start to its end (the last
    /// one where the walk ended).
    fn samples(&self, duration: f64, rate: f64) -> Vec<StampedPose> {
        // A duration a whole number of periods long, give or take rounding, ends on a sample.
        let n = (duration * rate - 1e-9).ceil().max(0.0) as usize;
        (0..=n)
            .filter_map(|k| {
                let stamp = k as f64 / rate;
                Some(StampedPose {
                    stamp,
                    pose: self.timed_pose(stamp)?,
                })
            })
            .collect()
    }
}

impl SimulatedSpot {
    /// A run along `route` through `building`, moving as `config.motion` says.
    ///
    /// # Errors
    /// [`SimError::InvalidConfig`] for invalid LiDAR, odometry, speed, rate, gait sway,
    /// motion limit or motion profile settings.
    pub fn new(
        building: Building,
        route: &Route,
        config: &SimulationConfig,
    ) -> Result<Self, SimError> {
        let lidar = SpinningLidar::new(config.lidar.clone())?;
        let sway = &config.gait_sway;
        require_non_negative(&[
            ("gyro_drift", config.gyro_drift.unwrap_or(0.0)),
            ("gait_sway.height", sway.height),
            ("gait_sway.tilt", sway.tilt),
            ("gait_sway.frequency", sway.frequency),
        ])?;
        let rotation_rate = config.lidar.rotation_rate;
        let (motion, truth, body_t_lidar) = match &config.motion {
            MotionProfile::Walk => {
                let mut truth = route.walk(config.speed, rotation_rate, config.spot.body_height)?;
                for p in &mut truth {
                    p.pose *= sway.offset(p.stamp);
                }
                (Motion::Sampled, truth, config.spot.body_t_lidar)
            }
            MotionProfile::FastTurns(turns) => {
                turns.validate()?;
                config.limits.validate()?;
                require_positive(&[("speed", config.speed, "finite and positive (m/s)")])?;
                let limits = WalkLimits {
                    speed: config.speed,
                    corner_speed: 0.0,
                    acceleration: turns.acceleration,
                    turn_rate: config.limits.max_yaw_rate,
                    turn_acceleration: turns.yaw_acceleration,
                };
                let walk = TimedWalk::new(route, &limits, config.spot.body_height);
                let duration = walk.duration();
                let motion = Motion::Spot {
                    walk,
                    sway: sway.clone(),
                };
                let truth = motion.samples(duration, rotation_rate);
                (motion, truth, config.spot.body_t_lidar)
            }
            MotionProfile::Handheld(hand) => {
                hand.validate(rotation_rate)?;
                let limits = WalkLimits {
                    speed: hand.speed,
                    corner_speed: hand.corner_speed,
                    acceleration: hand.acceleration,
                    turn_rate: hand.turn_rate,
                    turn_acceleration: hand.turn_acceleration,
                };
                let walk = TimedWalk::new(route, &limits, hand.height);
                let duration = walk.duration();
                let motion = Motion::Hand {
                    walk,
                    shake: hand.shake.clone(),
                };
                let truth = motion.samples(duration, hand.sample_rate);
                // The person carries the LiDAR itself: the body is the sensor.
                (motion, truth, Pose3::identity())
            }
        };
        Ok(Self {
            building,
            lidar,
            odometry: OdometryModel::new(config.odometry.clone(), config.seed)?,
            noise: SimRng::new(config.seed, 0x11da_4000),
            body_t_lidar,
            motion,
            truth,
            on_stairs: Vec::new(),
            next: 0,
            motion_distortion: config.motion_distortion,
            gyro_drift: config.gyro_drift,
        })
    }

    /// One lap of the corridor loop of the building `config.building` generates for
    /// `config.seed`, with the same seed for the sensor noise and the odometry drift.
    ///
    /// # Errors
    /// As [`Building::generate`] and [`SimulatedSpot::new`].
    pub fn corridor_loop(config: &SimulationConfig) -> Result<Self, SimError> {
        let building = Building::generate(config.seed, &config.building)?;
        let route = Route::corridor_loop(&building);
        Self::new(building, &route, config)
    }

    /// The tour of every floor ([`FloorsTour`]) of the building `config.building` generates
    /// for `config.seed`: Spot's walk (whatever `config.motion` says) at `config.speed` on the
    /// floors and [`STAIRS_SPEED`](crate::sim::STAIRS_SPEED) along the slope of
    /// the stairs, the odometry drifting [`STAIRS_SLIP`] times faster on them. With one floor,
    /// [`SimulatedSpot::corridor_loop`].
    ///
    /// # Errors
    /// As [`Building::generate`] and [`SimulatedSpot::new`].
    pub fn floors_tour(config: &SimulationConfig) -> Result<Self, SimError> {
        let building = Building::generate(config.seed, &config.building)?;
        if building.floors() == 1 {
            let route = Route::corridor_loop(&building);
            return Self::new(building, &route, config);
        }
        let tour = FloorsTour::new(&building)?;
        let (mut truth, on_stairs) = tour.walk(
            config.speed,
            config.lidar.rotation_rate,
            config.spot.body_height,
        )?;
        for p in &mut truth {
            p.pose *= config.gait_sway.offset(p.stamp);
        }
        let walk = SimulationConfig {
            motion: MotionProfile::Walk,
            ..config.clone()
        };
        let mut sim = Self::new(building, tour.route(), &walk)?;
        sim.truth = truth;
        sim.on_stairs = on_stairs;
        Ok(sim)
    }

    /// Whether each sample is on a flight of stairs (all `false` off a [`FloorsTour`]).
    #[must_use]
    pub fn on_stairs(&self) -> Vec<bool> {
        (0..self.truth.len())
            .map(|k| self.on_stairs.get(k).copied().unwrap_or(false))
            .collect()
    }

    /// The building walked through.
    #[must_use]
    pub fn building(&self) -> &Building {
        &self.building
    }

    /// The LiDAR model.
    #[must_use]
    pub fn lidar(&self) -> &SpinningLidar {
        &self.lidar
    }

    /// The LiDAR mounting (`body_T_lidar`).
    #[must_use]
    pub fn body_t_lidar(&self) -> Pose3 {
        self.body_t_lidar
    }

    /// The whole ground-truth trajectory `world_T_body`, one pose per sample.
    #[must_use]
    pub fn ground_truth(&self) -> Vec<StampedPose> {
        self.truth.clone()
    }

    /// The true `world_T_body` at any time `t` (seconds; before the start the first pose,
    /// after the end the last): the pose each column of a motion-distorted sweep is cast from.
    /// Spot's walk moves along the geodesic between its samples, the other motions follow their
    /// timed walk (so a sweep between two handheld samples 0.5 s apart sees the real motion,
    /// not an interpolation).
    #[must_use]
    pub fn pose_at(&self, t: f64) -> Pose3 {
        if let Some(pose) = self.motion.timed_pose(t) {
            return pose;
        }
        let k = self.truth.partition_point(|p| p.stamp <= t);
        match (
            k.checked_sub(1).and_then(|i| self.truth.get(i)),
            self.truth.get(k),
        ) {
            (Some(a), Some(b)) => {
                interpolate(&a.pose, &b.pose, (t - a.stamp) / (b.stamp - a.stamp))
            }
            (Some(only), None) | (None, Some(only)) => only.pose,
            (None, None) => Pose3::identity(),
        }
    }

    /// Number of samples the whole run yields.
    #[must_use]
    pub fn len(&self) -> usize {
        self.truth.len()
    }

    /// Run the remaining samples into a recording in `dir` and open it.
    ///
    /// # Errors
    /// [`SimError::Record`] as [`RecordingWriter::write`], [`RecordingWriter::finish`] and
    /// [`Recording::open`].
    pub fn record(self, dir: impl AsRef<std::path::Path>) -> Result<Recording, SimError> {
        let mut writer = RecordingWriter::create(dir, self.body_t_lidar)?;
        for sample in self {
            writer.write(&sample)?;
        }
        Ok(Recording::open(writer.finish()?)?)
    }

    /// Whether the run yields no sample (never, for a valid route).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.truth.is_empty()
    }
}

impl Iterator for SimulatedSpot {
    type Item = Sample;

    fn next(&mut self) -> Option<Sample> {
        let StampedPose {
            stamp,
            pose: world_t_body,
        } = *self.truth.get(self.next)?;
        let slip = if self.on_stairs.get(self.next).copied().unwrap_or(false) {
            STAIRS_SLIP
        } else {
            1.0
        };
        self.next += 1;
        let odom_t_body = self.odometry.step_slipping(&world_t_body, slip);
        let body_t_lidar = self.body_t_lidar;
        let start = world_t_body * body_t_lidar;
        let cloud = match (&self.motion, self.truth.get(self.next)) {
            (_, _) if !self.motion_distortion => {
                self.lidar
                    .scan_at_rest(&self.building, &start, &mut self.noise)
            }
            (
                Motion::Sampled,
                Some(&StampedPose {
                    pose: next_body, ..
                }),
            ) => self.lidar.scan_moving(
                &self.building,
                &start,
                &(next_body * body_t_lidar),
                &mut self.noise,
            ),
            // The last sample of a walk has no later pose: the robot has stopped. Cast from one
            // pose: every point was measured at the stamp, and its time says so.
            (Motion::Sampled, None) => {
                self.lidar
                    .scan_at_rest(&self.building, &start, &mut self.noise)
            }
            // A timed motion is known between the samples, however far apart they are.
            (motion, _) => self.lidar.scan_along(
                &self.building,
                |dt| motion.timed_pose(stamp + dt).unwrap_or(world_t_body) * body_t_lidar,
                &mut self.noise,
            ),
        };
        let gyro_orientation = self
            .gyro_drift
            .zip(self.truth.first())
            .map(|(rate, first)| {
                let [x, y, z] = GYRO_DRIFT_AXIS;
                let drift = nalgebra::Vector3::new(x, y, z) * (rate * (stamp - first.stamp));
                first.pose.rotation.inverse()
                    * world_t_body.rotation
                    * nalgebra::UnitQuaternion::from_scaled_axis(drift)
            });
        Some(Sample {
            stamp,
            odom_t_body,
            body_t_lidar: self.body_t_lidar,
            cloud,
            ground_truth: Some(world_t_body),
            gyro_orientation,
        })
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.truth.len() - self.next;
        (left, Some(left))
    }
}

impl ExactSizeIterator for SimulatedSpot {}
