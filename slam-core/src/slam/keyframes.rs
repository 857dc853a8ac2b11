//! What the engine keeps of each scan: keyframes (graph nodes with their clouds) and every
//! accepted scan's pose riding on one; the trajectories and the map read from them.

use std::borrow::Cow;

use nalgebra::Vector6;

use super::cloud_store::{KeyframeCloudError, KeyframeClouds, Loaded, Stash};
use super::engine::GraphSlam;
use crate::cloud::PointCloud;
use crate::geometry::Pose3;
use crate::io::StampedPose;
use crate::traits::optimizer::Optimizer;
use crate::traits::registrator::MapRegistrator;

/// A keyframe: a node of the graph with what the engine keeps of its scan.
pub(super) struct Keyframe<S, C> {
    pub(super) stamp: f64,
    /// The odometry at the keyframe, `None` for a LiDAR-only scan.
    pub(super) odom_t_lidar: Option<Pose3>,
    /// Prepared for the odometry/refinement registrator (read with
    /// [`GraphSlam::source_of`]).
    pub(super) source: Stash<S>,
    /// Prepared for the coarse loop registrator (read with [`GraphSlam::coarse_of`]).
    pub(super) coarse: Stash<C>,
    /// Distance walked from the first keyframe to this one along the estimate when it was
    /// made (metres): the drift a loop may correct grows with it.
    pub(super) walked: f64,
    /// The share of its scan its registration matched (0, unknown, for the first keyframe and
    /// one that fell back to its prediction): a revisit that matches much less has found the place
    /// changed.
    pub(super) matched: f64,
    /// The keyframes joined to it by an edge: its odometry edge's two ends (the previous
    /// keyframe, or on a revisit the old keyframe the walk rode on) and each accepted loop's
    /// other end, with the loop edge's index in the graph.
    pub(super) links: Vec<Link>,
}

/// The points in `stash`: borrowed when held, read back from `store`'s file and restored by
/// `registrator` when written out.
pub(super) fn source_of<'a, M: MapRegistrator>(
    stash: &'a Stash<M::Source>,
    store: &KeyframeClouds,
    registrator: &M,
) -> Result<Loaded<'a, M::Source>, KeyframeCloudError> {
    match stash {
        Stash::Held(s) => Ok(Loaded::Borrowed(s)),
        &Stash::Stored { offset, len } => {
            let bytes = store.read_bytes(offset, len)?;
            registrator
                .restored_source(&bytes)
                .map(Loaded::Owned)
                .ok_or_else(|| store.not_restored())
        }
    }
}

/// Writes the points held in `stash` to `store`'s file when `registrator` can write them; on a
/// failed write they stay held.
fn stash<M: MapRegistrator>(
    stash: &mut Stash<M::Source>,
    registrator: &M,
    store: &mut KeyframeClouds,
) -> Result<(), KeyframeCloudError> {
    if let Stash::Held(points) = stash
        && let Some(bytes) = registrator.stored_source(points)
    {
        let offset = store.write_bytes(&bytes)?;
        *stash = Stash::Stored {
            offset,
            len: bytes.len(),
        };
    }
    Ok(())
}

/// An edge of the graph seen from one of its keyframes.
#[derive(Clone, Copy, Debug)]
pub(super) struct Link {
    /// The keyframe at the other end.
    pub(super) keyframe: usize,
    /// The edge's index in the graph's edges when it is a loop (which an optimiser may weight
    /// out); `None` for an odometry edge.
    pub(super) loop_edge: Option<usize>,
}

/// An accepted scan: its stamp and LiDAR pose relative to its keyframe, so that it rides on the
/// keyframe's optimised pose.
#[derive(Clone, Copy, Debug)]
pub(super) struct ScanPose {
    pub(super) stamp: f64,
    /// Index of the keyframe.
    pub(super) keyframe: usize,
    /// The scan's LiDAR pose in the keyframe's LiDAR frame.
    pub(super) keyframe_t_lidar: Pose3,
    /// How the scan was deskewed, when it was.
    pub(super) sweep: Option<Sweep>,
}

/// The motion a scan was deskewed with.
#[derive(Clone, Copy, Debug)]
pub(super) struct Sweep {
    /// The middle of the sweep (seconds after the stamp).
    pub(super) middle: f64,
    /// The velocity (LiDAR-frame twist per second).
    pub(super) velocity: Vector6<f64>,
}

impl Sweep {
    /// The sweep of `cloud` (its time channel) deskewed with `velocity`; `None` without times.
    pub(super) fn of(cloud: &PointCloud, velocity: Vector6<f64>) -> Option<Self> {
        let times = cloud.time()?;
        let (lo, hi) = times
            .iter()
            .filter(|t| t.is_finite())
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &t| {
                (a.min(t), b.max(t))
            });
        (lo <= hi).then(|| Self {
            middle: 0.5 * f64::from(lo + hi),
            velocity,
        })
    }
}

impl<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>> GraphSlam<R, C, O> {
    /// Number of keyframes.
    #[must_use]
    pub fn keyframe_count(&self) -> usize {
        self.keyframes.len()
    }

    /// Keyframe `i`'s points prepared for the odometry and refinement registrator, read back
    /// from the store's file when they were written out.
    pub(super) fn source_of(&self, i: usize) -> Result<Loaded<'_, R::Source>, KeyframeCloudError> {
        source_of(&self.keyframes[i].source, &self.clouds, &self.odometry)
    }

    /// Keyframe `i`'s points prepared for the coarse loop registrator, as
    /// [`GraphSlam::source_of`].
    pub(super) fn coarse_of(&self, i: usize) -> Result<Loaded<'_, C::Source>, KeyframeCloudError> {
        source_of(&self.keyframes[i].coarse, &self.clouds, &self.loop_coarse)
    }

    /// With a store's file, writes out the prepared points of the keyframes older than the
    /// newest it keeps in memory (those the registrators can write); a write that fails leaves
    /// them in memory and is counted.
    pub(super) fn stash_old_points(&mut self) {
        let Some(resident) = self.clouds.resident() else {
            return;
        };
        while self.clouds.sources_out + resident < self.keyframes.len() {
            let i = self.clouds.sources_out;
            self.clouds.sources_out += 1;
            let failures = usize::from(
                stash(
                    &mut self.keyframes[i].source,
                    &self.odometry,
                    &mut self.clouds,
                )
                .is_err(),
            ) + usize::from(
                stash(
                    &mut self.keyframes[i].coarse,
                    &self.loop_coarse,
                    &mut self.clouds,
                )
                .is_err(),
            );
            self.report.keyframe_store_failures += failures;
        }
    }

    /// Keyframe `i`'s optimised LiDAR pose (`map_T_lidar`).
    pub(super) fn keyframe_pose(&self, i: usize) -> Pose3 {
        self.graph.nodes()[i].pose
    }

    /// The latest LiDAR pose in the map frame (`map_T_lidar`), `None` before the first scan.
    #[must_use]
    pub fn current_lidar_pose(&self) -> Option<Pose3> {
        let s = self.scan_poses.last()?;
        Some(self.keyframe_pose(s.keyframe) * s.keyframe_t_lidar)
    }

    /// Optimised keyframe trajectory: stamp and `map_T_lidar` per keyframe.
    #[must_use]
    pub fn keyframe_trajectory(&self) -> Vec<StampedPose> {
        self.keyframes
            .iter()
            .enumerate()
            .map(|(i, k)| StampedPose {
                stamp: k.stamp,
                pose: self.keyframe_pose(i),
            })
            .collect()
    }

    /// Trajectory of every accepted scan, stamp and `map_T_lidar`: each scan rides on its
    /// keyframe, so loop closures correct it too.
    #[must_use]
    pub fn scan_trajectory(&self) -> Vec<StampedPose> {
        self.scan_poses
            .iter()
            .map(|s| StampedPose {
                stamp: s.stamp,
                pose: self.keyframe_pose(s.keyframe) * s.keyframe_t_lidar,
            })
            .collect()
    }

    /// Every keyframe's scan (voxel-filtered, in the LiDAR frame; positions and intensities,
    /// no ring or time channel) with its optimised `map_T_lidar`: the rays an occupancy grid's
    /// free space comes from. A scan held in memory is borrowed; one the engine keeps in its
    /// file ([`GraphSlam::with_keyframe_store`]) is read back.
    ///
    /// # Errors
    /// [`KeyframeCloudError::Store`] for a scan the store's file no longer gives back.
    pub fn keyframe_scans(
        &self,
    ) -> impl Iterator<Item = Result<(Pose3, Cow<'_, PointCloud>), KeyframeCloudError>> + '_ {
        (0..self.keyframes.len()).filter_map(|i| self.keyframe_scan(i))
    }

    /// Keyframe `i`'s scan with its optimised `map_T_lidar`, as [`GraphSlam::keyframe_scans`]
    /// gives it; `None` past the last keyframe.
    pub fn keyframe_scan(
        &self,
        i: usize,
    ) -> Option<Result<(Pose3, Cow<'_, PointCloud>), KeyframeCloudError>> {
        let cloud = self.clouds.get(i)?;
        Some(cloud.map(|c| (self.keyframe_pose(i), c)))
    }

    /// How many keyframe scans are held in memory (all but those written to the store's file).
    #[must_use]
    pub fn keyframe_scans_in_memory(&self) -> usize {
        self.clouds.held()
    }

    /// The map: every keyframe cloud at its optimised pose, voxel-filtered at `voxel_size`.
    ///
    /// # Errors
    /// [`KeyframeCloudError::Cloud`] for a bad voxel size; as
    /// [`GraphSlam::keyframe_scans`].
    pub fn map(&self, voxel_size: f32) -> Result<PointCloud, KeyframeCloudError> {
        let mut all = PointCloud::new();
        for scan in self.keyframe_scans() {
            let (pose, cloud) = scan?;
            // Channels may differ between sensors' scans; the map keeps positions only.
            let c = PointCloud::from_points(cloud.transformed(&pose).into_parts().0);
            all.extend_from(&c)?;
        }
        Ok(all.voxel_downsample(voxel_size)?)
    }
}
