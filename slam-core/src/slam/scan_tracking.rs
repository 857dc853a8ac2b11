//! A prepared scan registered against the local map by the tracker, then (LiDAR-only, swept)
//! registered again together with its sweep's own motion and deskewed anew with it.

use nalgebra::{Matrix6, Vector6};

use crate::tracking::replaces;
use crate::traits::registrator::{Alignment, SweepAlignment};

use super::engine::{GraphSlam, ScanInput};
use super::scan_preparation::Prepared;
use crate::geometry::{Pose3, pose3_is_finite};
use crate::traits::optimizer::Optimizer;
use crate::traits::registrator::MapRegistrator;

/// Points of a sweep's cheap first recheck: as many as a wide stage of the tracker pairs.
const RECHECK_SWEEP_POINTS: usize = 600;

/// A scan after tracking.
pub(super) struct TrackedScan<S> {
    /// The scan, deskewed anew when its sweep's motion was found.
    pub(super) prepared: Prepared<S>,
    /// Its LiDAR pose in the map frame: registered, or the prediction on a fallback.
    pub(super) pose: Pose3,
    /// The registration's information; `None` on a fallback.
    pub(super) information: Option<Matrix6<f64>>,
    /// The share of the scan's points the registration matched (0 on a fallback).
    pub(super) inlier_ratio: f64,
}

impl<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>> GraphSlam<R, C, O> {
    /// `prepared` registered from `guesses`; with `refine_sweep` (a swept scan without
    /// odometry, whose velocity between two scans says little about the 0.1 s of one sweep: at
    /// 2 Hz a hand's shake is faster than the scans) registered again with its sweep's own
    /// motion and deskewed anew with `velocity` corrected by it.
    pub(super) fn track(
        &mut self,
        scan: &ScanInput<'_>,
        prepared: Prepared<R::Source>,
        guesses: &[Pose3],
        velocity: Option<Vector6<f64>>,
        refine_sweep: bool,
    ) -> TrackedScan<R::Source> {
        let (pose, registered) = self.register(&prepared, guesses);
        let mut tracked = TrackedScan {
            prepared,
            pose,
            information: registered.as_ref().map(|a| a.information),
            inlier_ratio: registered.as_ref().map_or(0.0, |a| a.inlier_ratio),
        };
        if refine_sweep
            && self.config.sweep_motion
            && let Some(rigid) = registered.as_ref()
            && let Some(sweep) = self.sweep_motion(&tracked.prepared, &tracked.pose, rigid)
        {
            let sweep = self.recheck_sweep(&tracked.prepared, guesses, sweep);
            let a = sweep.alignment;
            // The second scan has no velocity yet: its sweep's own motion is all there is.
            let v = velocity.unwrap_or_else(Vector6::zeros);
            tracked.prepared = self.redeskew(scan, tracked.prepared, v + sweep.velocity_correction);
            tracked.pose = a.pose;
            tracked.information = Some(a.information);
            tracked.inlier_ratio = a.inlier_ratio;
        }
        tracked
    }

    /// `found`, or the sweep registered from the predicted position (`guesses[0]`) with
    /// `found`'s rotation when `found` ended more than
    /// [`TrackerConfig::recheck_distance`](crate::tracking::TrackerConfig::recheck_distance) from
    /// that position and the other matched at least as much of the sweep with no larger RMS error:
    /// the tracker's own recheck compares registrations of a scan deskewed with the last scan's
    /// velocity, which after a jolt fits well nowhere until the sweep's motion is found.
    fn recheck_sweep(
        &self,
        prepared: &Prepared<R::Source>,
        guesses: &[Pose3],
        found: SweepAlignment,
    ) -> SweepAlignment {
        let (Some(prediction), Some(map)) = (guesses.first(), self.local_map.as_ref()) else {
            return found;
        };
        let Some(start) = self
            .config
            .tracker
            .recheck_start(prediction, &found.alignment.pose)
        else {
            return found;
        };
        let sweep = prepared.coarse.as_ref().unwrap_or(&prepared.cloud);
        // First on a few of its points (as many as a wide stage pairs): within the basin of
        // `found`, `found` stands; otherwise the whole sweep goes on from there.
        let tracker = &self.config.tracker;
        let start = if tracker.recheck_basin > 0.0 {
            let every = sweep.len().div_ceil(RECHECK_SWEEP_POINTS).max(1);
            let few = sweep.filtered(|i, _| i % every == 0);
            match self.odometry.align_sweep(&few, &map.target, &start) {
                Some(Ok(c)) if tracker.in_basin(&c.alignment.pose, &found.alignment.pose) => {
                    return found;
                }
                Some(Ok(c)) if pose3_is_finite(&c.alignment.pose) => c.alignment.pose,
                _ => start,
            }
        } else {
            start
        };
        match self.odometry.align_sweep(sweep, &map.target, &start) {
            Some(Ok(other)) if replaces(&other.alignment, &found.alignment) => other,
            _ => found,
        }
    }

    /// The pose of a scan and the registration taken: registered against the local map from
    /// `guesses` (the prediction first) by the tracker; the prediction and `None`, counted as a
    /// fallback, when it cannot be (no map, or the registration is not taken). An alternative
    /// guess that wins counts as an odometry fault.
    fn register(
        &mut self,
        prepared: &Prepared<R::Source>,
        guesses: &[Pose3],
    ) -> (Pose3, Option<Alignment>) {
        let has_map = self.ensure_local_map();
        let target = self
            .local_map
            .as_ref()
            .filter(|_| has_map)
            .map(|m| &m.target);
        let outcome = self.tracker.track(
            &self.odometry,
            &prepared.source,
            target,
            guesses,
            prepared.extent,
        );
        self.report.tracking = *self.tracker.health();
        if outcome.tracked() && outcome.guess > 0 {
            self.report.odometry_faults += 1;
        }
        // Scan poses are chained on each other without odometry: keep their quaternions unit,
        // or rounding compounds scan after scan.
        let mut pose = outcome.pose;
        pose.rotation.renormalize();
        (pose, outcome.alignment)
    }

    /// The scan registered again from `pose` (its registration) together with its sweep's own
    /// motion ([`Registrator::align_sweep`](crate::Registrator::align_sweep)): the pose at the
    /// sweep's start with its fit and information, and the correction to the velocity it was
    /// deskewed with.
    /// `None` when the backend cannot, or the result is not taken (too few inliers, a non-finite
    /// pose, too small a gain over `rigid`, the scan's own registration:
    /// [`GraphSlamConfig::sweep_min_gain`](super::GraphSlamConfig::sweep_min_gain),
    /// [`GraphSlamConfig::sweep_min_inlier_gain`](super::GraphSlamConfig::sweep_min_inlier_gain)).
    fn sweep_motion(
        &self,
        prepared: &Prepared<R::Source>,
        pose: &Pose3,
        rigid: &Alignment,
    ) -> Option<SweepAlignment> {
        let map = &self.local_map.as_ref()?.target;
        let sweep = self
            .odometry
            .align_sweep(
                prepared.coarse.as_ref().unwrap_or(&prepared.cloud),
                map,
                pose,
            )?
            .ok()?;
        let a = &sweep.alignment;
        let gain = self.config.sweep_min_gain;
        let more = self.config.sweep_min_inlier_gain;
        let better = a.rmse <= rigid.rmse * (1.0 - gain)
            || (a.inlier_ratio >= rigid.inlier_ratio + more && a.rmse <= rigid.rmse);
        (pose3_is_finite(&a.pose)
            && a.inlier_ratio >= self.config.tracker.min_inlier_ratio
            && better)
            .then_some(sweep)
    }
}
