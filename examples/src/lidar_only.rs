//! LiDAR-only odometry measured: spot-adapter's `ScanToScanOdometry` with its fallbacks and its
//! own time per scan (the registration, not the reading of the scan it wraps) kept where the
//! example can read them while the odometry runs on the read-ahead thread.

use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Instant;

use slam_core::Registrator;
use spot_adapter::AdapterError;
use spot_adapter::record::{DroppedPoints, SampleSource, ScanToScanConfig, ScanToScanOdometry};
use spot_adapter::robot::Sample;

/// What the scan-to-scan odometry did so far, shared with the thread it runs on.
#[derive(Debug, Default)]
pub struct ScanToScanStats {
    fallbacks: AtomicUsize,
    ms: Mutex<Vec<f64>>,
}

impl ScanToScanStats {
    /// Scans whose registration failed or diverged (the constant-velocity guess was kept).
    #[must_use]
    pub fn fallbacks(&self) -> usize {
        self.fallbacks.load(Ordering::Relaxed)
    }

    /// Milliseconds of odometry per scan, in order (the scan's reading left out).
    #[must_use]
    pub fn ms(&self) -> Vec<f64> {
        self.ms
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .clone()
    }
}

/// A source whose every `next` is timed: how long reading the last scan took.
struct TimedRead<I> {
    inner: I,
    last_ns: Arc<AtomicU64>,
}

impl<I: Iterator> Iterator for TimedRead<I> {
    type Item = I::Item;

    fn next(&mut self) -> Option<I::Item> {
        let started = Instant::now();
        let item = self.inner.next();
        let ns = u64::try_from(started.elapsed().as_nanos()).unwrap_or(u64::MAX);
        self.last_ns.store(ns, Ordering::Relaxed);
        item
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        self.inner.size_hint()
    }
}

impl<I: ExactSizeIterator> ExactSizeIterator for TimedRead<I> {}

impl<I: SampleSource> SampleSource for TimedRead<I> {
    fn dropped_points(&self) -> DroppedPoints {
        self.inner.dropped_points()
    }
}

/// `ScanToScanOdometry` over `I`, counting into a shared [`ScanToScanStats`].
pub struct MeasuredScanToScan<R: Registrator, I> {
    odometry: ScanToScanOdometry<R, TimedRead<I>>,
    read_ns: Arc<AtomicU64>,
    stats: Arc<ScanToScanStats>,
}

impl<R: Registrator, I> std::fmt::Debug for MeasuredScanToScan<R, I> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MeasuredScanToScan")
            .field("stats", &self.stats)
            .finish_non_exhaustive()
    }
}

impl<R: Registrator, I> MeasuredScanToScan<R, I> {
    /// `samples` with odometry from `registrator`, and the handle its figures are read from.
    pub fn new(
        registrator: R,
        samples: I,
        config: ScanToScanConfig,
    ) -> (Self, Arc<ScanToScanStats>) {
        let read_ns = Arc::new(AtomicU64::new(0));
        let stats = Arc::new(ScanToScanStats::default());
        let timed = TimedRead {
            inner: samples,
            last_ns: Arc::clone(&read_ns),
        };
        let measured = Self {
            odometry: ScanToScanOdometry::new(registrator, timed, config),
            read_ns,
            stats: Arc::clone(&stats),
        };
        (measured, stats)
    }
}

impl<R, I> Iterator for MeasuredScanToScan<R, I>
where
    R: Registrator,
    I: Iterator<Item = Result<Sample, AdapterError>>,
{
    type Item = Result<Sample, AdapterError>;

    fn next(&mut self) -> Option<Self::Item> {
        let started = Instant::now();
        let item = self.odometry.next()?;
        let all = started.elapsed().as_secs_f64() * 1e3;
        let read = self.read_ns.load(Ordering::Relaxed) as f64 * 1e-6;
        if item.is_ok() {
            self.stats
                .ms
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .push((all - read).max(0.0));
        }
        self.stats
            .fallbacks
            .store(self.odometry.fallbacks(), Ordering::Relaxed);
        Some(item)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        self.odometry.size_hint()
    }
}

impl<R, I> ExactSizeIterator for MeasuredScanToScan<R, I>
where
    R: Registrator,
    I: ExactSizeIterator<Item = Result<Sample, AdapterError>>,
{
}

impl<R, I> SampleSource for MeasuredScanToScan<R, I>
where
    R: Registrator + Send,
    R::Target: Send,
    I: SampleSource,
{
    fn dropped_points(&self) -> DroppedPoints {
        self.odometry.dropped_points()
    }
}
