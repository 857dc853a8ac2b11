//! `ScanBlocks`: the points of many placed scans copied into a few large buffers, for a render
//! that needs all of a map's keyframes at once.

use std::ops::Range;

use nalgebra::Point3;
use slam_core::Pose3;

/// Points a block holds (48 MB). Above glibc's largest dynamic mmap threshold (32 MB), so each
/// block is a mapping of its own, resident only as far as it is filled and handed back to the
/// system when the render drops it. A cloud a keyframe (about 140 KB each, read back from the
/// keyframe store) lands on the heap instead: a full render late on the large building held
/// about 200 MB of them at once, and the heap stays as large as it once was.
const BLOCK_POINTS: usize = 4 << 20;

/// Placed scans' points (their positions alone), in the order pushed.
#[derive(Default)]
pub(crate) struct ScanBlocks {
    blocks: Vec<Vec<Point3<f32>>>,
    /// Each scan's pose (`map_T_lidar`), block and range in it.
    scans: Vec<(Pose3, usize, Range<usize>)>,
}

impl ScanBlocks {
    /// Adds a scan: its `map_T_lidar` and points (LiDAR frame).
    pub(crate) fn push(&mut self, pose: Pose3, points: &[Point3<f32>]) {
        let fits = self
            .blocks
            .last()
            .is_some_and(|b| b.capacity() - b.len() >= points.len());
        if !fits {
            self.blocks
                .push(Vec::with_capacity(BLOCK_POINTS.max(points.len())));
        }
        let block = self.blocks.len() - 1;
        let b = &mut self.blocks[block];
        let start = b.len();
        b.extend_from_slice(points);
        self.scans.push((pose, block, start..b.len()));
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
    }
}
