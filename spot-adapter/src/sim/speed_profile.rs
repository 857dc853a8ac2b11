//! A one-dimensional move under a speed and an acceleration limit (a trapezoidal speed profile):
//! how a simulated walker covers a leg of its route, and how it turns its body at a corner.

/// One phase of constant acceleration: its duration (seconds), the speed at its start and at its
/// end, and the distance covered before it began.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Phase {
    duration: f64,
    from_speed: f64,
    to_speed: f64,
    start: f64,
}

impl Phase {
    /// Distance from the phase's start after `tau` seconds (`0 <= tau <= duration`).
    fn covered(&self, tau: f64) -> f64 {
        let accel = if self.duration > 0.0 {
            (self.to_speed - self.from_speed) / self.duration
        } else {
            0.0
        };
        self.from_speed * tau + 0.5 * accel * tau * tau
    }
}

/// Covering `distance` from speed `start_speed` to speed `end_speed`: accelerate at
/// `acceleration` up to `max_speed` (or as far as the distance allows), cruise, and slow down at
/// `acceleration` to arrive at `end_speed`. Distances and speeds in any one unit (metres and m/s
/// along a leg, radians and rad/s through a turn).
///
/// When the distance is too short to change speed at `acceleration`, the speed changes evenly
/// over it instead (the only case where the acceleration exceeds its limit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct TrapezoidMove {
    phases: [Phase; 3],
    distance: f64,
    duration: f64,
}

impl TrapezoidMove {
    /// The move; the caller checks that `distance >= 0`, `0 <= start_speed, end_speed <=
    /// max_speed`, and `max_speed` and `acceleration` are positive, all finite.
    pub(crate) fn new(
        distance: f64,
        start_speed: f64,
        end_speed: f64,
        max_speed: f64,
        acceleration: f64,
    ) -> Self {
        let (v0, v1, a) = (start_speed, end_speed, acceleration);
        // The peak speed of a triangle profile over exactly `distance`, capped.
        let peak = (a * distance + 0.5 * (v0 * v0 + v1 * v1))
            .sqrt()
            .min(max_speed);
        let durations = if peak < v0.max(v1) {
            // Too short to reach the end speed at `a`: one even change of speed.
            let t = if v0 + v1 > 0.0 {
                2.0 * distance / (v0 + v1)
            } else {
                0.0
            };
            [(t, v0, v1), (0.0, v1, v1), (0.0, v1, v1)]
        } else {
            let up = (peak * peak - v0 * v0) / (2.0 * a);
            let down = (peak * peak - v1 * v1) / (2.0 * a);
            let cruise = (distance - up - down).max(0.0);
            [
                ((peak - v0) / a, v0, peak),
                (if peak > 0.0 { cruise / peak } else { 0.0 }, peak, peak),
                ((peak - v1) / a, peak, v1),
            ]
        };
        let mut start = 0.0;
        let phases = durations.map(|(duration, from_speed, to_speed)| {
            let phase = Phase {
                duration,
                from_speed,
                to_speed,
                start,
            };
            start += phase.covered(duration);
            phase
        });
        Self {
            phases,
            distance,
            duration: phases.iter().map(|p| p.duration).sum(),
        }
    }

    /// Seconds the move takes.
    pub(crate) fn duration(&self) -> f64 {
        self.duration
    }

    /// Distance covered after `t` seconds: 0 before the move, `distance` after it.
    pub(crate) fn position(&self, t: f64) -> f64 {
        if t >= self.duration {
            return self.distance;
        }
        let mut tau = t.max(0.0);
        for p in &self.phases {
            if tau <= p.duration {
                return (p.start + p.covered(tau)).min(self.distance);
            }
            tau -= p.duration;
        }
        self.distance
    }
}

#[cfg(test)]
// Exact values where the move is clamped: they are returned as given.
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;

    /// Speeds and accelerations by finite differences, against the limits.
    fn check(m: &TrapezoidMove, max_speed: f64, acceleration: f64) {
        let dt = 1e-3;
        // Within the move: after it the position stops, whatever the end speed.
        let n = (m.duration() / dt).floor() as usize;
        let x: Vec<f64> = (0..=n).map(|k| m.position(k as f64 * dt)).collect();
        for w in x.windows(3) {
            let (v, a) = (
                (w[2] - w[0]) / (2.0 * dt),
                (w[2] - 2.0 * w[1] + w[0]) / (dt * dt),
            );
            assert!(v <= max_speed + 1e-9 && v >= -1e-9, "speed {v}");
            // The speed is continuous, so a second difference across a phase boundary is a
            // weighted mean of the two phases' accelerations.
            assert!(a.abs() <= acceleration + 1e-6, "acceleration {a}");
        }
    }

    #[test]
    fn a_long_move_cruises_at_the_top_speed() {
        // 10 m from rest to rest at 1 m/s, 0.5 m/s^2: 2 s up (1 m), 8 s cruise, 2 s down.
        let m = TrapezoidMove::new(10.0, 0.0, 0.0, 1.0, 0.5);
        assert!((m.duration() - 12.0).abs() < 1e-12);
        assert!((m.position(2.0) - 1.0).abs() < 1e-12);
        assert!((m.position(6.0) - 5.0).abs() < 1e-12);
        assert!((m.position(11.0) - 9.75).abs() < 1e-12);
        assert_eq!(m.position(-1.0), 0.0);
        assert_eq!(m.position(20.0), 10.0);
        check(&m, 1.0, 0.5);
    }

    #[test]
    fn a_short_move_peaks_below_the_top_speed() {
        // 1 m from rest to rest at 1 m/s^2: a triangle peaking at 1 m/s after 1 s.
        let m = TrapezoidMove::new(1.0, 0.0, 0.0, 5.0, 1.0);
        assert!((m.duration() - 2.0).abs() < 1e-12);
        assert!((m.position(1.0) - 0.5).abs() < 1e-12);
        check(&m, 1.0, 1.0);
    }

    #[test]
    fn start_and_end_speeds_are_kept() {
        let m = TrapezoidMove::new(4.0, 0.4, 0.2, 1.2, 1.0);
        let dt = 1e-6;
        assert!((m.position(dt) / dt - 0.4).abs() < 1e-5);
        let end = m.duration();
        assert!(((m.position(end) - m.position(end - dt)) / dt - 0.2).abs() < 1e-5);
        check(&m, 1.2, 1.0);
        // Too short to slow from 1 to 0 at 1 m/s^2 (needs 0.5 m): an even change over 0.1 m.
        let m = TrapezoidMove::new(0.1, 1.0, 0.0, 1.0, 1.0);
        assert!((m.duration() - 0.2).abs() < 1e-12);
        assert_eq!(TrapezoidMove::new(0.0, 0.0, 0.0, 1.0, 1.0).duration(), 0.0);
    }
}
