//! A gyro integrated into the body's orientation: the angular velocity of each
//! `sensor_msgs/Imu` reading (rad/s, in the IMU's frame) turned into the body frame by the IMU's
//! fixed mounting and integrated from reading to reading, then interpolated at any stamp in
//! between. The orientation starts at the identity at the first reading and drifts with the
//! gyro's bias, but its change between two scans is the rotation a tracker can predict with.
//!
//! Between two readings at `t0 < t1` (`dt = t1 - t0`) with body rates `w0` and `w1`, the rate is
//! taken to change linearly, and its integral turned into a rotation by the exponential map;
//! at `t1` this is the midpoint rule, and a stamp `t` in between gets the same integral up to
//! `t` (with `s = (t - t0) / dt`):
//!
//! ```text
//! R(t1) = R(t0) * Exp(dt * (w0 + w1) / 2)
//! R(t)  = R(t0) * Exp((t - t0) * (w0 + s / 2 * (w1 - w0)))
//! ```
//!
//! Both are exact for a constant rate, and for a rate changing linearly about a fixed axis;
//! otherwise the error over an interval is of third order in `dt`.
//!
//! What the data can do wrong, and what is done (each counted in [`GyroCounts`]):
//! - a reading stamped at or before the last one used (out of order, or repeated) is dropped;
//! - a reading with a non-finite rate (or a rate whose norm overflows) is dropped: the interval
//!   from the reading before it to the one after is integrated as one;
//! - a reading in another frame than the first reading's is dropped (its mounting is unknown);
//! - a gap of more than [`MAX_GYRO_GAP`] between two readings is not integrated across: the
//!   orientation is held and a new segment starts at the reading after it. A stamp inside the
//!   gap has no orientation, and [`GyroIntegrator::sample_orientation`] gives none to the first
//!   sample of a new segment when the sample before it had one in an older segment, so two
//!   consecutive samples that both have an orientation never straddle a gap.

use std::cmp::Ordering;
use std::collections::VecDeque;

use nalgebra::{UnitQuaternion, Vector3};

use crate::record::ros_messages::ImuReading;

/// The longest interval between two readings that is integrated (seconds). IMUs publish at
/// 100-1000 Hz; a longer silence is a dropped stream, across which a held rate would be a guess.
pub const MAX_GYRO_GAP: f64 = 0.5;

/// What became of the readings pushed so far.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GyroCounts {
    /// Readings integrated (the first one included).
    pub used: usize,
    /// Readings stamped at or before the last one used, dropped.
    pub out_of_order: usize,
    /// Readings with a non-finite angular velocity, dropped.
    pub non_finite: usize,
    /// Readings in another frame than the first reading's, dropped.
    pub other_frame: usize,
    /// Gaps of more than [`MAX_GYRO_GAP`] between readings used, not integrated across.
    pub gaps: usize,
}

impl GyroCounts {
    /// Readings dropped, for any reason.
    #[must_use]
    pub fn dropped(&self) -> usize {
        self.out_of_order + self.non_finite + self.other_frame
    }
}

/// What [`GyroIntegrator::push`] did with a reading.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GyroStep {
    /// The first reading: the orientation starts at the identity.
    Started,
    /// Integrated from the reading before.
    Integrated,
    /// Used after a gap of more than [`MAX_GYRO_GAP`]: the orientation was held across it.
    AfterGap,
    /// Dropped: stamped at or before the last reading used.
    OutOfOrder,
    /// Dropped: a non-finite rate.
    NonFinite,
    /// Dropped: in another frame than the first reading's.
    OtherFrame,
}

/// One reading used: its stamp, the body rate, the orientation there and the segment it belongs
/// to.
#[derive(Clone, Copy, Debug)]
struct Knot {
    stamp: f64,
    /// Rad/s in the body frame.
    rate: Vector3<f64>,
    orientation: UnitQuaternion<f64>,
    segment: usize,
}

/// The orientation at `stamp`, from reading `k0` to the next one at `t1` with body rate `w1`
/// (`k0.stamp < stamp <= t1`), the rate linear in time between the two.
fn between(k0: &Knot, t1: f64, w1: Vector3<f64>, stamp: f64) -> UnitQuaternion<f64> {
    let tau = stamp - k0.stamp;
    let mean = k0.rate + (w1 - k0.rate) * (0.5 * tau / (t1 - k0.stamp));
    let turn = UnitQuaternion::from_scaled_axis(mean * tau);
    // Renormalised so that rounding does not build up over a long recording.
    UnitQuaternion::new_normalize((k0.orientation * turn).into_inner())
}

/// Integrates a gyro's readings into the body's orientation, `start_R_body`, and interpolates
/// it at stamps between readings. Memory: the readings since the last
/// [`prune_before`](Self::prune_before).
#[derive(Clone, Debug)]
pub struct GyroIntegrator {
    frame: String,
    body_r_imu: UnitQuaternion<f64>,
    first: Option<f64>,
    knots: VecDeque<Knot>,
    segment: usize,
    counts: GyroCounts,
    /// The segment of the last sample's orientation (`None` when it had none).
    previous_sample: Option<usize>,
}

impl GyroIntegrator {
    /// An integrator of readings in `frame`, mounted at `body_r_imu` (the IMU frame's rotation in
    /// the body frame).
    #[must_use]
    pub fn new(frame: &str, body_r_imu: UnitQuaternion<f64>) -> Self {
        Self {
            frame: frame.to_owned(),
            body_r_imu,
            first: None,
            knots: VecDeque::new(),
            segment: 0,
            counts: GyroCounts::default(),
            previous_sample: None,
        }
    }

    /// The frame readings must be in.
    #[must_use]
    pub fn frame(&self) -> &str {
        &self.frame
    }

    /// Take in one reading (see the module's documentation for what is dropped).
    pub fn push(&mut self, reading: &ImuReading) -> GyroStep {
        let step = self.step(reading);
        match step {
            GyroStep::Started | GyroStep::Integrated => self.counts.used += 1,
            GyroStep::AfterGap => {
                self.counts.used += 1;
                self.counts.gaps += 1;
            }
            GyroStep::OutOfOrder => self.counts.out_of_order += 1,
            GyroStep::NonFinite => self.counts.non_finite += 1,
            GyroStep::OtherFrame => self.counts.other_frame += 1,
        }
        step
    }

    fn step(&mut self, reading: &ImuReading) -> GyroStep {
        if reading.frame_id != self.frame {
            return GyroStep::OtherFrame;
        }
        let rate = self.body_r_imu * reading.angular_velocity;
        if !(rate.iter().all(|v| v.is_finite()) && rate.norm().is_finite()) {
            return GyroStep::NonFinite;
        }
        let stamp = reading.stamp;
        let Some(&last) = self.knots.back() else {
            self.first = Some(stamp);
            self.knots.push_back(Knot {
                stamp,
                rate,
                orientation: UnitQuaternion::identity(),
                segment: self.segment,
            });
            return GyroStep::Started;
        };
        // Not after the last one (or a NaN stamp).
        if stamp.partial_cmp(&last.stamp) != Some(Ordering::Greater) {
            return GyroStep::OutOfOrder;
        }
        let (orientation, step) = if stamp - last.stamp > MAX_GYRO_GAP {
            self.segment += 1;
            (last.orientation, GyroStep::AfterGap)
        } else {
            (between(&last, stamp, rate, stamp), GyroStep::Integrated)
        };
        self.knots.push_back(Knot {
            stamp,
            rate,
            orientation,
            segment: self.segment,
        });
        step
    }

    /// What became of the readings so far.
    #[must_use]
    pub fn counts(&self) -> GyroCounts {
        self.counts
    }

    /// The first reading used's stamp.
    #[must_use]
    pub fn first_stamp(&self) -> Option<f64> {
        self.first
    }

    /// The last reading used's stamp.
    #[must_use]
    pub fn last_stamp(&self) -> Option<f64> {
        self.knots.back().map(|k| k.stamp)
    }

    /// `start_R_body` at `stamp` and its segment; `None` outside the readings kept, or inside a
    /// gap.
    fn at(&self, stamp: f64) -> Option<(UnitQuaternion<f64>, usize)> {
        let i = self.knots.partition_point(|k| k.stamp < stamp);
        let k1 = self.knots.get(i)?;
        // A stamp held exactly gives the stored orientation.
        #[allow(clippy::float_cmp)]
        if k1.stamp == stamp {
            return Some((k1.orientation, k1.segment));
        }
        let k0 = self.knots.get(i.checked_sub(1)?)?;
        if k0.segment != k1.segment {
            return None;
        }
        Some((between(k0, k1.stamp, k1.rate, stamp), k1.segment))
    }

    /// The body's orientation at `stamp` (`start_R_body`), interpolated between the readings
    /// around it; `None` before the first reading kept, after the last one, or inside a gap.
    #[must_use]
    pub fn orientation_at(&self, stamp: f64) -> Option<UnitQuaternion<f64>> {
        self.at(stamp).map(|(q, _)| q)
    }

    /// The orientation for the next sample, at `stamp`: as [`orientation_at`](Self::orientation_at),
    /// but `None` when the previous sample's orientation lies in an older segment (a gap since
    /// it), so that the change between two consecutive samples that both have one is always
    /// integrated, never held across a gap. Samples must be asked for in stamp order.
    pub fn sample_orientation(&mut self, stamp: f64) -> Option<UnitQuaternion<f64>> {
        let at = self.at(stamp);
        let previous = std::mem::replace(&mut self.previous_sample, at.map(|(_, s)| s));
        match (at, previous) {
            (Some((_, segment)), Some(before)) if before != segment => None,
            (at, _) => at.map(|(q, _)| q),
        }
    }

    /// Forget readings not needed for stamps from `stamp` on (the one before it is kept).
    pub fn prune_before(&mut self, stamp: f64) {
        while self.knots.len() > 1 && self.knots[1].stamp <= stamp {
            self.knots.pop_front();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    fn reading(stamp: f64, frame: &str, w: [f64; 3]) -> ImuReading {
        ImuReading {
            stamp,
            frame_id: frame.into(),
            orientation: None,
            angular_velocity: Vector3::from(w),
            linear_acceleration: Vector3::zeros(),
        }
    }

    /// A gyro turned a quarter about z: its x axis is the body's y.
    fn quarter_turned() -> GyroIntegrator {
        GyroIntegrator::new(
            "imu",
            UnitQuaternion::from_euler_angles(0.0, 0.0, FRAC_PI_2),
        )
    }

    #[test]
    fn a_constant_rate_is_integrated_exactly_in_the_body_frame() {
        let mut gyro = quarter_turned();
        // 0.3 rad/s about the IMU's x axis, that is about the body's y axis.
        for i in 0..=100 {
            let step = gyro.push(&reading(10.0 + 0.01 * f64::from(i), "imu", [0.3, 0.0, 0.0]));
            assert_ne!(step, GyroStep::OutOfOrder);
        }
        let want = UnitQuaternion::from_euler_angles(0.0, 0.3 * 0.555, 0.0);
        let got = gyro.orientation_at(10.555).unwrap();
        assert!(got.angle_to(&want) < 1e-12, "{}", got.angle_to(&want));
        assert!(gyro.orientation_at(9.99).is_none());
        assert!(gyro.orientation_at(11.001).is_none());
        assert_eq!(gyro.counts().used, 101);
        // Pruned: what lies before the stamp kept is gone, what follows stays.
        gyro.prune_before(10.5);
        assert!(gyro.orientation_at(10.45).is_none());
        assert!(gyro.orientation_at(10.5).is_some());
    }

    #[test]
    fn a_rate_changing_linearly_about_one_axis_is_integrated_exactly_between_readings() {
        // w(t) = 0.2 + 3 t about the body's z axis: the angle is 0.2 t + 1.5 t^2.
        let mut gyro = GyroIntegrator::new("imu", UnitQuaternion::identity());
        for i in 0..=4 {
            let t = 0.05 * f64::from(i);
            gyro.push(&reading(t, "imu", [0.0, 0.0, 0.2 + 3.0 * t]));
        }
        for t in [0.05, 0.071, 0.13, 0.2] {
            let want = 0.2 * t + 1.5 * t * t;
            let got = gyro.orientation_at(t).unwrap().scaled_axis().z;
            assert!((got - want).abs() < 1e-14, "at {t}: {got} vs {want}");
        }
    }

    #[test]
    fn bad_readings_are_dropped_and_counted() {
        let mut gyro = quarter_turned();
        let z = [0.0, 0.0, 1.0];
        for (stamp, frame, rate, step) in [
            (1.0, "imu", z, GyroStep::Started),
            (1.01, "imu", [f64::NAN, 0.0, 1.0], GyroStep::NonFinite),
            (1.01, "imu", [f64::MAX, f64::MAX, 0.0], GyroStep::NonFinite),
            (1.02, "other", z, GyroStep::OtherFrame),
            (1.02, "imu", z, GyroStep::Integrated),
            (1.015, "imu", z, GyroStep::OutOfOrder),
            (1.02, "imu", z, GyroStep::OutOfOrder),
        ] {
            assert_eq!(gyro.push(&reading(stamp, frame, rate)), step, "at {stamp}");
        }
        assert_eq!(
            gyro.counts(),
            GyroCounts {
                used: 2,
                out_of_order: 2,
                non_finite: 2,
                other_frame: 1,
                gaps: 0
            }
        );
        // The NaN reading's interval integrated as one with the next.
        let got = gyro.orientation_at(1.02).unwrap();
        assert!((got.angle() - 0.02).abs() < 1e-12);
    }

    #[test]
    fn a_gap_is_not_integrated_across_and_the_sample_after_it_has_no_orientation() {
        let mut gyro = quarter_turned();
        for t in [0.0, 0.1, 0.2, 0.9, 1.0, 1.1] {
            gyro.push(&reading(t, "imu", [0.0, 0.0, 1.0]));
        }
        assert_eq!(gyro.counts().gaps, 1);
        // Held across the gap, none inside it.
        let before = gyro.orientation_at(0.2).unwrap();
        assert!(gyro.orientation_at(0.5).is_none());
        assert_eq!(gyro.orientation_at(0.9).unwrap(), before);
        // Samples at 0.15 and 0.95 (none in the gap): the second is flagged by having none;
        // the third has one again, 0.1 rad on from the sample at 0.95's orientation.
        assert!(gyro.sample_orientation(0.15).is_some());
        assert!(gyro.sample_orientation(0.95).is_none());
        let q = gyro.sample_orientation(1.05).unwrap();
        let at_095 = gyro.orientation_at(0.95).unwrap();
        assert!((at_095.angle_to(&q) - 0.1).abs() < 1e-12);
        // Inside the gap: none, and the sample after it has one (there is no pair to mislead).
        let mut gyro = quarter_turned();
        for t in [0.0, 0.1, 0.9, 1.0] {
            gyro.push(&reading(t, "imu", [0.0, 0.0, 1.0]));
        }
        assert!(gyro.sample_orientation(0.05).is_some());
        assert!(gyro.sample_orientation(0.5).is_none());
        assert!(gyro.sample_orientation(0.95).is_some());
    }
}
