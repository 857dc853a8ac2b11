//! A scan made ready for the odometry: thinned to the map's voxel (a dense scan costs what its
//! voxels cost, not what its points cost), deskewed with the predicted velocity, thinned again
//! to the odometry's source voxel and prepared for its registrator; deskewed anew once the
//! sweep's own motion is known.

use nalgebra::Vector6;

use super::deskew::deskew;
use super::engine::{GraphSlam, ScanInput};
use super::keyframes::Sweep;
use super::report::SkipReason;
use crate::cloud::PointCloud;
use crate::geometry::Pose3;
use crate::tracking::scan_extent;
use crate::traits::optimizer::Optimizer;
use crate::traits::registrator::MapRegistrator;

/// A scan made ready for the odometry.
pub(super) struct Prepared<S> {
    /// Deskewed, finite points (LiDAR frame), at the map's voxel when `thinned` is given.
    pub(super) cloud: PointCloud,
    /// The scan thinned to the map's voxel before deskewing, when the backend takes it so.
    pub(super) thinned: Option<PointCloud>,
    /// `cloud` thinned again to the odometry's source voxel when `thinned` is given: what the
    /// source is prepared from and the sweep's motion is found on (voxelised once, not twice),
    /// and what a dense scan's keyframe keeps within
    /// [`GraphSlamConfig::keyframe_scan_spacing`](super::GraphSlamConfig) of the last whole one.
    pub(super) coarse: Option<PointCloud>,
    /// How it was deskewed, when it was.
    pub(super) sweep: Option<Sweep>,
    /// Prepared for the odometry registrator.
    pub(super) source: S,
    /// How far the scan reaches ([`scan_extent`]).
    pub(super) extent: f64,
}

impl<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>> GraphSlam<R, C, O> {
    /// `scan` deskewed with `velocity` (when given), non-finite points dropped (and counted),
    /// prepared for the odometry; why not when too few points are left or the registrator
    /// refuses it.
    pub(super) fn prepare(
        &mut self,
        scan: &ScanInput<'_>,
        velocity: Option<Vector6<f64>>,
    ) -> Result<Prepared<R::Source>, SkipReason> {
        // A backend that only thins the scan by voxel gets it thinned once, to the map's voxel,
        // before anything else: deskewing, registering and keeping a dense scan then cost what
        // its voxels cost, not what its points cost (an OS1-128 sweep: 131,072 points).
        let voxel = self.config.map_voxel_size;
        let thin = self.odometry.source_voxel().is_some_and(|v| v >= voxel);
        let cloud = scan.cloud;
        let mut thinning = None;
        // A garbled return beyond any voxel key is dropped and counted, not allowed to fail the
        // thinning of the whole scan.
        let mut work = || thinning = thin.then(|| cloud.voxel_downsample_keyable(voxel).ok());
        // The local map, changed by the last keyframe, is indexed for this scan's registration
        // on the other core meanwhile (an OS1-128 window: about 2 ms of each).
        match self.local_map.as_mut() {
            Some(map) => self.odometry.ready_map_beside(&mut map.target, &mut work),
            None => work(),
        }
        let (thinned, far) = thinning
            .flatten()
            .map_or((None, 0), |(thinned, far)| (Some(thinned), far));
        let base = thinned.as_ref().unwrap_or(scan.cloud);
        let deskewed = velocity.and_then(|v| deskew(base, &v).map(|c| (c, v)));
        let sweep = deskewed.as_ref().and_then(|(_, v)| Sweep::of(base, *v));
        let mut cloud = deskewed.map_or_else(|| base.clone(), |(c, _)| c);
        let dropped = match thinned {
            Some(_) => {
                far + scan
                    .cloud
                    .points()
                    .iter()
                    .filter(|p| !p.iter().all(|v| v.is_finite()))
                    .count()
            }
            None => cloud.remove_non_finite(),
        };
        if cloud.len() < self.config.min_scan_points {
            return Err(SkipReason::TooFewPoints);
        }
        let coarse = self.coarse(&cloud, thinned.is_some());
        let source = self
            .odometry
            .prepare_source(coarse.as_ref().unwrap_or(&cloud))
            .map_err(|_| SkipReason::PreparationFailed)?;
        self.report.dropped_points += dropped;
        Ok(Prepared {
            extent: scan_extent(&cloud),
            cloud,
            thinned,
            coarse,
            sweep,
            source,
        })
    }

    /// Whether `scan` is dense enough for its keyframes to keep their whole scan only every
    /// [`GraphSlamConfig::keyframe_scan_spacing`](super::GraphSlamConfig).
    pub(super) fn spaces_whole_scans(&self, scan: &ScanInput<'_>) -> bool {
        self.config.keyframe_scan_spacing > 0.0 && scan.cloud.len() > self.config.dense_scan_points
    }

    /// Whether a keyframe at `pose` is far enough from the last one that kept its whole scan
    /// to keep its own ([`GraphSlamConfig::keyframe_scan_spacing`](super::GraphSlamConfig)).
    pub(super) fn whole_scan_due(&self, pose: &Pose3) -> bool {
        self.last_whole_scan.is_none_or(|k| {
            (self.keyframe_pose(k).translation.vector - pose.translation.vector).norm()
                >= self.config.keyframe_scan_spacing
        })
    }

    /// `cloud` (deskewed, at the map's voxel when `thinned`) at the odometry's source voxel,
    /// when the scan was thinned for it.
    fn coarse(&self, cloud: &PointCloud, thinned: bool) -> Option<PointCloud> {
        let voxel = self.odometry.source_voxel().filter(|_| thinned)?;
        cloud.voxel_downsample(voxel).ok()
    }

    /// `prepared` deskewed anew with `velocity` (the one its sweep was registered with), and
    /// prepared again for the map; as it was when the correction is implausible (beyond 10 rad/s
    /// or 10 m/s) or the scan cannot be prepared.
    pub(super) fn redeskew(
        &self,
        scan: &ScanInput<'_>,
        prepared: Prepared<R::Source>,
        velocity: Vector6<f64>,
    ) -> Prepared<R::Source> {
        let plausible = velocity.fixed_rows::<3>(0).norm() <= 10.0
            && velocity.fixed_rows::<3>(3).norm() <= 10.0;
        let base = prepared.thinned.as_ref().unwrap_or(scan.cloud);
        let again = plausible
            .then(|| deskew(base, &velocity))
            .flatten()
            .and_then(|mut cloud| {
                cloud.remove_non_finite();
                let coarse = self.coarse(&cloud, prepared.thinned.is_some());
                let source = self
                    .odometry
                    .prepare_source(coarse.as_ref().unwrap_or(&cloud))
                    .ok()?;
                Some((cloud, coarse, source))
            });
        match again {
            Some((cloud, coarse, source)) => Prepared {
                sweep: Sweep::of(base, velocity),
                cloud,
                coarse,
                source,
                ..prepared
            },
            None => prepared,
        }
    }
}
