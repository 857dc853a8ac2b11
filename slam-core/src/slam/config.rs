//! Settings of the Graph-SLAM engine, with the thesis' values as defaults.

use crate::error::InvalidSetting;
use crate::robust_kernel::RobustKernel;
use crate::tracking::TrackerConfig;

/// How an edge's information matrix is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(tag = "kind", deny_unknown_fields)
)]
pub enum EdgeInformation {
    /// A diagonal information from standard deviations per edge.
    Fixed {
        /// Translation standard deviation, metres.
        translation_sigma: f64,
        /// Rotation standard deviation, radians.
        rotation_sigma: f64,
    },
    /// The registration's own `J^T W J`, moved into the edge's frame and multiplied by `scale`
    /// (registration information is usually over-confident: scale < 1).
    FromRegistration {
        /// Multiplier.
        scale: f64,
    },
    /// Both uncertainties at once: the fixed sigmas' covariance plus the registration's
    /// (`(Σ_fixed + Σ_registration)^-1`, the information two independent errors of the
    /// edge give). Where the scan constrains the motion well the edge is as stiff as the fixed
    /// sigmas make it; along what the registration barely saw (the axis of a corridor of
    /// blank walls) it is as soft as the registration says, so a loop closed later moves
    /// those keyframes rather than bending the rest of the map.
    FixedAndRegistration {
        /// Translation standard deviation of the fixed part, metres.
        translation_sigma: f64,
        /// Rotation standard deviation of the fixed part, radians.
        rotation_sigma: f64,
        /// Multiplier of the registration's information.
        scale: f64,
    },
}

/// Settings of [`GraphSlam`](super::GraphSlam). Distances in metres, angles in radians.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
// Independent switches of independent stages (gravity, deskew, sweep motion, inline loops),
// each named where it is read: not a state machine in disguise.
#[allow(clippy::struct_excessive_bools)]
pub struct GraphSlamConfig {
    /// A new keyframe once the LiDAR moved this far from the last one (thesis: 0.20 m).
    pub keyframe_distance: f64,
    /// ... or turned this much (radians; default 10 degrees).
    pub keyframe_rotation: f64,
    /// Keyframes in the local map that scans are registered against (thesis: n = 40): the
    /// last ones the robot was at, which on a revisit are old keyframes it rode on.
    pub local_map_keyframes: usize,
    /// No new keyframe where the map already is (metres; default 0.5, 0 turns it off): a scan
    /// registered where a new keyframe would be made rides instead on the newest keyframe
    /// within this distance, when that keyframe (or one next to it in the graph) is in the
    /// local map the scan was registered against and the registration matched at least
    /// [`revisit_min_inlier_ratio`](Self::revisit_min_inlier_ratio) of the scan. A robot
    /// walking a building again therefore localises against the keyframes it made the first
    /// time, and the graph, the map and each loop's optimisation stay the size of the
    /// building, not of the walk. A revisit starts when a loop closes: the old keyframes
    /// around the loop join the local map. Where the place changed (a poorer match), a new
    /// keyframe is made, so the map follows the change.
    pub revisit_radius: f64,
    /// With [`revisit_radius`](Self::revisit_radius): the share of the scan's points the
    /// registration must match (0 to 1; default 0.8) to ride on an old keyframe instead of
    /// making a new one.
    pub revisit_min_inlier_ratio: f64,
    /// With [`revisit_radius`](Self::revisit_radius): a scan that matched more than this share
    /// of its points less than the old keyframe's scan did when it was made (0 to 1; default
    /// 0.06) has found the place changed, and makes a new keyframe, which the map then shows.
    /// A corridor's match varies by a few hundredths from walk to walk; a corridor lined with
    /// crates since matches 0.80-0.88 where it matched 0.97-0.99.
    pub revisit_max_match_drop: f64,
    /// How keyframes (and, without odometry, every scan) are registered against the local
    /// map: the adaptive reach, the checks a registration must pass, and the retries. An
    /// odometry step that ends further than [`TrackerConfig::arbitration_distance`] (0.5 m) from
    /// the constant-velocity extrapolation of the last two scans is suspect (a jump, a reset):
    /// the keyframe is then registered from both guesses and the better fit kept; when the
    /// extrapolation's wins the step is counted as a fault
    /// ([`SlamReport::odometry_faults`](super::SlamReport)).
    pub tracker: TrackerConfig,
    /// Loop candidates lie within this distance of the new keyframe (thesis: 0.5 m).
    pub loop_search_radius: f64,
    /// The loop target is made of the candidate and this many keyframes on each side (thesis: 20).
    pub loop_neighbours: usize,
    /// A coarse loop alignment is accepted when its mean squared error is below this (m^2).
    pub loop_max_mean_squared_error: f64,
    /// Keyframes to wait after a loop attempt before trying again (limits optimiser calls).
    pub loop_min_keyframe_gap: usize,
    /// A refined loop alignment further than this (metres) from the coarse one is rejected.
    pub loop_max_refine_shift: f64,
    /// A loop may move the new keyframe from its estimate by at most `loop_search_radius` plus
    /// this fraction of the distance walked between the two keyframes (default 0.02: 2 %, ten
    /// times what LiDAR SLAM drifts on the simulated laps, and above Spot's own leg odometry's
    /// 1.9 %; raise it for a front end that drifts more). Drift grows with the walk,
    /// so a far loop after a long lap passes, while a look-alike place a few rooms back, whose
    /// loop would teleport the robot by metres after a short walk, is refused before it
    /// reaches the graph (repeated rooms match each other geometrically, and their loops agree
    /// with one another: a robust back end is the second line, not the only one).
    pub loop_max_drift_rate: f64,
    /// A loop may move the new keyframe up or down by at most `loop_search_radius` plus this
    /// fraction of the distance walked between the two keyframes (default 0.005: 0.5 %; the
    /// simulated walks drift under 1 cm in height over 400 m, and the thesis' LiDAR odometry
    /// 0.44-0.63 % in all). Height is the best-kept part of a walk's estimate, so this is
    /// tighter than [`loop_max_drift_rate`](Self::loop_max_drift_rate): floors that look alike
    /// (a building whose storeys repeat one plan) match each other by appearance, and their
    /// loop would pull one floor onto the other; at 0.5 % a 3 m storey is out of reach for any
    /// two visits less than 500 m of walk apart. Heights are the map frame's z, up when the
    /// first pose is level (a robot's odometry frame, or a LiDAR held level at the start).
    pub loop_max_height_drift_rate: f64,
    /// Robust kernel on loop-closure edges (a wrong loop must not wreck the map).
    #[cfg_attr(
        feature = "serde",
        serde(with = "crate::robust_kernel::optional_kernel")
    )]
    pub loop_kernel: Option<RobustKernel>,
    /// Information of odometry edges: by default fixed 1 cm / 0.2° sigmas, a stiff chain that
    /// a look-alike loop cannot stretch. [`EdgeInformation::FixedAndRegistration`] lets each
    /// edge go as soft as its registration was weak: where registration slipped along a corridor
    /// of blank walls, a loop closed later then moves those keyframes instead of bending the
    /// rest of the map (on the simulated blank-corridor lap, LiDAR-only with trackers that
    /// slip there, ATE 0.12 m after the loop against 0.40 m with the fixed sigmas). The price:
    /// a chain soft along a corridor is soft along one of identical rooms too, and with
    /// [`loop_max_drift_rate`](Self::loop_max_drift_rate) off, graduated non-convexity then
    /// keeps consistent sets of look-alike loops a few rooms long more often (with the fixed
    /// sigmas it can too: small turns within their noise bend a lap a room's length). Keep the
    /// drift gate on.
    pub odometry_information: EdgeInformation,
    /// Information of loop-closure edges: by default the refinement's own `J^T W J` (scale 1).
    /// On the simulated laps this ends where fixed 2 cm / 0.3° sigmas do (scales 1 to 100 give
    /// the same trajectories; 0.01 lets the loop sag by 1 cm), while a real loop weighs each
    /// direction as its geometry constrains it (a corridor's axis less than its width).
    pub loop_information: EdgeInformation,
    /// Voxel (metres) of the keyframe clouds kept for the map.
    pub map_voxel_size: f32,
    /// A keyframe of a dense scan (more than [`dense_scan_points`](Self::dense_scan_points))
    /// keeps its whole scan at [`map_voxel_size`](Self::map_voxel_size) (its
    /// [`keyframe_scan`](super::GraphSlam::keyframe_scan): the map and the grid's rays) only
    /// when it lies at least this far (metres) from the last keyframe that kept one; the
    /// others keep the points their registration used (the scan at the odometry's source
    /// voxel, for a backend that thins by voxel). Place recognition still reads every
    /// keyframe's whole scan as the keyframe is made, so the trajectory, the loops and the
    /// graph are the same to the bit either way; only what is kept for the map differs. At
    /// 2 Hz a hand-held sensor moves half a metre a scan and every scan is a keyframe: an
    /// OS1-128's keyframes kept 44,000 points each, 0.7 MB a scan (on a 218-scan walk at 1 m:
    /// 156 MB resident at the end against 214 MB). 0 (the default) keeps every keyframe's
    /// whole scan.
    pub keyframe_scan_spacing: f64,
    /// Scans of more than this many points (as the sensor gave them, 0: every scan) are dense,
    /// for [`keyframe_scan_spacing`](Self::keyframe_scan_spacing).
    pub dense_scan_points: usize,
    /// Scans with fewer finite points are skipped.
    pub min_scan_points: usize,
    /// Take the body's roll and pitch from the odometry, heading and position from the
    /// registration (on by default): the odometry frame's z axis is up (Spot's state
    /// estimator takes roll and pitch from its IMU) and the map frame is the odometry frame at
    /// the first scan, so the odometry's tilt is the body's in the map, while registration
    /// against a local map that drifts with the walk lets it drift (1 degree over a simulated
    /// 800 m walk, and 0.4 m of height from walking forward on it). Leave it off for odometry
    /// whose frame is not level. Scans without odometry are registered in all six degrees.
    pub odometry_gravity: bool,
    /// With [`Self::odometry_gravity`], the standard deviation (radians, 0.01 degrees) of the
    /// relative tilt of an odometry edge whose two keyframes were both levelled on the
    /// odometry's gravity: their roll and pitch come from one IMU, so the edge's rotations about
    /// its x and y axes are known that well, whatever its own information says. Without it the
    /// optimiser could spread a loop's height mismatch as a tilt of the chain (a floor climbed
    /// to by stairs ended tilted, 7.6 cm low at its far end against 4.6 cm with it).
    pub gravity_tilt_sigma: f64,
    /// Deskew keyframe scans that carry a per-point `time` channel, with the LiDAR velocity the
    /// odometry showed between the previous scan and this one (constant over the sweep). Scans
    /// without times, and scans more than a second after the previous one, are used as they
    /// are.
    pub deskew: bool,
    /// Without odometry, register each swept scan (one with per-point times) a second time
    /// together with the velocity over its sweep
    /// ([`Registrator::align_sweep`](crate::Registrator::align_sweep), for backends that offer
    /// it), and deskew it anew with that velocity instead of the constant velocity of the last
    /// two scans; taken when it matches at least the tracker's `min_inlier_ratio` and fits
    /// better by [`sweep_min_gain`](Self::sweep_min_gain) (or matches more by
    /// [`sweep_min_inlier_gain`](Self::sweep_min_inlier_gain)). Costs about
    /// one more registration a scan; needed where the sensor shakes faster than the scans come
    /// (a hand-held LiDAR recorded at 2 Hz). On by default.
    pub sweep_motion: bool,
    /// With [`sweep_motion`](Self::sweep_motion): the sweep's own registration is taken
    /// when it cuts the RMS error of the scan's registration by at least this share (0 to 1;
    /// default 0.05). Its twelve unknowns always fit a little better; where the motion over a
    /// sweep is smooth (Spot's walk: 1-4 % lower) the velocity they find is noise, and taking it
    /// drifted the skewed seed-3 lap to ATE 4.9 cm against 1.5 cm; a shaking hand's sweeps fit
    /// 15-45 % better.
    pub sweep_min_gain: f64,
    /// ... or when it matches at least this much more of the scan (a share, default 0.05) with
    /// no larger RMS error. Mid-turn, a sweep deskewed with the last step's turn rate (96°/s
    /// where the hand had nearly stopped) registers a few degrees off: its sweep's motion
    /// matched 74 % of it against 61 % at 5 % less RMS error, just short of the gain, and the
    /// scan was kept 9° off (seed 35 of the hand-held walk). Measured on 36 hand-held walks
    /// (seeds 1-36, as simulated and perturbed by 2,400 source points instead of 2,500): the
    /// largest step error 9.1° and 6.5° without it, 6.1° and 6.5° with; steps more than 2° off
    /// 33 and 44 without, 31 and 37 with; walks above 4 cm ATE 5 and 8 without, 5 and 6 with.
    /// Spot's smooth walk matches as much either way. 1 leaves the RMS error alone to decide.
    pub sweep_min_inlier_gain: f64,
    /// How a LiDAR-only scan without a gyro is predicted to turn since the last one.
    pub turn_prediction: TurnPrediction,
    /// Run one loop-closure step inside [`GraphSlam::process`](super::GraphSlam::process) after
    /// each new keyframe. When false the caller schedules
    /// [`GraphSlam::loop_closure_step`](super::GraphSlam::loop_closure_step) itself.
    pub inline_loop_closure: bool,
}

/// How a LiDAR-only scan without a gyro is predicted to turn since the last one
/// ([`GraphSlamConfig::turn_prediction`]); its translation is always extrapolated at the last
/// step's velocity.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum TurnPrediction {
    /// With the share of the last step's turn (none, half or all) that has predicted the
    /// recent scans best ([`TurnPersistence`](crate::tracking::TurnPersistence)), the default:
    /// a robot's smooth turns keep constant velocity, while a hand-held LiDAR at 2 Hz, whose
    /// turns come in jolts, holds its heading (the simulated hand-held walks, seeds 1-6: ATE
    /// 2.7-4.0 cm and no step more than 4.6° off, against 2.7-26.5 cm and 19.7° with constant
    /// velocity).
    #[default]
    Adaptive,
    /// With all of the last step's turn (constant velocity).
    ConstantVelocity,
}

impl Default for GraphSlamConfig {
    fn default() -> Self {
        Self {
            keyframe_distance: 0.20,
            keyframe_rotation: 10f64.to_radians(),
            local_map_keyframes: 40,
            revisit_radius: 0.5,
            revisit_min_inlier_ratio: 0.8,
            revisit_max_match_drop: 0.06,
            tracker: TrackerConfig::default(),
            loop_search_radius: 0.5,
            loop_neighbours: 20,
            loop_max_mean_squared_error: 0.01,
            loop_min_keyframe_gap: 5,
            loop_max_refine_shift: 0.3,
            loop_max_drift_rate: 0.02,
            loop_max_height_drift_rate: 0.005,
            loop_kernel: Some(RobustKernel::Cauchy { c: 1.0 }),
            odometry_information: EdgeInformation::Fixed {
                translation_sigma: 0.01,
                rotation_sigma: 0.2f64.to_radians(),
            },
            loop_information: EdgeInformation::FromRegistration { scale: 1.0 },
            map_voxel_size: 0.05,
            keyframe_scan_spacing: 0.0,
            dense_scan_points: 0,
            min_scan_points: 100,
            odometry_gravity: true,
            gravity_tilt_sigma: 0.01f64.to_radians(),
            deskew: true,
            sweep_motion: true,
            sweep_min_gain: 0.05,
            sweep_min_inlier_gain: 0.05,
            turn_prediction: TurnPrediction::Adaptive,
            inline_loop_closure: true,
        }
    }
}

impl EdgeInformation {
    /// Checks the sigmas (finite, positive, and with a finite `1 / sigma^2`) or the scale
    /// (finite and positive); `field` names the configuration field it sits in.
    fn validate(&self, field: Fields) -> Result<(), InvalidSetting> {
        match *self {
            Self::Fixed {
                translation_sigma,
                rotation_sigma,
            } => {
                for (setting, sigma) in [
                    (field.translation_sigma, translation_sigma),
                    (field.rotation_sigma, rotation_sigma),
                ] {
                    InvalidSetting::check(
                        sigma.is_finite() && sigma > 0.0 && (1.0 / (sigma * sigma)).is_finite(),
                        setting,
                        sigma,
                        "finite and positive (with a finite 1 / sigma^2)",
                    )?;
                }
                Ok(())
            }
            Self::FromRegistration { scale } => InvalidSetting::check(
                scale.is_finite() && scale > 0.0,
                field.scale,
                scale,
                "finite and positive",
            ),
            Self::FixedAndRegistration {
                translation_sigma,
                rotation_sigma,
                scale,
            } => {
                Self::Fixed {
                    translation_sigma,
                    rotation_sigma,
                }
                .validate(field)?;
                Self::FromRegistration { scale }.validate(field)
            }
        }
    }
}

/// The setting names of one [`EdgeInformation`] field.
#[derive(Clone, Copy)]
struct Fields {
    translation_sigma: &'static str,
    rotation_sigma: &'static str,
    scale: &'static str,
}

impl GraphSlamConfig {
    /// Checks every setting: distances, angles and thresholds finite and not negative (those
    /// that divide or bound a search positive), at least one local-map keyframe, a valid loop
    /// kernel, positive sigmas and scales, a positive map voxel.
    /// [`GraphSlam::try_new`](super::GraphSlam::try_new) calls it.
    ///
    /// # Errors
    /// [`InvalidSetting`] naming the first bad setting.
    pub fn validate(&self) -> Result<(), InvalidSetting> {
        self.validate_distances()?;
        InvalidSetting::check(
            self.gravity_tilt_sigma.is_finite()
                && self.gravity_tilt_sigma > 0.0
                && (1.0 / (self.gravity_tilt_sigma * self.gravity_tilt_sigma)).is_finite(),
            "GraphSlamConfig::gravity_tilt_sigma",
            self.gravity_tilt_sigma,
            "finite and positive (with a finite 1 / sigma^2)",
        )?;
        InvalidSetting::check(
            (0.0..1.0).contains(&self.sweep_min_gain),
            "GraphSlamConfig::sweep_min_gain",
            self.sweep_min_gain,
            "in [0, 1)",
        )?;
        InvalidSetting::check(
            self.sweep_min_inlier_gain > 0.0 && self.sweep_min_inlier_gain <= 1.0,
            "GraphSlamConfig::sweep_min_inlier_gain",
            self.sweep_min_inlier_gain,
            "in (0, 1] (1 turns it off)",
        )?;
        InvalidSetting::check(
            (0.0..=1.0).contains(&self.revisit_min_inlier_ratio),
            "GraphSlamConfig::revisit_min_inlier_ratio",
            self.revisit_min_inlier_ratio,
            "in [0, 1]",
        )?;
        InvalidSetting::check(
            (0.0..=1.0).contains(&self.revisit_max_match_drop),
            "GraphSlamConfig::revisit_max_match_drop",
            self.revisit_max_match_drop,
            "in [0, 1]",
        )?;
        let voxel = f64::from(self.map_voxel_size);
        InvalidSetting::check(
            voxel.is_finite() && voxel > 0.0,
            "GraphSlamConfig::map_voxel_size",
            voxel,
            "finite and positive",
        )?;
        InvalidSetting::check(
            self.local_map_keyframes >= 1,
            "GraphSlamConfig::local_map_keyframes",
            self.local_map_keyframes as f64,
            "at least 1",
        )?;
        if let Some(kernel) = self.loop_kernel {
            let parameter = match kernel {
                RobustKernel::Huber { delta } => delta,
                RobustKernel::Cauchy { c } | RobustKernel::GemanMcClure { c } => c,
            };
            InvalidSetting::check(
                kernel.is_valid(),
                "GraphSlamConfig::loop_kernel",
                parameter,
                "a kernel parameter finite and positive",
            )?;
        }
        self.tracker.validate()?;
        self.odometry_information.validate(Fields {
            translation_sigma: "GraphSlamConfig::odometry_information::translation_sigma",
            rotation_sigma: "GraphSlamConfig::odometry_information::rotation_sigma",
            scale: "GraphSlamConfig::odometry_information::scale",
        })?;
        self.loop_information.validate(Fields {
            translation_sigma: "GraphSlamConfig::loop_information::translation_sigma",
            rotation_sigma: "GraphSlamConfig::loop_information::rotation_sigma",
            scale: "GraphSlamConfig::loop_information::scale",
        })
    }

    /// The distances, angles and rates that must be finite and not negative.
    fn validate_distances(&self) -> Result<(), InvalidSetting> {
        InvalidSetting::check_non_negative(&[
            ("GraphSlamConfig::keyframe_distance", self.keyframe_distance),
            ("GraphSlamConfig::keyframe_rotation", self.keyframe_rotation),
            (
                "GraphSlamConfig::loop_search_radius",
                self.loop_search_radius,
            ),
            (
                "GraphSlamConfig::loop_max_mean_squared_error",
                self.loop_max_mean_squared_error,
            ),
            (
                "GraphSlamConfig::loop_max_refine_shift",
                self.loop_max_refine_shift,
            ),
            (
                "GraphSlamConfig::loop_max_drift_rate",
                self.loop_max_drift_rate,
            ),
            (
                "GraphSlamConfig::loop_max_height_drift_rate",
                self.loop_max_height_drift_rate,
            ),
            ("GraphSlamConfig::revisit_radius", self.revisit_radius),
            (
                "GraphSlamConfig::keyframe_scan_spacing",
                self.keyframe_scan_spacing,
            ),
        ])
    }
}
