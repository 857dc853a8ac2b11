//! `KeyframeBatches`: the keyframes of a full render read a batch at a time, pass after pass,
//! so that the render holds a bounded number of their points whatever the size of the map.

use std::cell::{Cell, RefCell};

use nalgebra::Point3;
use slam_core::{KeyframeCloudError, Pose3};

use crate::nav::growing_map::Keyframes;
use crate::nav::scan_blocks::ScanBlocks;

/// Placed scans: each one's `map_T_lidar` and points (LiDAR frame).
pub(crate) type PlacedScans<'a> = [(Pose3, &'a [Point3<f32>])];

/// Keyframes `picked` of `keyframes`, handed over in batches of one [`ScanBlocks`] block (48 MB
/// of points) on each [`KeyframeBatches::pass`]: the batches of a pass together are every
/// picked keyframe's pose and points, in order. A pass reads them back (the engine's keyframe
/// store); when they all fit in one batch, the first pass's batch is kept for the others.
///
/// A full render late on the large building read about 1,300 keyframes (16 million points,
/// 197 MB) into memory at once; in batches it holds one block, and reads each keyframe once a
/// pass (six: four for the floor, two for the band and the cloud).
pub(crate) struct KeyframeBatches<'a, K: Keyframes + ?Sized> {
    keyframes: &'a K,
    picked: &'a [usize],
    blocks: RefCell<ScanBlocks>,
    /// Whether `blocks` holds every picked keyframe, read by an earlier pass.
    whole: Cell<bool>,
    /// The first read that failed: it ends its pass and every later one.
    error: RefCell<Option<KeyframeCloudError>>,
}

impl<'a, K: Keyframes + ?Sized> KeyframeBatches<'a, K> {
    /// Batches of keyframes `picked` of `keyframes` (indices, in the order to hand them over)
    /// of up to `batch_points` points ([`crate::nav::scan_blocks::BLOCK_POINTS`]; a keyframe
    /// with more is a batch of its own).
    pub(crate) fn new(keyframes: &'a K, picked: &'a [usize], batch_points: usize) -> Self {
        Self {
            keyframes,
            picked,
            blocks: RefCell::new(ScanBlocks::with_block_points(batch_points)),
            whole: Cell::new(false),
            error: RefCell::new(None),
        }
    }

    /// Calls `visit` with each batch in turn: the picked keyframes' `map_T_lidar` (the
    /// identity for one the keyframes do not have) and points (LiDAR frame). Nothing more
    /// once a read failed ([`Self::error`]).
    pub(crate) fn pass(&self, visit: &mut dyn FnMut(&PlacedScans<'_>)) {
        if self.error.borrow().is_some() {
            return;
        }
        let mut blocks = self.blocks.borrow_mut();
        if self.whole.get() {
            visit(&blocks.scans());
            return;
        }
        blocks.clear();
        let mut flushed = false;
        for &k in self.picked {
            let pose = self.keyframes.pose(k).unwrap_or_else(Pose3::identity);
            let scan = match self.keyframes.scan(k) {
                Ok(scan) => scan,
                Err(e) => {
                    *self.error.borrow_mut() = Some(e);
                    return;
                }
            };
            if !blocks.is_empty() && blocks.needs_a_block_for(scan.len()) {
                visit(&blocks.scans());
                blocks.clear();
                flushed = true;
            }
            blocks.push(pose, scan.points());
        }
        visit(&blocks.scans());
        self.whole.set(!flushed);
    }

    /// The first read that failed, taken out.
    pub(crate) fn error(&self) -> Option<KeyframeCloudError> {
        self.error.borrow_mut().take()
    }
}

#[cfg(test)]
mod tests {
    use std::borrow::Cow;

    use slam_core::PointCloud;

    use super::*;

    /// Keyframes of `sizes` points, counting their reads.
    struct Counted {
        scans: Vec<(Pose3, PointCloud)>,
        reads: Cell<usize>,
    }

    impl Counted {
        fn new(sizes: &[usize]) -> Self {
            let scans = sizes
                .iter()
                .enumerate()
                .map(|(k, &n)| {
                    let points = (0..n).map(|i| Point3::new(k as f32, i as f32, 0.0));
                    let pose = Pose3::translation(k as f64, 0.0, 0.0);
                    (pose, PointCloud::from_points(points.collect()))
                })
                .collect();
            Self {
                scans,
                reads: Cell::new(0),
            }
        }
    }

    impl Keyframes for Counted {
        fn count(&self) -> usize {
            self.scans.len()
        }
        fn pose(&self, k: usize) -> Option<Pose3> {
            self.scans.get(k).map(|(p, _)| *p)
        }
        fn scan(&self, k: usize) -> Result<Cow<'_, PointCloud>, KeyframeCloudError> {
            self.reads.set(self.reads.get() + 1);
            Ok(Cow::Owned(self.scans[k].1.clone()))
        }
    }

    /// Keyframes' poses and points, owned.
    type Owned = Vec<(Pose3, Vec<Point3<f32>>)>;

    /// The picked keyframes (poses and points) of one pass's batches, and each batch's points.
    fn one_pass(batches: &KeyframeBatches<'_, Counted>) -> (Owned, Vec<usize>) {
        let (mut scans, mut sizes) = (Vec::new(), Vec::new());
        batches.pass(&mut |batch| {
            sizes.push(batch.iter().map(|(_, p)| p.len()).sum());
            scans.extend(batch.iter().map(|(pose, p)| (*pose, p.to_vec())));
        });
        (scans, sizes)
    }

    /// Every pass hands over the picked keyframes in order, in batches of at most the batch's
    /// points (a larger keyframe alone), reading them again each pass; keyframes that fit in
    /// one batch are read once for every pass.
    #[test]
    fn passes_hand_over_the_picked_keyframes_in_bounded_batches() {
        let keyframes = Counted::new(&[4, 3, 0, 5, 9, 2, 2, 1]);
        let picked = [7, 0, 1, 2, 3, 4, 6];
        let want: Owned = picked
            .iter()
            .map(|&k| (keyframes.scans[k].0, keyframes.scans[k].1.points().to_vec()))
            .collect();
        let batches = KeyframeBatches::new(&keyframes, &picked, 8);
        for pass in 1..=3 {
            let (scans, sizes) = one_pass(&batches);
            assert_eq!(scans, want);
            // 1 + 4 + 3 + 0, then 5, then 9 alone, then 2.
            assert_eq!(sizes, [8, 5, 9, 2]);
            assert_eq!(keyframes.reads.get(), pass * picked.len());
        }
        assert!(batches.error().is_none());
        keyframes.reads.set(0);
        let whole = KeyframeBatches::new(&keyframes, &picked, 100);
        for _ in 0..3 {
            let (scans, sizes) = one_pass(&whole);
            assert_eq!((scans, sizes), (want.clone(), vec![24]));
        }
        assert_eq!(keyframes.reads.get(), picked.len());
    }
}
