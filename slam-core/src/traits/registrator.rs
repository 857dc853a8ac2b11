//! The `Registrator` trait: align a source cloud to a target cloud.

use nalgebra::{Matrix6, Vector6};

use crate::cloud::PointCloud;
use crate::error::RegistrationError;
use crate::geometry::Pose3;

/// The outcome of one alignment.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Alignment {
    /// `target_T_source`: maps source points into the target frame.
    pub pose: Pose3,
    /// Whether the update fell below the convergence thresholds before the iteration cap.
    pub converged: bool,
    /// Iterations run.
    pub iterations: usize,
    /// Source points with an accepted correspondence in the last iteration.
    pub inliers: usize,
    /// `inliers` over the number of source points used.
    pub inlier_ratio: f64,
    /// Root mean squared residual (metres) of the inliers at the final pose.
    pub rmse: f64,
    /// `J^T W J` of the last linearisation (6x6, tangent order `[rho; phi]`, perturbation on the
    /// left of `pose`): weigh a pose-graph edge with it.
    pub information: Matrix6<f64>,
    /// Smallest eigenvalue of `information`, relative to the largest: near zero means a degenerate
    /// direction (a long featureless corridor, a single plane).
    pub min_eigenvalue_ratio: f64,
}

/// How far a tracker lets one alignment look for correspondences: it widens the reach after its
/// motion prediction has been far off (a sudden turn) and narrows it when the prediction is good,
/// where a wide reach would pair points with the wrong surfaces.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Reach {
    /// Points farther apart than this (metres) are not paired.
    pub distance: f64,
    /// Scale of the robust kernel (metres): the backend's kernel threshold (Tukey's `k`,
    /// Huber's `k`) for this alignment. Residuals well beyond it stop counting.
    pub kernel: f64,
}

impl Reach {
    /// Whether both lengths are finite and positive.
    #[must_use]
    pub fn is_valid(&self) -> bool {
        self.distance.is_finite()
            && self.distance > 0.0
            && self.kernel.is_finite()
            && self.kernel > 0.0
    }
}

/// A sweep registered with its own motion ([`Registrator::align_sweep`]).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SweepAlignment {
    /// The alignment; its pose is the sensor's at time 0 of the sweep.
    pub alignment: Alignment,
    /// The correction to the velocity the sweep was deskewed with (a twist per second in the
    /// sensor frame, `[v; w]`): the sweep's own motion is that velocity plus this.
    pub velocity_correction: Vector6<f64>,
}

/// A registration backend. Preparing a cloud (k-d tree, normals, features) is separate from
/// aligning, so that a target can be prepared once and aligned against many times.
///
/// ```
/// use nalgebra::{Matrix6, Point3, Vector3};
/// use slam_core::{Alignment, PointCloud, Pose3, Reach, Registrator, RegistrationError};
///
/// /// Aligns centroids only: a toy backend that shows the contract.
/// struct CentroidAligner;
///
/// impl Registrator for CentroidAligner {
///     type Source = Point3<f64>;
///     type Target = Point3<f64>;
///     fn prepare_source(&self, c: &PointCloud) -> Result<Self::Source, RegistrationError> {
///         c.centroid().ok_or(RegistrationError::TooFewPoints { what: "source", points: 0, required: 1 })
///     }
///     fn prepare_target(&self, c: &PointCloud) -> Result<Self::Target, RegistrationError> {
///         c.centroid().ok_or(RegistrationError::TooFewPoints { what: "target", points: 0, required: 1 })
///     }
///     /// Centroids pair no points: there is no reach to limit.
///     fn align_within(&self, s: &Self::Source, t: &Self::Target, initial: &Pose3, _: &Reach)
///         -> Result<Alignment, RegistrationError> {
///         self.align(s, t, initial)
///     }
///     fn align(&self, s: &Self::Source, t: &Self::Target, _initial: &Pose3)
///         -> Result<Alignment, RegistrationError> {
///         Ok(Alignment {
///             pose: Pose3::translation(t.x - s.x, t.y - s.y, t.z - s.z),
///             converged: true, iterations: 1, inliers: 1, inlier_ratio: 1.0, rmse: 0.0,
///             information: Matrix6::identity(), min_eigenvalue_ratio: 1.0,
///         })
///     }
/// }
///
/// let source = PointCloud::from_points(vec![Point3::new(0.0, 0.0, 0.0)]);
/// let target = PointCloud::from_points(vec![Point3::new(1.0, 2.0, 3.0)]);
/// let r = CentroidAligner;
/// let a = r.align(&r.prepare_source(&source)?, &r.prepare_target(&target)?, &Pose3::identity())?;
/// assert_eq!(a.pose.translation.vector, Vector3::new(1.0, 2.0, 3.0));
/// # Ok::<(), RegistrationError>(())
/// ```
pub trait Registrator {
    /// A source cloud made ready for alignment (downsampled, features extracted).
    type Source;
    /// A target made ready for queries (k-d tree, normals, features).
    type Target;

    /// Prepare a cloud to be aligned.
    ///
    /// # Errors
    /// [`RegistrationError::TooFewPoints`] when too little is left after filtering.
    fn prepare_source(&self, cloud: &PointCloud) -> Result<Self::Source, RegistrationError>;

    /// Prepare a cloud to be aligned against (done once, reused for many sources).
    ///
    /// # Errors
    /// [`RegistrationError::TooFewPoints`] when too little is left after filtering.
    fn prepare_target(&self, cloud: &PointCloud) -> Result<Self::Target, RegistrationError>;

    /// Find `target_T_source`, starting from `initial`.
    ///
    /// # Errors
    /// A non-finite initial guess, too few correspondences, or a degenerate system. Failing to
    /// converge within the iteration cap is not an error: see [`Alignment::converged`].
    fn align(
        &self,
        source: &Self::Source,
        target: &Self::Target,
        initial: &Pose3,
    ) -> Result<Alignment, RegistrationError>;

    /// As [`Registrator::align`], with the correspondence reach and the robust kernel's scale
    /// of `reach` in place of the backend's configured ones (a tracker's adaptive reach; see
    /// [`Tracker`](crate::tracking::Tracker)). Everything else is as configured.
    ///
    /// # Errors
    /// As [`Registrator::align`], and [`RegistrationError::InvalidConfig`] for a `reach` that
    /// is not finite and positive.
    fn align_within(
        &self,
        source: &Self::Source,
        target: &Self::Target,
        initial: &Pose3,
        reach: &Reach,
    ) -> Result<Alignment, RegistrationError>;

    /// Registers a sweep whose points carry times (seconds since the sweep began, the cloud's
    /// `time` channel) and that was deskewed with a constant velocity that may be off, estimating
    /// its pose at time 0 together with the correction to that velocity: where a sensor shakes
    /// faster than its scans come, only a sweep's own points show how it moved during it.
    /// `initial` is the pose at time 0 to start from.
    ///
    /// `None`, the default, when the backend cannot (a caller then keeps its registration from
    /// [`Registrator::align`]).
    ///
    /// # Errors
    /// As [`Registrator::align`].
    fn align_sweep(
        &self,
        sweep: &PointCloud,
        target: &Self::Target,
        initial: &Pose3,
    ) -> Option<Result<SweepAlignment, RegistrationError>> {
        let _ = (sweep, target, initial);
        None
    }
}

/// A registrator that can build a target from prepared sources placed at poses: the local map of
/// the last keyframes (LiDAR odometry) or the neighbourhood of a loop-closure candidate. Sources
/// are prepared once per keyframe and reused, so the map is never re-extracted from raw clouds.
///
/// Every method is required: a wrapper around another backend (one that logs or counts its
/// calls) must forward each of them, or the compiler says which it forgot. With defaults, a
/// wrapper that forgot [`empty_map`](Self::empty_map) or [`add_to_map`](Self::add_to_map)
/// would compile, and the engine would silently rebuild its local map whole after each keyframe
/// instead of updating it in place. A backend that only builds maps whole implements
/// [`WholeMapRegistrator`] instead, which gives it this trait with the plain answers (a source
/// kept as it is, no voxel, no map updated in place).
pub trait MapRegistrator: Registrator {
    /// A target made of `parts`: each prepared source moved by its pose (`world_T_source`). The
    /// result is in the world frame.
    ///
    /// # Errors
    /// [`RegistrationError::TooFewPoints`] when the parts hold too little.
    fn target_from_sources(
        &self,
        parts: &[(&Self::Source, Pose3)],
    ) -> Result<Self::Target, RegistrationError>;

    /// Sets the backend up for its sensor, from the number of points (`points`, as the sensor
    /// gave them, before any thinning) of the first scan a caller registers with it: a backend
    /// whose map settings follow the scan's density (a sparse 16-beam scan affords a finer map
    /// than a dense 128-beam one) takes them from here. The engine calls it once, before its
    /// first keyframe; a backend with nothing to set does nothing.
    fn fit_to_scan(&mut self, points: usize);

    /// The voxel (metres) its maps are thinned to, when it thins them by voxel (after
    /// [`MapRegistrator::fit_to_scan`]; 0 when it keeps every point); `None` when it keeps its
    /// maps another way.
    fn map_voxel(&self) -> Option<f32>;

    /// The form in which a keyframe keeps a prepared source for the maps it will be part of: a
    /// backend may thin here what [`MapRegistrator::target_from_sources`] would thin anyway, so
    /// that each map rebuild touches fewer points. The result must still align as a source.
    /// Return `source` to keep it whole.
    fn keyframe_source(&self, source: Self::Source) -> Self::Source;

    /// The voxel (metres) [`Registrator::prepare_source`] thins a scan to, when that is all it
    /// does with the scan's layout: a caller may then hand it a scan already thinned to a finer
    /// voxel (the engine thins a dense scan once, to its map voxel, and deskews, registers and
    /// keeps that). `None` when the backend needs the scan as the sensor gave it (LOAM's
    /// features run along each ring in firing order).
    fn source_voxel(&self) -> Option<f32>;

    /// An empty map that parts can be added to ([`MapRegistrator::add_to_map`]) and removed from
    /// ([`MapRegistrator::remove_from_map`]) one at a time, so that a sliding window of keyframes
    /// is updated in place; or `None` when this backend builds maps only whole with
    /// [`MapRegistrator::target_from_sources`] (then a caller rebuilds the map instead).
    fn empty_map(&self) -> Option<Self::Target>;

    /// Adds `source` placed at `pose` (`world_T_source`) to `map`, a map from
    /// [`MapRegistrator::empty_map`], under `key`. A backend whose `empty_map` is `None` is
    /// never asked.
    fn add_to_map(&self, map: &mut Self::Target, key: u32, source: &Self::Source, pose: &Pose3);

    /// Removes from `map` what was added under `key`. A backend whose `empty_map` is `None` is
    /// never asked.
    fn remove_from_map(&self, map: &mut Self::Target, key: u32);

    /// Runs `beside` (the caller's own work, which does not touch `map`) while `map` is made
    /// ready for the next alignment, on another core where the backend can: a map updated in
    /// place is indexed again on its first query after a change, and a caller that knows an
    /// alignment comes next can hide that rebuild behind other work. Nothing a later alignment
    /// returns may change. A backend with nothing to prepare runs `beside` alone; a wrapper
    /// forwards it (required, as the others are, so that a wrapper cannot lose it unnoticed).
    fn ready_map_beside(&self, map: &mut Self::Target, beside: &mut (dyn FnMut() + Send));

    /// Starts making `map` ready for the next alignment on another thread and returns at once,
    /// where the backend can: a caller that has just changed its map in place and has other
    /// work before the next alignment (a keyframe's loop search, the next scan's thinning) hides
    /// the rebuild behind it; the next query or [`MapRegistrator::ready_map_beside`] waits for
    /// it if it has not finished. A change to `map` before then drops it. Nothing a later
    /// alignment returns may change. A backend with nothing to prepare does nothing; a wrapper
    /// forwards it.
    fn ready_map_ahead(&self, map: &mut Self::Target);

    /// A keyframe's source (as [`MapRegistrator::keyframe_source`] left it) as bytes, for an
    /// engine that keeps older keyframes in a file
    /// ([`GraphSlam::with_keyframe_store`](crate::GraphSlam::with_keyframe_store)); `None`
    /// keeps it in memory. [`MapRegistrator::restored_source`] must give back a source that
    /// aligns and maps exactly as this one.
    fn stored_source(&self, source: &Self::Source) -> Option<Vec<u8>>;

    /// The source [`MapRegistrator::stored_source`] wrote; `None` when `bytes` are not one.
    fn restored_source(&self, bytes: &[u8]) -> Option<Self::Source>;
}

/// A registrator that builds maps only whole: implementing this one method gives it
/// [`MapRegistrator`], with each source kept as it is, no [`source_voxel`](MapRegistrator::source_voxel)
/// and no map updated in place (a caller rebuilds the local map after each keyframe).
///
/// ```
/// # use slam_core::{Alignment, PointCloud, Pose3, Reach, RegistrationError, Registrator};
/// use slam_core::{MapRegistrator, WholeMapRegistrator};
///
/// /// A backend whose prepared clouds are plain point lists.
/// struct Points;
/// # impl Registrator for Points {
/// #     type Source = Vec<nalgebra::Point3<f64>>;
/// #     type Target = Vec<nalgebra::Point3<f64>>;
/// #     fn prepare_source(&self, c: &PointCloud) -> Result<Self::Source, RegistrationError> {
/// #         Ok(c.points().iter().map(|p| p.cast()).collect())
/// #     }
/// #     fn prepare_target(&self, c: &PointCloud) -> Result<Self::Target, RegistrationError> {
/// #         self.prepare_source(c)
/// #     }
/// #     fn align(&self, _: &Self::Source, _: &Self::Target, _: &Pose3)
/// #         -> Result<Alignment, RegistrationError> { unimplemented!() }
/// #     fn align_within(&self, _: &Self::Source, _: &Self::Target, _: &Pose3, _: &Reach)
/// #         -> Result<Alignment, RegistrationError> { unimplemented!() }
/// # }
///
/// impl WholeMapRegistrator for Points {
///     fn whole_map(
///         &self,
///         parts: &[(&Self::Source, Pose3)],
///     ) -> Result<Self::Target, RegistrationError> {
///         Ok(parts.iter().flat_map(|(s, pose)| s.iter().map(move |p| pose * p)).collect())
///     }
/// }
///
/// let map = Points.target_from_sources(&[(&vec![[1.0, 0.0, 0.0].into()], Pose3::identity())])?;
/// assert_eq!(map.len(), 1);
/// assert!(Points.empty_map().is_none());
/// # Ok::<(), RegistrationError>(())
/// ```
pub trait WholeMapRegistrator: Registrator {
    /// A target made of `parts`, as [`MapRegistrator::target_from_sources`] (which calls this).
    ///
    /// # Errors
    /// [`RegistrationError::TooFewPoints`] when the parts hold too little.
    fn whole_map(
        &self,
        parts: &[(&Self::Source, Pose3)],
    ) -> Result<Self::Target, RegistrationError>;

    /// As [`MapRegistrator::stored_source`]; by default `None`, the source kept in memory.
    fn stored_source(&self, source: &Self::Source) -> Option<Vec<u8>> {
        let _ = source;
        None
    }

    /// As [`MapRegistrator::restored_source`]; by default `None`.
    fn restored_source(&self, bytes: &[u8]) -> Option<Self::Source> {
        let _ = bytes;
        None
    }
}

impl<R: WholeMapRegistrator> MapRegistrator for R {
    fn target_from_sources(
        &self,
        parts: &[(&Self::Source, Pose3)],
    ) -> Result<Self::Target, RegistrationError> {
        self.whole_map(parts)
    }

    fn fit_to_scan(&mut self, _points: usize) {}

    fn map_voxel(&self) -> Option<f32> {
        None
    }

    fn keyframe_source(&self, source: Self::Source) -> Self::Source {
        source
    }

    fn source_voxel(&self) -> Option<f32> {
        None
    }

    fn empty_map(&self) -> Option<Self::Target> {
        None
    }

    fn add_to_map(
        &self,
        _map: &mut Self::Target,
        _key: u32,
        _source: &Self::Source,
        _pose: &Pose3,
    ) {
    }

    fn remove_from_map(&self, _map: &mut Self::Target, _key: u32) {}

    /// A map built whole is ready when built: `beside` alone.
    fn ready_map_beside(&self, _map: &mut Self::Target, beside: &mut (dyn FnMut() + Send)) {
        beside();
    }

    /// A map built whole is ready when built: nothing to do.
    fn ready_map_ahead(&self, _map: &mut Self::Target) {}

    fn stored_source(&self, source: &Self::Source) -> Option<Vec<u8>> {
        WholeMapRegistrator::stored_source(self, source)
    }

    fn restored_source(&self, bytes: &[u8]) -> Option<Self::Source> {
        WholeMapRegistrator::restored_source(self, bytes)
    }
}
