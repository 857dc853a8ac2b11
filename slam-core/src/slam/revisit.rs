//! Revisits: no new keyframe where the map already is. A scan registered where a new keyframe
//! would be made rides instead on a keyframe already there, when the local map it was
//! registered against vouches for that keyframe
//! ([`GraphSlamConfig::revisit_radius`](super::GraphSlamConfig::revisit_radius)); the next
//! scans' motion is then measured from it. A loop closure starts a revisit by bringing the old
//! keyframes around it into the local map.

use super::engine::GraphSlam;
use super::keyframes::Link;
use crate::geometry::Pose3;
use crate::traits::optimizer::Optimizer;
use crate::traits::registrator::MapRegistrator;

/// How many edges of the graph a keyframe may be from the local map to be ridden on: the
/// relative poses along a few edges are as good as the registrations that made them, while a
/// keyframe far along the graph may sit where drift put it.
const VOUCHING_HOPS: usize = 10;

/// What the next scan's motion is measured from: the last keyframe, or on a revisit the last
/// scan that rode on an old one.
#[derive(Clone, Copy, Debug)]
pub(super) struct Reference {
    /// The keyframe.
    pub(super) keyframe: usize,
    /// The reference scan's LiDAR pose in the keyframe's LiDAR frame (the identity for the
    /// keyframe itself).
    pub(super) keyframe_t_lidar: Pose3,
    /// The odometry at the reference scan, `None` for a LiDAR-only scan.
    pub(super) odom_t_lidar: Option<Pose3>,
}

impl<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>> GraphSlam<R, C, O> {
    /// The reference of the next scan; `None` before the first keyframe.
    pub(super) fn reference(&self) -> Option<Reference> {
        if let Some(anchor) = self.anchor {
            return Some(anchor);
        }
        let last = self.keyframes.len().checked_sub(1)?;
        Some(Reference {
            keyframe: last,
            keyframe_t_lidar: Pose3::identity(),
            odom_t_lidar: self.keyframes[last].odom_t_lidar,
        })
    }

    /// `reference`'s LiDAR pose in the map frame.
    pub(super) fn reference_pose(&self, reference: &Reference) -> Pose3 {
        self.keyframe_pose(reference.keyframe) * reference.keyframe_t_lidar
    }

    /// The keyframe a scan registered at `pose` (matching `inlier_ratio` of its points) rides
    /// on instead of making a new one: the newest keyframe within
    /// [`GraphSlamConfig::revisit_radius`](super::GraphSlamConfig::revisit_radius) that is old
    /// (not one of the keyframes made since the last revisit, which the walk is laying down
    /// now) and that the local map vouches for: it is in the local map, or a few edges of the
    /// graph from a keyframe that is ([`VOUCHING_HOPS`]; loops an optimiser weighted out do not
    /// count), so the registration placed the scan consistently with it. `None` when off, when
    /// the match was too poor, or when no keyframe qualifies, or when the scan matched more than
    /// [`GraphSlamConfig::revisit_max_match_drop`](super::GraphSlamConfig::revisit_max_match_drop)
    /// less of itself than the keyframe did when it was made (the place changed).
    pub(super) fn revisited_keyframe(&self, pose: &Pose3, inlier_ratio: f64) -> Option<usize> {
        let radius = self.config.revisit_radius;
        if radius <= 0.0 || inlier_ratio < self.config.revisit_min_inlier_ratio {
            return None;
        }
        let n = self.keyframes.len();
        let laid_down = self
            .chain_start
            .max(n.saturating_sub(self.config.local_map_keyframes));
        let old = self
            .node_index
            .newest_within(pose, radius, |i| i < laid_down && self.vouched_for(i))?;
        // Matching much less than when the keyframe was made: the place changed.
        let drop = self.keyframes[old].matched - inlier_ratio;
        (drop <= self.config.revisit_max_match_drop).then_some(old)
    }

    /// Whether keyframe `i` is within [`VOUCHING_HOPS`] edges of the local map (a breadth-first
    /// search over odometry edges and the loops the optimiser kept).
    fn vouched_for(&self, i: usize) -> bool {
        let weights = self.optimizer.edge_weights();
        let kept = |link: &Link| {
            link.loop_edge
                .is_none_or(|k| weights.is_none_or(|w| w.get(k).is_none_or(|&w| w >= 0.5)))
        };
        let mut seen = vec![i];
        let mut frontier = vec![i];
        for _ in 0..=VOUCHING_HOPS {
            if frontier.iter().any(|&k| self.window.contains(k)) {
                return true;
            }
            let mut next = Vec::new();
            for k in frontier {
                for link in self.keyframes[k].links.iter().filter(|l| kept(l)) {
                    if !seen.contains(&link.keyframe) {
                        seen.push(link.keyframe);
                        next.push(link.keyframe);
                    }
                }
            }
            frontier = next;
        }
        false
    }

    /// The scan registered at `keyframe_t_lidar` from keyframe `keyframe` rides on it: the
    /// reference of the next scans, and the most recent keyframe of the local map.
    pub(super) fn revisit(
        &mut self,
        keyframe: usize,
        keyframe_t_lidar: Pose3,
        odom_t_lidar: Option<Pose3>,
    ) {
        self.anchor = Some(Reference {
            keyframe,
            keyframe_t_lidar,
            odom_t_lidar,
        });
        self.chain_start = self.keyframes.len();
        self.report.revisits += 1;
        self.visit_keyframe(keyframe);
    }

    /// After a loop from keyframe `old` to the newest one closed: the old keyframes around
    /// `old` (a quarter of the local map on each side) join the local map, so that the next
    /// scans may ride on them. The newest keyframe stays the most recent. The caller rebuilds
    /// the local map.
    pub(super) fn start_revisit(&mut self, old: usize, new: usize) {
        if self.config.revisit_radius <= 0.0 || new + 1 != self.keyframes.len() {
            return;
        }
        let capacity = self.config.local_map_keyframes;
        let side = capacity / 4;
        let last_old = new.saturating_sub(capacity);
        for i in old.saturating_sub(side)..=(old + side).min(last_old) {
            self.window.visit(i, capacity);
        }
        self.window.visit(new, capacity);
    }
}
