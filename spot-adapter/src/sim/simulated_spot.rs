//! The simulated Spot: walks a route through a [`Building`], scanning with a VLP-16 and
//! reporting drifting odometry, one [`Sample`] per LiDAR turn.

use slam_core::Pose3;
use slam_core::io::StampedPose;

use crate::error::AdapterError;
use crate::record::{Recording, RecordingWriter};
use crate::robot::{MotionLimits, Sample, SpotGeometry};
use crate::sim::building::Building;
use crate::sim::gait_sway::GaitSway;
use crate::sim::generator::BuildingConfig;
use crate::sim::lidar::{Vlp16, Vlp16Config};
use crate::sim::odometry::{OdometryDriftConfig, OdometryModel};
use crate::sim::rng::SimRng;
use crate::sim::route::Route;

/// Settings of a simulated run.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct SimulationConfig {
    /// Seeds the sensor noise and the odometry drift, and the building in
    /// [`SimulatedSpot::corridor_loop`] (a building made with [`Building::generate`] has its
    /// own seed).
    pub seed: u64,
    /// The building [`SimulatedSpot::corridor_loop`] generates.
    pub building: BuildingConfig,
    /// Walking speed, 0.6 m/s (the thesis' runs).
    pub speed: f64,
    /// The LiDAR; one sample per turn, so its `rotation_rate` (5 Hz) is the sample rate.
    pub lidar: Vlp16Config,
    /// The odometry's drift.
    pub odometry: OdometryDriftConfig,
    /// Body height and LiDAR mounting.
    pub spot: SpotGeometry,
    /// How fast a [`CommandedSpot`](crate::sim::CommandedSpot) may be commanded to move.
    pub limits: MotionLimits,
    /// The body's sway while walking (none by default).
    pub gait_sway: GaitSway,
    /// Cast each column from the pose at its firing time (the robot walks 12 cm during a
    /// sweep), as a real spinning LiDAR sees it; `false` (the default) casts the whole turn from
    /// the pose at the sample's stamp, so no deskewing is needed, and every point's `time` is 0.
    pub motion_distortion: bool,
}

impl Default for SimulationConfig {
    fn default() -> Self {
        Self {
            seed: 0,
            building: BuildingConfig::default(),
            speed: 0.6,
            lidar: Vlp16Config::default(),
            odometry: OdometryDriftConfig::default(),
            spot: SpotGeometry::default(),
            limits: MotionLimits::default(),
            gait_sway: GaitSway::default(),
            motion_distortion: false,
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
/// # Ok::<(), spot_adapter::AdapterError>(())
/// ```
#[derive(Clone, Debug)]
pub struct SimulatedSpot {
    building: Building,
    lidar: Vlp16,
    odometry: OdometryModel,
    noise: SimRng,
    body_t_lidar: Pose3,
    truth: Vec<StampedPose>,
    next: usize,
    motion_distortion: bool,
}

impl SimulatedSpot {
    /// A run along `route` through `building`.
    ///
    /// # Errors
    /// [`AdapterError::InvalidConfig`] for invalid LiDAR, odometry, speed or rate settings.
    pub fn new(
        building: Building,
        route: &Route,
        config: &SimulationConfig,
    ) -> Result<Self, AdapterError> {
        let lidar = Vlp16::new(config.lidar.clone())?;
        let sway = &config.gait_sway;
        for (setting, value) in [
            ("gait_sway.height", sway.height),
            ("gait_sway.tilt", sway.tilt),
            ("gait_sway.frequency", sway.frequency),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(AdapterError::invalid(
                    setting,
                    value,
                    "finite and non-negative",
                ));
            }
        }
        let mut truth = route.walk(
            config.speed,
            config.lidar.rotation_rate,
            config.spot.body_height,
        )?;
        for p in &mut truth {
            p.pose *= sway.offset(p.stamp);
        }
        Ok(Self {
            building,
            lidar,
            odometry: OdometryModel::new(config.odometry.clone(), config.seed)?,
            noise: SimRng::new(config.seed, 0x11da_4000),
            body_t_lidar: config.spot.body_t_lidar,
            truth,
            next: 0,
            motion_distortion: config.motion_distortion,
        })
    }

    /// One lap of the corridor loop of the building `config.building` generates for
    /// `config.seed`, with the same seed for the sensor noise and the odometry drift.
    ///
    /// # Errors
    /// As [`Building::generate`] and [`SimulatedSpot::new`].
    pub fn corridor_loop(config: &SimulationConfig) -> Result<Self, AdapterError> {
        let building = Building::generate(config.seed, &config.building)?;
        let route = Route::corridor_loop(&building);
        Self::new(building, &route, config)
    }

    /// The building walked through.
    #[must_use]
    pub fn building(&self) -> &Building {
        &self.building
    }

    /// The LiDAR model.
    #[must_use]
    pub fn lidar(&self) -> &Vlp16 {
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

    /// Number of samples the whole run yields.
    #[must_use]
    pub fn len(&self) -> usize {
        self.truth.len()
    }

    /// Run the remaining samples into a recording in `dir` and open it.
    ///
    /// # Errors
    /// As [`RecordingWriter::write`], [`RecordingWriter::finish`] and [`Recording::open`].
    pub fn record(self, dir: impl AsRef<std::path::Path>) -> Result<Recording, AdapterError> {
        let mut writer = RecordingWriter::create(dir, self.body_t_lidar)?;
        for sample in self {
            writer.write(&sample)?;
        }
        Recording::open(writer.finish()?)
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
        self.next += 1;
        let odom_t_body = self.odometry.step(&world_t_body);
        let start = world_t_body * self.body_t_lidar;
        let cloud = match self.truth.get(self.next) {
            Some(&StampedPose {
                pose: next_body, ..
            }) if self.motion_distortion => self.lidar.scan_moving(
                &self.building,
                &start,
                &(next_body * self.body_t_lidar),
                &mut self.noise,
            ),
            // The last sample of a run has no later pose: the robot has stopped.
            // Cast from one pose: every point was measured at the stamp, and its time says so.
            _ => self
                .lidar
                .scan_at_rest(&self.building, &start, &mut self.noise),
        };
        Some(Sample {
            stamp,
            odom_t_body,
            body_t_lidar: self.body_t_lidar,
            cloud,
            ground_truth: Some(world_t_body),
            gyro_orientation: None,
        })
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.truth.len() - self.next;
        (left, Some(left))
    }
}

impl ExactSizeIterator for SimulatedSpot {}
