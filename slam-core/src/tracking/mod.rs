//! Tracking a LiDAR through its scans, the one loop that the Graph-SLAM engine's odometry and
//! the navigator's localiser share: predict where the sensor is, register the scan against a
//! target from that prediction with a correspondence reach that follows how wrong the
//! predictions have recently been, check the result, and otherwise fall back to the prediction
//! with the reason named and counted.
//!
//! The reach is KISS-ICP's adaptive threshold (Vizzo et al., "KISS-ICP: In Defense of
//! Point-to-Point ICP", RA-L 2023, eq. 5-7): the correction each registration made to its
//! prediction is turned into the largest displacement it causes for a point of the scan, and
//! three times the RMS of those over recent scans bounds how far apart a scan point and its
//! partner may be. Here it drives a coarse stage (wide reach, wide kernel) before the backend's
//! own fine alignment, so that a sudden turn that puts far points metres from their partners is
//! pulled in first and then refined at the backend's accuracy; a scan that still does not
//! register is tried once more from the other guesses the caller gave (the last pose held, the
//! odometry's and the constant-velocity extrapolation's) and with the widest reach.

mod extent;
mod health;
mod reach;
mod tracker;
mod turn_persistence;

pub use extent::scan_extent;
pub use health::{FallbackCounts, FallbackReason, TrackingHealth};
pub use reach::{AdaptiveReach, ReachConfig, point_displacement};
pub(crate) use tracker::replaces;
pub use tracker::{TrackOutcome, Tracker, TrackerConfig};
pub use turn_persistence::{TURN_SHARES, TurnPersistence};
