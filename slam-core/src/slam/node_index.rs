//! Spatial index over keyframe positions for loop-closure candidate search.

use rstar::RTree;
use rstar::primitives::GeomWithData;

use crate::geometry::Pose3;

type Entry = GeomWithData<[f64; 3], usize>;

/// An R-tree of keyframe positions; rebuilt in bulk after an optimisation moves the nodes.
#[derive(Default)]
pub(crate) struct NodeIndex {
    tree: RTree<Entry>,
}

impl NodeIndex {
    /// Index the positions of `poses` (keyframe index = position in the slice).
    pub(crate) fn rebuild<'a>(&mut self, poses: impl Iterator<Item = &'a Pose3>) {
        let entries: Vec<Entry> = poses
            .enumerate()
            .map(|(i, p)| {
                let t = p.translation.vector;
                GeomWithData::new([t.x, t.y, t.z], i)
            })
            .collect();
        self.tree = RTree::bulk_load(entries);
    }

    /// Add one keyframe.
    pub(crate) fn insert(&mut self, index: usize, pose: &Pose3) {
        let t = pose.translation.vector;
        self.tree.insert(GeomWithData::new([t.x, t.y, t.z], index));
    }

    /// The smallest keyframe index within `radius` of `pose` that `admit` admits.
    pub(crate) fn oldest_within(
        &self,
        pose: &Pose3,
        radius: f64,
        admit: impl Fn(usize) -> bool,
    ) -> Option<usize> {
        self.within(pose, radius).filter(|&i| admit(i)).min()
    }

    /// The largest keyframe index within `radius` of `pose` that `admit` admits.
    pub(crate) fn newest_within(
        &self,
        pose: &Pose3,
        radius: f64,
        admit: impl Fn(usize) -> bool,
    ) -> Option<usize> {
        // Newest first, so that an expensive `admit` runs until the first it admits.
        let mut near: Vec<usize> = self.within(pose, radius).collect();
        near.sort_unstable_by(|a, b| b.cmp(a));
        near.into_iter().find(|&i| admit(i))
    }

    /// The keyframe indices within `radius` of `pose`.
    fn within(&self, pose: &Pose3, radius: f64) -> impl Iterator<Item = usize> + '_ {
        let t = pose.translation.vector;
        self.tree
            .locate_within_distance([t.x, t.y, t.z], radius * radius)
            .map(|e| e.data)
    }
}
