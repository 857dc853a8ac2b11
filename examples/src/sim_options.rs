//! The simulator's choices on the command line of `simulate` and `slam`: which LiDAR
//! (`--sensor`) and how it moves (`--motion`).

use clap::ValueEnum;
use spot_adapter::sim::{LidarConfig, MotionProfile};

/// The simulated LiDAR, as `--sensor` chooses it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum Sensor {
    /// Velodyne VLP-16: 16 rings over ±15°, 1800 columns, 5 Hz (28,800 rays a sweep).
    #[default]
    #[value(name = "vlp16")]
    Vlp16,
    /// Ouster OS1-128: 128 rings over ±22.5°, 1024 columns, 10 Hz (131,072 rays a sweep).
    #[value(name = "os1-128")]
    Os1_128,
}

impl Sensor {
    /// The sensor's settings.
    #[must_use]
    pub fn lidar(self) -> LidarConfig {
        match self {
            Self::Vlp16 => LidarConfig::vlp16(),
            Self::Os1_128 => LidarConfig::os1_128(),
        }
    }
}

/// How the simulated LiDAR moves along the lap, as `--motion` chooses it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum Motion {
    /// Spot walks at 0.6 m/s and turns through corners while walking on; a sample per sweep.
    #[default]
    Walk,
    /// Spot stops at each corner and turns in place at its full 1 rad/s; a sample per sweep.
    FastTurns,
    /// A person carries the LiDAR at 1.2 m/s, 1.3 m up, shaking, turning corners at up to 1.6
    /// rad/s; a sample (one sweep) every 0.5 s.
    Handheld,
}

impl Motion {
    /// The motion's profile, with its defaults.
    #[must_use]
    pub fn profile(self) -> MotionProfile {
        match self {
            Self::Walk => MotionProfile::Walk,
            Self::FastTurns => MotionProfile::fast_turns(),
            Self::Handheld => MotionProfile::handheld(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::value_name;

    #[test]
    fn names_as_on_the_command_line() {
        assert_eq!(value_name(&Sensor::Os1_128), "os1-128");
        assert_eq!(value_name(&Motion::FastTurns), "fast-turns");
        assert_eq!(Sensor::default().lidar(), LidarConfig::default());
        assert_eq!(Motion::default().profile(), MotionProfile::default());
        assert_eq!(Sensor::Os1_128.lidar().rings, 128);
    }
}
