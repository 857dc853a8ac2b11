//! Spot's leg odometry as the robot reports it: `odom_T_body`, drifting about 1.9 % of the
//! distance walked (the figure the thesis measured), vertical drift included.

use nalgebra::{Translation3, UnitQuaternion, Vector3};
use slam_core::Pose3;

use crate::sim::SimError;
use crate::sim::rng::SimRng;
use crate::sim::setting_checks::require_non_negative;

/// How the reported odometry drifts.
///
/// Each step the true body motion is integrated with three errors:
/// - a bias: the odometry frame position moves by `drift_rate * d` along a fixed direction (drawn
///   per seed, with vertical component `vertical_fraction`) for a step of length `d`, so the
///   end-point error grows by `drift_rate` per metre on any route, loops included (a body-frame
///   scale error would cancel around a loop, which real drift does not);
/// - a heading random walk of `yaw_noise` rad per square-root metre, which bends the
///   trajectory as slipping feet do;
/// - white translation noise of `translation_noise` m per square-root metre.
///
/// With the defaults the relative drift (end-point error over distance) is 1.9 % plus a few
/// tenths of a percent of noise.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct OdometryDriftConfig {
    /// Bias drift per metre walked, 0.019 (1.9 %).
    pub drift_rate: f64,
    /// Vertical share of the bias direction (sine of its elevation), 0.2: about 0.4 % of the
    /// distance ends up as height error.
    pub vertical_fraction: f64,
    /// Heading random walk, 0.0006 rad per square-root metre.
    pub yaw_noise: f64,
    /// Translation noise, 0.002 m per square-root metre.
    pub translation_noise: f64,
}

impl Default for OdometryDriftConfig {
    fn default() -> Self {
        Self {
            drift_rate: 0.019,
            vertical_fraction: 0.2,
            yaw_noise: 0.0006,
            translation_noise: 0.002,
        }
    }
}

/// Integrates true body motion into drifting odometry.
#[derive(Clone, Debug)]
pub struct OdometryModel {
    config: OdometryDriftConfig,
    rng: SimRng,
    bias_direction: Vector3<f64>,
    last_truth: Option<Pose3>,
    odom_t_body: Pose3,
}

impl OdometryModel {
    /// A model for `seed`. The odometry frame starts where the robot first stands, level and
    /// facing its heading (`odom_T_body` at the first pose is the body's roll and pitch
    /// alone), as Spot's does after power-on.
    ///
    /// # Errors
    /// [`SimError::InvalidConfig`] for negative or non-finite values or a vertical fraction
    /// outside `[-1, 1]`.
    pub fn new(config: OdometryDriftConfig, seed: u64) -> Result<Self, SimError> {
        let c = &config;
        require_non_negative(&[
            ("drift_rate", c.drift_rate),
            ("yaw_noise", c.yaw_noise),
            ("translation_noise", c.translation_noise),
        ])?;
        if !(-1.0..=1.0).contains(&c.vertical_fraction) {
            return Err(SimError::invalid(
                "vertical_fraction",
                c.vertical_fraction,
                "within [-1, 1]",
            ));
        }
        let mut rng = SimRng::new(seed, 0x0d0e_7e11);
        let heading = rng.range(0.0, std::f64::consts::TAU);
        let v = c.vertical_fraction;
        let horizontal = (1.0 - v * v).sqrt();
        let bias_direction = Vector3::new(
            horizontal * heading.cos(),
            horizontal * heading.sin(),
            if rng.chance(0.5) { v } else { -v },
        );
        Ok(Self {
            config,
            rng,
            bias_direction,
            last_truth: None,
            odom_t_body: Pose3::identity(),
        })
    }

    /// The unit direction (odometry frame) along which the bias drifts.
    #[must_use]
    pub fn bias_direction(&self) -> Vector3<f64> {
        self.bias_direction
    }

    /// Feed the next true pose `world_T_body`; returns the reported `odom_T_body`.
    pub fn step(&mut self, world_t_body: &Pose3) -> Pose3 {
        self.step_slipping(world_t_body, 1.0)
    }

    /// As [`OdometryModel::step`] with the bias and both noises `slip` times larger over this
    /// step: feet slip more on stairs (the thesis saw Spot's odometry drift most there).
    pub(crate) fn step_slipping(&mut self, world_t_body: &Pose3, slip: f64) -> Pose3 {
        let Some(last) = self.last_truth.replace(*world_t_body) else {
            // The odometry frame is level, at the first pose's position and heading.
            let (roll, pitch, _) = world_t_body.rotation.euler_angles();
            self.odom_t_body.rotation = UnitQuaternion::from_euler_angles(roll, pitch, 0.0);
            return self.odom_t_body;
        };
        let delta = last.inverse() * world_t_body;
        let d = delta.translation.vector.norm();
        let c = &self.config;
        let s = slip * d.sqrt();
        let yaw = self.rng.normal(c.yaw_noise * s);
        let noise = Vector3::new(
            self.rng.normal(c.translation_noise * s),
            self.rng.normal(c.translation_noise * s),
            self.rng.normal(c.translation_noise * s),
        );
        let noisy = Pose3::from_parts(
            Translation3::from(delta.translation.vector + noise),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw) * delta.rotation,
        );
        self.odom_t_body *= noisy;
        self.odom_t_body.translation.vector += self.bias_direction * (slip * c.drift_rate * d);
        // Spot's state estimator takes roll and pitch from its IMU: the odometry frame stays
        // level and the body's roll and pitch in it are the true ones; only its heading and
        // position drift. (The heading noise composed about a body pitched on stairs used to
        // leave the odometry tilted for good, 0.1 degrees after one flight, which no IMU keeps.)
        let (roll, pitch, _) = world_t_body.rotation.euler_angles();
        let (_, _, heading) = self.odom_t_body.rotation.euler_angles();
        self.odom_t_body.rotation = UnitQuaternion::from_euler_angles(roll, pitch, heading);
        self.odom_t_body
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The end-point error of 10 m walked straight east in 0.1 m steps, slipping `slip` times.
    fn end_error(slip: f64) -> f64 {
        let mut model = OdometryModel::new(OdometryDriftConfig::default(), 7).unwrap();
        let mut truth = Pose3::identity();
        let mut odom = model.step_slipping(&truth, slip);
        for _ in 0..100 {
            truth.translation.vector.x += 0.1;
            odom = model.step_slipping(&truth, slip);
        }
        (odom.translation.vector - truth.translation.vector).norm()
    }

    /// Up a flight (nose up 30 degrees, slipping three times as much) and on along a level
    /// floor: the body's roll and pitch in the odometry are the true ones at every step, while
    /// its heading drifts.
    #[test]
    fn the_odometry_keeps_the_true_roll_and_pitch_on_stairs() {
        let mut model = OdometryModel::new(OdometryDriftConfig::default(), 11).unwrap();
        let mut truth = Pose3::identity();
        let mut heading_drift: f64 = 0.0;
        for k in 0..200 {
            let (pitch, rise) = if k < 100 { (-0.52, 0.05) } else { (0.0, 0.0) };
            truth.translation.vector += Vector3::new(0.1, 0.0, rise);
            truth.rotation = UnitQuaternion::from_euler_angles(0.01 * f64::from(k % 3), pitch, 0.3);
            let slip = if k < 100 { 3.0 } else { 1.0 };
            let odom = model.step_slipping(&truth, slip);
            let (r, p, y) = odom.rotation.euler_angles();
            let (tr, tp, ty) = truth.rotation.euler_angles();
            assert!(
                (r - tr).abs() < 1e-9 && (p - tp).abs() < 1e-9,
                "step {k}: {r} {p} against {tr} {tp}"
            );
            heading_drift = heading_drift.max((y - ty).abs());
        }
        assert!(heading_drift > 1e-4, "the heading drifts: {heading_drift}");
    }

    #[test]
    fn slipping_three_times_drifts_about_three_times_as_far() {
        let (flat, stairs) = (end_error(1.0), end_error(3.0));
        // The bias alone: 1.9 % of 10 m, then three times that; noise adds a few millimetres.
        assert!((flat - 0.19).abs() < 0.03, "flat {flat}");
        assert!(
            (stairs / flat - 3.0).abs() < 0.3,
            "stairs {stairs}, flat {flat}"
        );
    }
}
