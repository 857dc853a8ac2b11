//! The local map the odometry registers against: the last
//! [`GraphSlamConfig::local_map_keyframes`](super::GraphSlamConfig::local_map_keyframes)
//! keyframes at their poses, slid keyframe by keyframe, rebuilt when a loop closure moved them.

use super::engine::GraphSlam;
use crate::geometry::Pose3;
use crate::traits::optimizer::Optimizer;
use crate::traits::registrator::MapRegistrator;

/// The target the odometry registers against (keyed by keyframe index).
pub(super) struct LocalMap<T> {
    pub(super) target: T,
    /// Whether the backend updates it in place ([`MapRegistrator::empty_map`]); otherwise it is
    /// rebuilt whole after every keyframe.
    pub(super) in_place: bool,
}

impl<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>> GraphSlam<R, C, O> {
    /// Builds the local map if there is none (at the start, and after a loop closure moved the
    /// keyframes): in place when the backend supports it, else whole. A build the backend
    /// refuses is counted ([`SlamReport::local_map_failures`](super::SlamReport)); the scan
    /// then falls back to its prediction.
    pub(super) fn ensure_local_map(&mut self) -> bool {
        if self.local_map.is_some() {
            return true;
        }
        let n = self.keyframes.len();
        let first = n.saturating_sub(self.config.local_map_keyframes);
        let keyed = u32::try_from(n).is_ok();
        if let (Some(mut target), true) = (self.odometry.empty_map(), keyed) {
            for i in first..n {
                let pose = self.keyframe_pose(i);
                self.odometry
                    .add_to_map(&mut target, i as u32, &self.keyframes[i].source, &pose);
            }
            self.local_map = Some(LocalMap {
                target,
                in_place: true,
            });
        } else {
            let parts: Vec<(&R::Source, Pose3)> = (first..n)
                .map(|i| (&self.keyframes[i].source, self.keyframe_pose(i)))
                .collect();
            match self.odometry.target_from_sources(&parts) {
                Ok(target) => {
                    self.local_map = Some(LocalMap {
                        target,
                        in_place: false,
                    });
                }
                Err(_) => self.report.local_map_failures += 1,
            }
        }
        self.local_map.is_some()
    }

    /// Adds keyframe `index` (the newest) to an in-place local map and drops the one that left
    /// the window; a map built whole is dropped, to be rebuilt when next needed.
    pub(super) fn slide_local_map(&mut self, index: usize) {
        let window = self.config.local_map_keyframes;
        let pose = self.keyframe_pose(index);
        match (&mut self.local_map, u32::try_from(index)) {
            (
                Some(LocalMap {
                    target,
                    in_place: true,
                }),
                Ok(key),
            ) => {
                self.odometry
                    .add_to_map(target, key, &self.keyframes[index].source, &pose);
                if let Some(old) = index.checked_sub(window) {
                    self.odometry.remove_from_map(target, old as u32);
                }
            }
            _ => self.local_map = None,
        }
    }
}
