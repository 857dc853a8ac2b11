//! Any sample source read on a thread of its own, a few samples ahead of the engine, so reading
//! (decompressing chunks, decoding clouds)
//! runs beside the engine instead of before each of its scans. The queue is bounded, so memory
//! stays that of `depth` samples whatever the recording's length.

use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread::JoinHandle;

use crate::record::RecordError;
use crate::record::no_return::DroppedPoints;
use crate::record::source::SampleSource;
use crate::robot::Sample;

/// One sample read, with the points the source had removed once it was read.
type Read = (Result<Sample, RecordError>, DroppedPoints);

/// `source` read ahead on a thread of its own (see the module documentation).
///
/// The samples come out in the source's order, and nothing after the first error. Dropping it stops the thread after the sample it is reading. A
/// panic on the reading thread is resumed on the consumer's, as if it had read the source
/// itself.
///
/// ```
/// use spot_adapter::record::{ReadAhead, SampleSource};
/// # fn demo(source: Box<dyn SampleSource>) {
/// let mut samples = ReadAhead::new(source, 4);
/// for sample in &mut samples {
///     let _sample = sample.expect("a readable recording");
/// }
/// println!("{} no-return points removed", samples.dropped_points().no_return);
/// # }
/// ```
#[derive(Debug)]
pub struct ReadAhead {
    receiver: Option<Receiver<Read>>,
    thread: Option<JoinHandle<()>>,
    /// Samples not yet delivered, as the source counted them.
    left: usize,
    dropped: DroppedPoints,
}

fn read_into<S: SampleSource>(mut source: S, sender: &SyncSender<Read>) {
    while let Some(sample) = source.next() {
        let failed = sample.is_err();
        // The consumer has gone: stop reading.
        if sender.send((sample, source.dropped_points())).is_err() || failed {
            return;
        }
    }
}

impl ReadAhead {
    /// `source` read by a new thread, at most `depth` samples (at least 1) ahead. When no
    /// thread can be started, the only sample is that error ([`RecordError::Io`] on the path
    /// `<read-ahead thread>`).
    pub fn new<S: SampleSource + 'static>(source: S, depth: usize) -> Self {
        let left = source.len();
        let dropped = source.dropped_points();
        let (sender, receiver) = sync_channel(depth.max(1));
        let thread = std::thread::Builder::new()
            .name("spot-nav read-ahead".into())
            .spawn(move || read_into(source, &sender));
        match thread {
            Ok(thread) => Self {
                receiver: Some(receiver),
                thread: Some(thread),
                left,
                dropped,
            },
            // No thread to read on: the error comes out as the only sample.
            Err(e) => {
                let (sender, receiver) = sync_channel(1);
                let _ = sender.send((
                    Err(RecordError::io(
                        std::path::Path::new("<read-ahead thread>"),
                        e,
                    )),
                    dropped,
                ));
                Self {
                    receiver: Some(receiver),
                    thread: None,
                    left,
                    dropped,
                }
            }
        }
    }

    /// The reading thread's end: its panic, if it had one, resumed here.
    fn join(&mut self) {
        if let Some(thread) = self.thread.take()
            && let Err(panic) = thread.join()
        {
            std::panic::resume_unwind(panic);
        }
    }
}

impl Iterator for ReadAhead {
    type Item = Result<Sample, RecordError>;

    fn next(&mut self) -> Option<Self::Item> {
        let received = self.receiver.as_ref()?.recv();
        let Ok((sample, dropped)) = received else {
            // The source is done (or its thread panicked).
            self.receiver = None;
            self.left = 0;
            self.join();
            return None;
        };
        self.dropped = dropped;
        self.left = if sample.is_err() {
            0
        } else {
            self.left.saturating_sub(1)
        };
        Some(sample)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        (self.left, Some(self.left))
    }
}

impl ExactSizeIterator for ReadAhead {}

impl SampleSource for ReadAhead {
    fn dropped_points(&self) -> DroppedPoints {
        self.dropped
    }
}

impl Drop for ReadAhead {
    fn drop(&mut self) {
        // Closing the queue first makes a thread blocked on a full queue stop.
        self.receiver = None;
        if let Some(thread) = self.thread.take() {
            // A panic is not resumed while dropping (that would abort).
            let _ = thread.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::no_return::ReturnFilter;
    use crate::record::source::ReturnFiltered;
    use slam_core::{PointCloud, Pose3};

    fn sample(i: usize, points: &[[f32; 3]]) -> Sample {
        Sample {
            stamp: i as f64 * 0.1,
            odom_t_body: Pose3::identity(),
            body_t_lidar: Pose3::identity(),
            cloud: PointCloud::from_points(
                points
                    .iter()
                    .map(|p| nalgebra::Point3::new(p[0], p[1], p[2]))
                    .collect(),
            ),
            ground_truth: None,
            gyro_orientation: None,
        }
    }

    /// 20 samples with one no-return each, then an error at sample 12 when `fail`.
    fn source(fail: bool) -> ReturnFiltered<std::vec::IntoIter<Result<Sample, RecordError>>> {
        let samples: Vec<_> = (0..20)
            .map(|i| {
                if fail && i == 12 {
                    Err(RecordError::NotFound { path: "x".into() })
                } else {
                    Ok(sample(
                        i,
                        &[[1.0, 2.0, 3.0], [0.0, 0.0, 0.0], [4.0, 5.0, 6.0]],
                    ))
                }
            })
            .collect();
        ReturnFiltered::new(samples.into_iter(), ReturnFilter::default())
    }

    #[test]
    fn samples_come_out_as_the_source_gives_them() {
        let direct: Vec<_> = source(false).map(|s| s.map(|s| s.stamp).ok()).collect();
        let mut ahead = ReadAhead::new(source(false), 3);
        assert_eq!(ahead.len(), 20);
        let first = ahead.next().and_then(Result::ok).map(|s| s.stamp);
        assert_eq!(ahead.len(), 19);
        assert_eq!(ahead.dropped_points().no_return, 1);
        let rest: Vec<_> = ahead.by_ref().map(|s| s.map(|s| s.stamp).ok()).collect();
        assert_eq!([vec![first], rest].concat(), direct);
        assert_eq!(ahead.dropped_points().no_return, 20);
        assert_eq!(ahead.len(), 0);
        assert!(ahead.next().is_none());
    }

    #[test]
    fn nothing_follows_an_error() {
        let got: Vec<bool> = ReadAhead::new(source(true), 2).map(|s| s.is_ok()).collect();
        assert_eq!(got.len(), 13);
        assert!(got[..12].iter().all(|&ok| ok));
        assert!(!got[12]);
    }

    #[test]
    fn dropping_it_early_stops_the_thread() {
        let mut ahead = ReadAhead::new(source(false), 1);
        assert!(ahead.next().is_some());
        // The thread is blocked on the full queue; dropping must not hang.
        drop(ahead);
    }
}
