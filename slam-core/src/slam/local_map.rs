//! The local map the odometry registers against: the last
//! [`GraphSlamConfig::local_map_keyframes`](super::GraphSlamConfig::local_map_keyframes)
//! keyframes the robot was at (the newest keyframes on a first walk; on a revisit, the old ones
//! it rides on), slid keyframe by keyframe, rebuilt when a loop closure moved them.

use super::keyframes::source_of;
use std::collections::VecDeque;

use super::engine::GraphSlam;
use crate::geometry::Pose3;
use crate::traits::optimizer::Optimizer;
use crate::traits::registrator::MapRegistrator;

/// The target the odometry registers against (keyed by keyframe index).
pub(super) struct LocalMap<T> {
    pub(super) target: T,
    /// Whether the backend updates it in place ([`MapRegistrator::empty_map`]); otherwise it is
    /// rebuilt whole after every change.
    pub(super) in_place: bool,
}

/// The keyframes the local map is made of: the last ones visited, least recently visited
/// first.
#[derive(Debug, Default)]
pub(super) struct LocalWindow {
    keys: VecDeque<usize>,
}

/// What visiting a keyframe did to the window.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Visit {
    /// It was in the window already (now the most recent).
    Known,
    /// It joined the window, and pushed out the least recently visited one, if any.
    Joined { left: Option<usize> },
}

impl LocalWindow {
    /// Marks keyframe `key` as the most recently visited of at most `capacity`.
    pub(super) fn visit(&mut self, key: usize, capacity: usize) -> Visit {
        if let Some(at) = self.keys.iter().position(|&k| k == key) {
            self.keys.remove(at);
            self.keys.push_back(key);
            return Visit::Known;
        }
        self.keys.push_back(key);
        let left = (self.keys.len() > capacity)
            .then(|| self.keys.pop_front())
            .flatten();
        Visit::Joined { left }
    }

    /// Whether keyframe `key` is in the window.
    pub(super) fn contains(&self, key: usize) -> bool {
        self.keys.contains(&key)
    }

    /// The keyframes, least recently visited first.
    pub(super) fn keys(&self) -> impl Iterator<Item = usize> + '_ {
        self.keys.iter().copied()
    }
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
        let keyed = u32::try_from(self.keyframes.len()).is_ok();
        if let (Some(mut target), true) = (self.odometry.empty_map(), keyed) {
            let mut unread = 0;
            for i in self.window.keys() {
                let pose = self.keyframe_pose(i);
                // A keyframe the store cannot give back is left out of the map, and counted.
                match self.source_of(i) {
                    Ok(source) => self
                        .odometry
                        .add_to_map(&mut target, i as u32, &source, &pose),
                    Err(_) => unread += 1,
                }
            }
            self.report.keyframe_store_failures += unread;
            self.local_map = Some(LocalMap {
                target,
                in_place: true,
            });
        } else {
            let loaded: Vec<_> = self
                .window
                .keys()
                .filter_map(|i| Some((self.source_of(i).ok()?, self.keyframe_pose(i))))
                .collect();
            let unread = self.window.keys().count() - loaded.len();
            let parts: Vec<(&R::Source, Pose3)> = loaded.iter().map(|(s, p)| (&**s, *p)).collect();
            let built = self.odometry.target_from_sources(&parts);
            drop(parts);
            drop(loaded);
            self.report.keyframe_store_failures += unread;
            match built {
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

    /// Makes keyframe `index` the most recently visited: added to an in-place local map (and
    /// the one it pushed out of the window dropped), or a map built whole dropped, to be
    /// rebuilt when next needed; nothing changes when it was in the window already.
    pub(super) fn visit_keyframe(&mut self, index: usize) {
        let Visit::Joined { left } = self.window.visit(index, self.config.local_map_keyframes)
        else {
            return;
        };
        let pose = self.keyframe_pose(index);
        match (&mut self.local_map, u32::try_from(index)) {
            (
                Some(LocalMap {
                    target,
                    in_place: true,
                }),
                Ok(key),
            ) => {
                match source_of(&self.keyframes[index].source, &self.clouds, &self.odometry) {
                    Ok(source) => self.odometry.add_to_map(target, key, &source, &pose),
                    Err(_) => self.report.keyframe_store_failures += 1,
                }
                if let Some(old) = left {
                    self.odometry.remove_from_map(target, old as u32);
                }
                // Indexed on the other core while the keyframe's loop search and the next
                // scan's thinning run on this one.
                self.odometry.ready_map_ahead(target);
            }
            _ => self.local_map = None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{LocalWindow, Visit};

    #[test]
    fn the_window_keeps_the_last_keyframes_visited() {
        let mut w = LocalWindow::default();
        for k in 0..3 {
            assert_eq!(w.visit(k, 3), Visit::Joined { left: None });
        }
        assert_eq!(w.visit(3, 3), Visit::Joined { left: Some(0) });
        // A revisit moves 1 to the back, so 2 is the next to leave.
        assert_eq!(w.visit(1, 3), Visit::Known);
        assert_eq!(w.visit(7, 3), Visit::Joined { left: Some(2) });
        assert_eq!(w.keys().collect::<Vec<_>>(), [3, 1, 7]);
        assert!(w.contains(7) && !w.contains(0));
    }
}
