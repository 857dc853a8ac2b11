//! `ScanBlocks`: the points of many placed scans copied into a few large buffers, for a render
//! that reads a map's keyframes a batch at a time.

use std::ops::Range;

use nalgebra::Point3;
use slam_core::Pose3;

/// Points a block holds (48 MB). Above glibc's largest dynamic mmap threshold (32 MB), so each
/// block is a mapping of its own, resident only as far as it is filled and handed back to the
/// system when the render drops it. A cloud a keyframe (about 140 KB each, read back from the
/// keyframe store) lands on the heap instead: a full render late on the large building held
/// about 200 MB of them at once, and the heap stays as large as it once was.
pub(crate) const BLOCK_POINTS: usize = 4 << 20;

/// Placed scans' points (their positions alone), in the order pushed.
pub(crate) struct ScanBlocks {
    /// Points a block holds, [`BLOCK_POINTS`] (a scan larger gets a block its size).
    block_points: usize,
    blocks: Vec<Vec<Point3<f32>>>,
    /// Each scan's pose (`map_T_lidar`), block and range in it.
    scans: Vec<(Pose3, usize, Range<usize>)>,
}

impl Default for ScanBlocks {
    fn default() -> Self {
        Self::with_block_points(BLOCK_POINTS)
    }
}

impl ScanBlocks {
    /// Empty, with blocks of `block_points` points (tests take small ones).
    pub(crate) fn with_block_points(block_points: usize) -> Self {
        Self {
            block_points,
            blocks: Vec::new(),
            scans: Vec::new(),
        }
    }

    /// Adds a scan: its `map_T_lidar` and points (LiDAR frame).
    pub(crate) fn push(&mut self, pose: Pose3, points: &[Point3<f32>]) {
        if self.needs_a_block_for(points.len()) {
            self.blocks
                .push(Vec::with_capacity(self.block_points.max(points.len())));
        }
        let block = self.blocks.len() - 1;
        let b = &mut self.blocks[block];
        let start = b.len();
        b.extend_from_slice(points);
        self.scans.push((pose, block, start..b.len()));
    }

    /// Whether it holds no scan.
    pub(crate) fn is_empty(&self) -> bool {
        self.scans.is_empty()
    }

    /// Whether a scan of `points` points would start a block: one more block of memory.
    pub(crate) fn needs_a_block_for(&self, points: usize) -> bool {
        self.blocks
            .last()
            .is_none_or(|b| b.capacity() - b.len() < points)
    }

    /// Empties it, keeping its first block (its memory) for the next scans.
    pub(crate) fn clear(&mut self) {
        self.blocks.truncate(1);
        if let Some(b) = self.blocks.first_mut() {
            b.clear();
        }
        self.scans.clear();
    }

    /// The scans, each its pose and points, in the order pushed.
    pub(crate) fn scans(&self) -> Vec<(Pose3, &[Point3<f32>])> {
        self.scans
            .iter()
            .map(|(pose, block, range)| (*pose, &self.blocks[*block][range.clone()]))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Scans come back as pushed, whether they share a block or not, and one larger than a
    /// block gets a block of its own size.
    #[test]
    fn scans_come_back_as_pushed() {
        let scan = |n: usize, at: f32| -> Vec<Point3<f32>> {
            (0..n).map(|i| Point3::new(at, i as f32, -at)).collect()
        };
        let pushed = [
            (Pose3::translation(1.0, 0.0, 0.0), scan(3, 1.0)),
            (Pose3::translation(2.0, 0.0, 0.0), Vec::new()),
            (
                Pose3::translation(3.0, 0.0, 0.0),
                scan(BLOCK_POINTS - 3, 3.0),
            ),
            (
                Pose3::translation(4.0, 0.0, 0.0),
                scan(BLOCK_POINTS + 5, 4.0),
            ),
            (Pose3::translation(5.0, 0.0, 0.0), scan(2, 5.0)),
        ];
        let mut blocks = ScanBlocks::default();
        for (pose, points) in &pushed {
            blocks.push(*pose, points);
        }
        let got = blocks.scans();
        assert_eq!(got.len(), pushed.len());
        for ((pose, points), (want_pose, want)) in got.iter().zip(&pushed) {
            assert_eq!(pose, want_pose);
            assert_eq!(*points, want.as_slice());
        }
        // 3 + 0 + (BLOCK - 3) fill the first block; the next two take a block each.
        assert_eq!(blocks.blocks.len(), 3);
        // The last block, the first 2 points of its BLOCK, has room for the rest.
        assert!(
            !blocks.needs_a_block_for(BLOCK_POINTS - 2)
                && blocks.needs_a_block_for(BLOCK_POINTS - 1)
        );
        assert!(!blocks.is_empty());
        // Cleared, it keeps its first block, empty.
        blocks.clear();
        assert!(blocks.is_empty() && blocks.scans().is_empty());
        assert_eq!(blocks.blocks.len(), 1);
        assert!(!blocks.needs_a_block_for(BLOCK_POINTS));
        assert!(blocks.needs_a_block_for(BLOCK_POINTS + 1));
        blocks.push(pushed[0].0, &pushed[0].1);
        assert_eq!(blocks.scans(), vec![(pushed[0].0, pushed[0].1.as_slice())]);
    }
}
