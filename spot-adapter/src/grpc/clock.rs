//! Wall-clock seconds and their wire forms (`google.protobuf.Timestamp` and `Duration`).

use std::time::{SystemTime, UNIX_EPOCH};

/// This host's wall clock: seconds since the Unix epoch.
pub(crate) fn local_now() -> f64 {
    // A clock set before 1970 reads as the epoch: time sync then measures the true skew.
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64())
}

/// Seconds since the epoch as a `Timestamp` (nanoseconds rounded).
pub(crate) fn timestamp(seconds: f64) -> prost_types::Timestamp {
    let whole = seconds.floor();
    let mut nanos = ((seconds - whole) * 1e9).round() as i32;
    let mut secs = whole as i64;
    if nanos >= 1_000_000_000 {
        secs += 1;
        nanos -= 1_000_000_000;
    }
    prost_types::Timestamp {
        seconds: secs,
        nanos,
    }
}

/// A `Timestamp` as seconds since the epoch.
pub(crate) fn seconds(timestamp: &prost_types::Timestamp) -> f64 {
    timestamp.seconds as f64 + f64::from(timestamp.nanos) * 1e-9
}

/// Seconds as a `Duration` (negative durations have both parts negative).
pub(crate) fn duration(seconds: f64) -> prost_types::Duration {
    let secs = seconds.trunc();
    prost_types::Duration {
        seconds: secs as i64,
        nanos: ((seconds - secs) * 1e9).round() as i32,
    }
}

/// A `Duration` as seconds.
pub(crate) fn duration_seconds(duration: &prost_types::Duration) -> f64 {
    duration.seconds as f64 + f64::from(duration.nanos) * 1e-9
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wire_times_round_trip_to_the_nanosecond() {
        for s in [0.0, 1.5, 1_796_168_482.972_339_4, 12.999_999_999_9] {
            assert!((seconds(&timestamp(s)) - s).abs() < 2e-9, "{s}");
        }
        let t = timestamp(12.999_999_999_9);
        assert!((0..1_000_000_000).contains(&t.nanos));
        for s in [0.0, 0.25, -0.25, 12.5, -12.5] {
            assert!((duration_seconds(&duration(s)) - s).abs() < 1e-12, "{s}");
        }
        assert_eq!(
            duration(-1.5),
            prost_types::Duration {
                seconds: -1,
                nanos: -500_000_000
            }
        );
    }
}
