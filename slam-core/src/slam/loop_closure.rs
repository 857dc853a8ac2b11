//! Loop closure: candidates queued as keyframes arrive (an old keyframe near the new one, or a
//! look-alike from place recognition), each checked in a bounded step (coarse then refined
//! registration against the old keyframe's neighbourhood, the drift the walk allows), closed
//! with a new edge and one optimisation.

use super::cloud_store::KeyframeCloudError;
use std::collections::VecDeque;
use std::time::Instant;

use super::engine::GraphSlam;
use super::information::edge_information;
use super::keyframes::Link;
use super::report::{LoopOutcome, LoopRejection, SlamReport};
use crate::geometry::{Pose3, pose3_is_finite};
use crate::traits::optimizer::Optimizer;
use crate::traits::place_recognizer::PlaceMatch;
use crate::traits::registrator::MapRegistrator;

/// A loop to check: an old keyframe near a new one.
#[derive(Clone, Copy, Debug)]
pub(super) struct LoopCandidate {
    /// Index of the old keyframe.
    old: usize,
    /// Index of the new keyframe.
    new: usize,
    /// Where place recognition puts the new keyframe (the old keyframe's pose turned by the
    /// heading between the scans), when the candidate came from it: the start of the check
    /// instead of the new keyframe's own estimate, which may have drifted far.
    guess: Option<Pose3>,
}

/// The candidates waiting for a loop-closure step, oldest first, and when each kind was last
/// queued (the two kinds are throttled apart).
#[derive(Debug, Default)]
pub(super) struct LoopQueue {
    pending: VecDeque<LoopCandidate>,
    /// The last keyframe that queued an old keyframe near it.
    last_near: Option<usize>,
    /// The last keyframe that queued a look-alike from place recognition.
    last_look_alike: Option<usize>,
}

impl<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>> GraphSlam<R, C, O> {
    /// Queue a loop candidate for keyframe `index` at `pose`: the oldest keyframe near it outside
    /// the local window, or else the best look-alike place recognition found. The two kinds are
    /// throttled apart ([`GraphSlamConfig::loop_min_keyframe_gap`] each), so that look-alikes
    /// refused one after another (a corridor of identical rooms) never keep a loop by position
    /// from being tried.
    ///
    /// [`GraphSlamConfig::loop_min_keyframe_gap`]: super::GraphSlamConfig::loop_min_keyframe_gap
    pub(super) fn queue_loop_candidate(
        &mut self,
        index: usize,
        pose: &Pose3,
        look_alikes: &[PlaceMatch],
    ) {
        let window = self.config.local_map_keyframes;
        if index <= window {
            return;
        }
        let gap = self.config.loop_min_keyframe_gap;
        let may_try = |last: Option<usize>| last.is_none_or(|l| index >= l + gap);
        // Keyframes in the local map are tied to this one by its registration already.
        let near = may_try(self.loops.last_near)
            .then(|| {
                self.node_index
                    .oldest_within(pose, self.config.loop_search_radius, |i| {
                        i < index - window && !self.window.contains(i)
                    })
            })
            .flatten();
        let candidate = match near {
            Some(old) => {
                self.loops.last_near = Some(index);
                Some((old, None))
            }
            // Only the best look-alike: the next best of a place whose best is recent is
            // rarely the same place.
            None if may_try(self.loops.last_look_alike) => look_alikes
                .first()
                .filter(|m| m.keyframe < index - window && !self.window.contains(m.keyframe))
                .map(|m| {
                    self.loops.last_look_alike = Some(index);
                    let turn = Pose3::from_parts(
                        nalgebra::Translation3::identity(),
                        nalgebra::UnitQuaternion::from_euler_angles(0.0, 0.0, m.yaw),
                    );
                    (m.keyframe, Some(self.keyframe_pose(m.keyframe) * turn))
                }),
            None => None,
        };
        if let Some((old, guess)) = candidate {
            self.report.place_candidates += usize::from(guess.is_some());
            self.loops.pending.push_back(LoopCandidate {
                old,
                new: index,
                guess,
            });
        }
    }

    /// How far (metres) a loop from keyframe `old` to `new` may move `new`: the loop search
    /// radius plus [`GraphSlamConfig::loop_max_drift_rate`](super::GraphSlamConfig) of the
    /// distance walked between them.
    fn drift_allowance(&self, old: usize, new: usize) -> f64 {
        self.config.loop_search_radius + self.config.loop_max_drift_rate * self.walked(old, new)
    }

    /// How far (metres) a loop from keyframe `old` to `new` may move `new` up or down: the
    /// loop search radius plus
    /// [`GraphSlamConfig::loop_max_height_drift_rate`](super::GraphSlamConfig) of the distance
    /// walked between them.
    fn height_drift_allowance(&self, old: usize, new: usize) -> f64 {
        self.config.loop_search_radius
            + self.config.loop_max_height_drift_rate * self.walked(old, new)
    }

    /// The distance walked between keyframes `old` and `new` (metres).
    fn walked(&self, old: usize, new: usize) -> f64 {
        (self.keyframes[new].walked - self.keyframes[old].walked).abs()
    }

    /// Try the oldest queued loop candidate: coarse alignment of the new keyframe to the
    /// candidate's neighbourhood, acceptance on its mean squared error, refinement, a new edge and
    /// one optimisation. Bounded: at most one candidate per call. A rejection is counted by its
    /// reason ([`SlamReport::loop_rejections`]).
    pub fn loop_closure_step(&mut self) -> LoopOutcome {
        let Some(candidate) = self.loops.pending.pop_front() else {
            return LoopOutcome::Idle;
        };
        let started = Instant::now();
        self.report.loops_attempted += 1;
        let outcome = match self.try_loop(&candidate) {
            Ok(mean_squared_error) => {
                self.close_loop(&candidate);
                LoopOutcome::Closed {
                    from: candidate.old as u64,
                    to: candidate.new as u64,
                    mean_squared_error,
                }
            }
            Err(reason) => {
                self.report.loop_rejections.add(reason);
                LoopOutcome::Rejected {
                    from: candidate.old as u64,
                    to: candidate.new as u64,
                    reason,
                }
            }
        };
        SlamReport::record(
            &mut self.report.loop_ms,
            started.elapsed().as_secs_f64() * 1e3,
        );
        outcome
    }

    /// Checks `candidate` and adds its edge to the graph: the coarse alignment's mean squared
    /// error, or why it was rejected.
    fn try_loop(&mut self, candidate: &LoopCandidate) -> Result<f64, LoopRejection> {
        let (cand, new) = (candidate.old, candidate.new);
        let lo = cand.saturating_sub(self.config.loop_neighbours);
        // Keep the neighbourhood disjoint from the new keyframe's own recent window.
        let hi = (cand + self.config.loop_neighbours)
            .min(new.saturating_sub(self.config.local_map_keyframes));
        // Old keyframes' points may come back from the keyframe store's file.
        let coarse_loaded = (lo..=hi.max(cand))
            .map(|i| Ok((self.coarse_of(i)?, self.keyframe_pose(i))))
            .collect::<Result<Vec<_>, KeyframeCloudError>>()
            .map_err(|_| LoopRejection::CoarseTarget)?;
        let refine_loaded = (lo..=hi.max(cand))
            .map(|i| Ok((self.source_of(i)?, self.keyframe_pose(i))))
            .collect::<Result<Vec<_>, KeyframeCloudError>>()
            .map_err(|_| LoopRejection::RefineTarget)?;
        let new_coarse = self
            .coarse_of(new)
            .map_err(|_| LoopRejection::CoarseTarget)?;
        let new_source = self
            .source_of(new)
            .map_err(|_| LoopRejection::RefineTarget)?;
        let coarse_parts: Vec<(&C::Source, Pose3)> =
            coarse_loaded.iter().map(|(s, p)| (&**s, *p)).collect();
        let refine_parts: Vec<(&R::Source, Pose3)> =
            refine_loaded.iter().map(|(s, p)| (&**s, *p)).collect();
        let initial = candidate.guess.unwrap_or_else(|| self.keyframe_pose(new));
        let coarse_target = self
            .loop_coarse
            .target_from_sources(&coarse_parts)
            .map_err(|_| LoopRejection::CoarseTarget)?;
        let coarse = self
            .loop_coarse
            .align(&new_coarse, &coarse_target, &initial)
            .map_err(|_| LoopRejection::CoarseAlignment)?;
        if !coarse.converged || !pose3_is_finite(&coarse.pose) {
            return Err(LoopRejection::CoarseNotConverged);
        }
        let mse = coarse.rmse * coarse.rmse;
        if mse > self.config.loop_max_mean_squared_error {
            return Err(LoopRejection::CoarseMismatch);
        }
        let refine_target = self
            .loop_refine
            .target_from_sources(&refine_parts)
            .map_err(|_| LoopRejection::RefineTarget)?;
        let refined = self
            .loop_refine
            .align(&new_source, &refine_target, &coarse.pose)
            .map_err(|_| LoopRejection::RefineAlignment)?;
        if !refined.converged || !pose3_is_finite(&refined.pose) {
            return Err(LoopRejection::RefineNotConverged);
        }
        let shift = (refined.pose.translation.vector - coarse.pose.translation.vector).norm();
        if shift > self.config.loop_max_refine_shift {
            return Err(LoopRejection::RefineShift);
        }
        // The correction this loop makes to the new keyframe, against the drift the walk since
        // the candidate could have gathered.
        let correction =
            (refined.pose.translation.vector - self.keyframe_pose(new).translation.vector).norm();
        if correction > self.drift_allowance(cand, new) {
            return Err(LoopRejection::BeyondDrift);
        }
        let rise = (refined.pose.translation.z - self.keyframe_pose(new).translation.z).abs();
        if rise > self.height_drift_allowance(cand, new) {
            return Err(LoopRejection::BeyondHeightDrift);
        }
        let info = edge_information(
            self.config.loop_information,
            Some(&refined.information),
            &refined.pose,
        );
        self.loop_edges.push(self.graph.edges().len());
        self.graph
            .add_edge(
                cand as u64,
                new as u64,
                self.keyframe_pose(cand).inverse() * refined.pose,
                info,
                self.config.loop_kernel,
            )
            .map_err(|_| {
                self.loop_edges.pop();
                LoopRejection::EdgeRefused
            })?;
        let loop_edge = self.loop_edges.last().copied();
        self.keyframes[cand].links.push(Link {
            keyframe: new,
            loop_edge,
        });
        self.keyframes[new].links.push(Link {
            keyframe: cand,
            loop_edge,
        });
        Ok(mse)
    }

    /// After `candidate`'s edge joined the graph: one optimisation, the loop counted, the local
    /// map and the node index rebuilt at the moved poses.
    fn close_loop(&mut self, candidate: &LoopCandidate) {
        if self.optimizer.optimize(&mut self.graph).is_err() {
            self.report.optimizer_failures += 1;
        }
        if let Some(weights) = self.optimizer.edge_weights() {
            self.report.loops_weighted_out = self
                .loop_edges
                .iter()
                .filter(|&&k| weights.get(k).is_some_and(|&w| w < 0.5))
                .count();
        }
        self.report.loops_closed += 1;
        self.report.place_loops_closed += usize::from(candidate.guess.is_some());
        self.start_revisit(candidate.old, candidate.new);
        // The keyframes moved: rebuild the local map now, within this step, so that the next
        // scan's odometry does not pay for it.
        self.local_map = None;
        self.ensure_local_map();
        let poses: Vec<Pose3> = self.graph.nodes().iter().map(|n| n.pose).collect();
        self.node_index.rebuild(poses.iter());
    }
}
