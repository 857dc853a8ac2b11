//! Where a scan is expected before it is registered: from the robot's odometry since the last
//! keyframe (thesis eq. 4.1-4.2), or LiDAR-only from the constant velocity of the last two scans
//! (its rotation from the gyro when there is one, else with the share of the last turn that has
//! predicted best lately: [`TurnPersistence`]); and with what velocity its sweep is deskewed.

use nalgebra::Vector6;

use super::config::TurnPrediction;
use super::engine::{GraphSlam, GyroReading, ScanInput};
use super::keyframes::ScanPose;
use super::report::SkipReason;
use super::revisit::Reference;
use crate::geometry::{Pose3, se3_exp, se3_log};
use crate::io::StampedPose;
use crate::tracking::{TURN_SHARES, TurnPersistence};
use crate::traits::optimizer::Optimizer;
use crate::traits::registrator::MapRegistrator;

/// What the engine expects of a scan.
pub(super) enum Prediction {
    /// The first scan: the first keyframe, at `pose` (the map frame is the odometry frame
    /// there, or without odometry the body frame), deskewed with `velocity`.
    First {
        pose: Pose3,
        velocity: Option<Vector6<f64>>,
    },
    /// An odometry step shorter than a keyframe's: the scan rides, unregistered, on `keyframe`
    /// at the odometry's `keyframe_t_lidar`.
    Short {
        keyframe: usize,
        keyframe_t_lidar: Pose3,
    },
    /// An odometry step long enough for a keyframe: registered from `guesses` (the odometry's
    /// first; the constant-velocity extrapolation too when the step looks suspect), deskewed
    /// with `velocity`.
    Odometry {
        guesses: Vec<Pose3>,
        velocity: Option<Vector6<f64>>,
    },
    /// LiDAR-only: registered from `guess`, deskewed with `velocity`, then refined with its
    /// sweep's own motion; a keyframe once it moved far enough from `reference`.
    LidarOnly {
        guess: Pose3,
        velocity: Option<Vector6<f64>>,
        reference: Reference,
    },
}

impl<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>> GraphSlam<R, C, O> {
    /// The prediction for `scan` (whose LiDAR pose in the odometry frame is `odom_t_lidar`, and
    /// whose points have different times when `swept`); the velocity since the last scan is
    /// taken from the odometry here. A first swept scan with odometry waits for a second one
    /// ([`SkipReason::AwaitingVelocity`]).
    pub(super) fn predict(
        &mut self,
        scan: &ScanInput<'_>,
        odom_t_lidar: Option<Pose3>,
        swept: bool,
    ) -> Result<Prediction, SkipReason> {
        self.turn_basis = None;
        let odometry_velocity = self.odometry_velocity(scan.stamp, odom_t_lidar, swept);
        let Some(reference) = self.reference() else {
            if swept && odom_t_lidar.is_some() && odometry_velocity.is_none() {
                self.last_stamp = scan.stamp;
                return Err(SkipReason::AwaitingVelocity);
            }
            return Ok(Prediction::First {
                pose: odom_t_lidar.unwrap_or(scan.body_t_lidar),
                velocity: odometry_velocity,
            });
        };
        // Odometry now and at the reference: predicted from it. Otherwise LiDAR-only.
        if let (Some(now), Some(then)) = (odom_t_lidar, reference.odom_t_lidar) {
            return Ok(self.odometry_prediction(
                scan.stamp,
                now,
                then,
                &reference,
                odometry_velocity,
            ));
        }
        let (guess, velocity, basis) = self
            .motion_prior(scan.stamp)
            .unwrap_or_else(|| (self.reference_pose(&reference), None, None));
        let gyro_before = self.report.gyro_predictions;
        let (guess, velocity) = self.gyro_prior(scan, guess, velocity);
        if basis.is_some() && self.report.gyro_predictions == gyro_before {
            self.report.turn_shares[self.turn_choice()] += 1;
        }
        self.turn_basis = basis;
        Ok(Prediction::LidarOnly {
            guess,
            velocity: velocity.filter(|_| swept),
            reference,
        })
    }

    /// The odometry's velocity (LiDAR-frame twist per second) since the previous scan, for
    /// deskewing a `swept` scan at `stamp`; remembers this scan's odometry for the next.
    fn odometry_velocity(
        &mut self,
        stamp: f64,
        odom_t_lidar: Option<Pose3>,
        swept: bool,
    ) -> Option<Vector6<f64>> {
        let Some(now) = odom_t_lidar else {
            self.last_odometry = None;
            return None;
        };
        self.last_odometry
            .replace(StampedPose { stamp, pose: now })
            .and_then(|last| {
                let dt = stamp - last.stamp;
                (swept && dt > 0.0 && dt <= 1.0).then(|| se3_log(&(last.pose.inverse() * now)) / dt)
            })
    }

    /// A scan with odometry: predicted from the odometry since `reference` (whose odometry is
    /// `reference_odom_t_lidar`); registered only once it moved far enough for a new keyframe.
    fn odometry_prediction(
        &self,
        stamp: f64,
        odom_t_lidar: Pose3,
        reference_odom_t_lidar: Pose3,
        reference: &Reference,
        velocity: Option<Vector6<f64>>,
    ) -> Prediction {
        let delta = reference_odom_t_lidar.inverse() * odom_t_lidar;
        let predicted = self.reference_pose(reference) * delta;
        let moved = delta.translation.vector.norm() >= self.config.keyframe_distance
            || delta.rotation.angle() >= self.config.keyframe_rotation;
        if !moved {
            return Prediction::Short {
                keyframe: reference.keyframe,
                keyframe_t_lidar: reference.keyframe_t_lidar * delta,
            };
        }
        let prior = self.motion_prior(stamp);
        let suspect = prior.as_ref().is_some_and(|(p, _, _)| {
            (p.inverse() * predicted).translation.vector.norm()
                > self.config.tracker.arbitration_distance
        });
        // A suspect odometry step would deskew with its jump as the velocity: take the
        // extrapolation's instead. The extrapolation arbitrates only a suspect step, so that
        // clean input runs exactly as without the check.
        let velocity = if suspect {
            velocity.and(prior.as_ref().and_then(|(_, v, _)| *v))
        } else {
            velocity
        };
        let mut guesses = vec![predicted];
        guesses.extend(prior.filter(|_| suspect).map(|(guess, _, _)| guess));
        Prediction::Odometry { guesses, velocity }
    }

    /// `predicted` and `velocity` with their rotation taken from the gyro when this scan and the
    /// last one both have a gyro orientation: the last scan's orientation turned by the body's
    /// rotation between the two (in the LiDAR frame), the angular velocity that rotation over
    /// the time between them; translation as predicted.
    fn gyro_prior(
        &mut self,
        scan: &ScanInput<'_>,
        predicted: Pose3,
        velocity: Option<Vector6<f64>>,
    ) -> (Pose3, Option<Vector6<f64>>) {
        let (
            Some(GyroReading {
                stamp: then,
                orientation: g0,
            }),
            Some(g1),
            Some(last),
        ) = (
            self.last_gyro,
            scan.gyro_orientation,
            self.scan_poses.last(),
        )
        else {
            return (predicted, velocity);
        };
        let dt = scan.stamp - then;
        if dt.is_nan() || dt <= 0.0 || !g1.coords.iter().all(|v| v.is_finite()) {
            return (predicted, velocity);
        }
        let mount = scan.body_t_lidar.rotation;
        let turn = mount.inverse() * g0.inverse() * g1 * mount;
        let x1 = self.keyframe_pose(last.keyframe) * last.keyframe_t_lidar;
        let mut rotation = x1.rotation * turn;
        rotation.renormalize();
        self.report.gyro_predictions += 1;
        let velocity = velocity.map(|mut v| {
            v.fixed_rows_mut::<3>(3)
                .copy_from(&(turn.scaled_axis() / dt));
            v
        });
        (Pose3::from_parts(predicted.translation, rotation), velocity)
    }

    /// The share of the last step's turn a LiDAR-only prediction repeats: all of it unless
    /// [`TurnPrediction::Adaptive`].
    fn turn_share(&self) -> f64 {
        TURN_SHARES[self.turn_choice()]
    }

    /// The index in [`TURN_SHARES`] of [`Self::turn_share`].
    fn turn_choice(&self) -> usize {
        match self.config.turn_prediction {
            TurnPrediction::Adaptive => self.turns.choice(),
            TurnPrediction::ConstantVelocity => TURN_SHARES.len() - 1,
        }
    }

    /// The LiDAR pose at `stamp` extrapolated at the velocity of the last two accepted scans
    /// (with [`Self::turn_share`] of its turn), with that velocity (LiDAR-frame twist per second)
    /// and what the extrapolation was made from; the last scan's pose held, and
    /// no velocity, when there is only one or the scans are more than a second apart. `None`
    /// before the first scan. Read from the scans' keyframes, so a loop closure that moved them
    /// moves the extrapolation too.
    fn motion_prior(&self, stamp: f64) -> Option<(Pose3, Option<Vector6<f64>>, Option<TurnBasis>)> {
        // Each scan's pose in the middle of its sweep: registering a deskewed sweep fixes its
        // middle whatever velocity it was deskewed with, while its start moves with that
        // velocity's error. A velocity taken from the starts would feed that error back into
        // the next deskew, and scan after scan it grows (LiDAR-only, 5 Hz, 12 cm a sweep).
        let middle = |s: &ScanPose| {
            let x = self.keyframe_pose(s.keyframe) * s.keyframe_t_lidar;
            s.sweep.map_or((s.stamp, x), |w| {
                (s.stamp + w.middle, x * se3_exp(&(w.velocity * w.middle)))
            })
        };
        let (last, earlier) = self.scan_poses.split_last()?;
        let x1 = self.keyframe_pose(last.keyframe) * last.keyframe_t_lidar;
        let (t1, m1) = middle(last);
        let velocity = earlier.last().and_then(|prev| {
            let (t0, m0) = middle(prev);
            let (dt0, dt) = (t1 - t0, stamp - t1);
            (dt0 > 0.0 && dt0 <= 1.0 && dt > 0.0 && dt <= 1.0)
                .then(|| se3_log(&(m0.inverse() * m1)) / dt0)
        });
        let basis = velocity.map(|v| TurnBasis {
            from: m1,
            velocity: v,
            dt: stamp - t1,
        });
        let pose = basis.as_ref().map_or(x1, |b| b.predict(self.turn_share()));
        Some((pose, velocity, basis))
    }
}

/// What a LiDAR-only prediction was extrapolated from: the last scan's mid-sweep pose, the
/// velocity of the last step and the time since; scored against the registered pose
/// ([`TurnPersistence::record`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct TurnBasis {
    from: Pose3,
    velocity: Vector6<f64>,
    dt: f64,
}

impl TurnBasis {
    /// The prediction with `share` of the last step's turn.
    fn predict(&self, share: f64) -> Pose3 {
        TurnPersistence::predict(&self.from, &self.velocity, self.dt, share)
    }

    /// Scores the turn shares on the pose the scan registered at.
    pub(super) fn score(&self, turns: &mut TurnPersistence, registered: &Pose3, extent: f64) {
        turns.record(&self.from, &self.velocity, self.dt, registered, extent);
    }
}
