//! Stuck detection: a robot that keeps being commanded to walk but does not get anywhere (an
//! obstacle the map does not show, a leg caught) backs off and tries again, and is reported
//! blocked after a few attempts instead of pushing for ever.

use std::collections::VecDeque;

use nalgebra::Vector2;

use crate::nav::NavError;
use crate::robot::VelocityCommand;

/// Settings of the stuck monitor. Lengths in metres, speeds in m/s.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct StuckConfig {
    /// Walking cycles (commands that translate) over which progress is judged, 25 (5 s at 5 Hz).
    pub window: usize,
    /// Less net motion of the estimate than this over the window is no progress, 0.15 m.
    pub min_progress: f64,
    /// Cycles of backing off once stuck, 5 (1 s).
    pub backoff_cycles: usize,
    /// Backing-off speed, 0.2 m/s.
    pub backoff_speed: f64,
    /// Attempts to get free before the robot is reported blocked, 3.
    pub max_attempts: usize,
}

impl Default for StuckConfig {
    fn default() -> Self {
        Self {
            window: 25,
            min_progress: 0.15,
            backoff_cycles: 5,
            backoff_speed: 0.2,
            max_attempts: 3,
        }
    }
}

impl StuckConfig {
    /// Positive lengths and speeds, counts of at least 1.
    ///
    /// # Errors
    /// [`NavError::InvalidConfig`] naming the first bad setting.
    pub fn validate(&self) -> Result<(), NavError> {
        for (setting, value) in [
            ("stuck.min_progress", self.min_progress),
            ("stuck.backoff_speed", self.backoff_speed),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(NavError::invalid(setting, value, "finite and positive"));
            }
        }
        for (setting, value) in [
            ("stuck.window", self.window),
            ("stuck.backoff_cycles", self.backoff_cycles),
            ("stuck.max_attempts", self.max_attempts),
        ] {
            if value == 0 {
                return Err(NavError::invalid(setting, 0.0, "at least 1"));
            }
        }
        Ok(())
    }
}

/// What the monitor says this cycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum StuckState {
    /// Go on as planned.
    Free,
    /// Back off this cycle.
    BackingOff,
    /// Every attempt failed.
    Blocked,
}

/// Positions at the walking cycles of the window, the back-off left, the attempts made.
#[derive(Clone, Debug)]
pub(crate) struct StuckMonitor {
    config: StuckConfig,
    positions: VecDeque<Vector2<f64>>,
    walking: bool,
    backoff_left: usize,
    attempts: usize,
    /// Whether the last check started a back-off.
    started: bool,
}

impl StuckMonitor {
    pub(crate) fn new(config: StuckConfig) -> Self {
        Self {
            positions: VecDeque::with_capacity(config.window + 1),
            config,
            walking: false,
            backoff_left: 0,
            attempts: 0,
            started: false,
        }
    }

    /// Whether the last [`StuckMonitor::check`] began a back-off (the moment to mark what
    /// blocks the robot).
    pub(crate) fn just_started(&self) -> bool {
        self.started
    }

    /// Forget the history (a new goal, a relocalisation, an arrival).
    pub(crate) fn reset(&mut self) {
        self.positions.clear();
        self.walking = false;
        self.backoff_left = 0;
        self.attempts = 0;
        self.started = false;
    }

    /// The state for a cycle at `position` (the estimate), after the command of the cycle
    /// before was recorded by [`StuckMonitor::commanded`].
    pub(crate) fn check(&mut self, position: Vector2<f64>) -> StuckState {
        self.started = false;
        if self.backoff_left > 0 {
            self.backoff_left -= 1;
            return StuckState::BackingOff;
        }
        if !self.walking {
            // Turning in place or standing: no progress is expected.
            return StuckState::Free;
        }
        self.positions.push_back(position);
        if self.positions.len() > self.config.window {
            self.positions.pop_front();
        }
        let stuck = self.positions.len() == self.config.window
            && self
                .positions
                .front()
                .is_some_and(|first| (position - first).norm() < self.config.min_progress);
        if !stuck {
            return StuckState::Free;
        }
        self.positions.clear();
        self.attempts += 1;
        if self.attempts > self.config.max_attempts {
            return StuckState::Blocked;
        }
        self.backoff_left = self.config.backoff_cycles - 1;
        self.started = true;
        StuckState::BackingOff
    }

    /// Record the command sent this cycle: only cycles that translate count toward the window.
    pub(crate) fn commanded(&mut self, command: &VelocityCommand) {
        self.walking = command.forward.hypot(command.lateral) > 0.05;
        if !self.walking {
            self.positions.clear();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_progress_while_walking_backs_off_then_blocks() {
        let config = StuckConfig::default();
        let mut m = StuckMonitor::new(config.clone());
        let walk = VelocityCommand::new(0.5, 0.0);
        let here = Vector2::new(1.0, 2.0);
        let mut states = Vec::new();
        for _ in 0..200 {
            let s = m.check(here);
            states.push(s);
            if s == StuckState::Blocked {
                break;
            }
            if s == StuckState::Free {
                m.commanded(&walk);
            }
        }
        let backoffs = states
            .iter()
            .filter(|&&s| s == StuckState::BackingOff)
            .count();
        assert_eq!(backoffs, config.max_attempts * config.backoff_cycles);
        assert_eq!(states.last(), Some(&StuckState::Blocked));
        // The first back-off comes once a whole window of walking went nowhere.
        let first = states
            .iter()
            .position(|&s| s == StuckState::BackingOff)
            .unwrap();
        assert_eq!(first, config.window);
    }

    #[test]
    fn progress_or_turning_in_place_is_not_stuck() {
        let mut m = StuckMonitor::new(StuckConfig::default());
        for k in 0..100 {
            // 0.1 m per cycle: progress.
            assert_eq!(
                m.check(Vector2::new(0.1 * f64::from(k), 0.0)),
                StuckState::Free
            );
            m.commanded(&VelocityCommand::new(0.5, 0.0));
        }
        let mut m = StuckMonitor::new(StuckConfig::default());
        for _ in 0..100 {
            assert_eq!(m.check(Vector2::zeros()), StuckState::Free);
            m.commanded(&VelocityCommand::new(0.0, 1.0));
        }
    }
}
