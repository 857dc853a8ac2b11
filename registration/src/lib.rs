//! # registration
//!
//! Point-cloud registration backends behind [`slam_core::Registrator`] and
//! [`slam_core::MapRegistrator`]:
//!
//! - [`PointToPointIcp`]: closed-form weighted SVD step per iteration (Besl & McKay 1992; Arun
//!   et al. 1987), each source point paired with the midpoint of its two nearest target points
//!   by default (textbook nearest-point pairs snap onto the target's sampling lattice).
//! - [`PointToPlaneIcp`]: Gauss-Newton on SE(3) against target normals from PCA (Chen & Medioni
//!   1992), with Huber or Tukey weights (thesis eq. 4.7).
//! - [`LoamFeatures`] + [`LoamRegistrator`]: LOAM (Zhang & Singh 2014, thesis section 4.1.1):
//!   edge and planar points picked per laser ring by roughness (eq. 4.3), the ring from the
//!   cloud's ring field or from a [`LidarLayout`]; edges matched to lines and planar points to
//!   planes fitted to their nearest target features, Tukey-weighted Gauss-Newton (eq. 4.7).
//!
//! Both ICP backends first align a quarter of the source points with plain nearest searches,
//! then all of them. ICP correspondences come from `kiddo`'s immutable k-d tree, built once per
//! target; LOAM's come
//! from a [`VoxelHashMap`] (exact k-nearest in hashed cells), which a sliding local map can be
//! updated in place. Both reuse a point's neighbours across iterations while the triangle
//! inequality proves them still nearest, so most iterations run no search. Every result
//! reports convergence, iterations, inliers, RMSE and the 6x6 information `J^T W J` with its
//! smallest-to-largest eigenvalue ratio, so a caller can weigh a pose-graph edge and notice a
//! degenerate scene (a single plane, a long featureless corridor).
//!
//! ```
//! use nalgebra::Point3;
//! use registration::{IcpConfig, PointToPlaneIcp};
//! use slam_core::{PointCloud, Registrator, pose3_from_xyz_rpy};
//!
//! // Three walls of a room corner, 5 cm apart on a grid.
//! let mut pts = Vec::new();
//! for i in 0..60 {
//!     for j in 0..60 {
//!         let (u, v) = (i as f32 * 0.05, j as f32 * 0.05);
//!         pts.extend([Point3::new(u, v, 0.0), Point3::new(u, 0.0, v), Point3::new(0.0, u, v)]);
//!     }
//! }
//! let target = PointCloud::from_points(pts);
//! let truth = pose3_from_xyz_rpy(0.05, -0.03, 0.02, 0.01, -0.02, 0.03);
//! let source = target.transformed(&truth.inverse());
//! // Synthetic points on a grid: keep them all (voxel centroids would sit off the corner planes).
//! let icp = PointToPlaneIcp { config: IcpConfig { source_voxel: 0.0, target_voxel: 0.0, ..IcpConfig::default() } };
//! let a = icp.align(&icp.prepare_source(&source)?, &icp.prepare_target(&target)?, &slam_core::Pose3::identity())?;
//! assert!((a.pose.translation.vector - truth.translation.vector).norm() < 1e-3);
//! # Ok::<(), slam_core::RegistrationError>(())
//! ```
//!
//! When not to use it: without a rough initial guess (more than about 1 m or 20 degrees off) ICP
//! and LOAM converge to the nearest local minimum; use a global registration first. LOAM needs a
//! spinning LiDAR's ring structure (a ring field, or clouds in the sensor frame with a known
//! layout); for other clouds use the ICP backends.

mod alignment_inputs;
mod alignment_report;
mod config;
mod icp;
mod icp_backend;
mod icp_target;
mod kernel;
mod lidar_layout;
mod loam;
mod loam_features;
mod loam_matching;
mod matcher;
mod neighbour_cache;
mod place_index;
mod point_to_plane;
mod point_to_point;
mod pool_awake;
mod scan_context;
mod sweep;
mod sym3;
mod target;
mod voxel_hash_map;
mod voxel_window;

pub use config::IcpConfig;
pub use kernel::IcpKernel;
pub use lidar_layout::LidarLayout;
pub use loam::{LoamConfig, LoamRegistrator, LoamTarget};
pub use loam_features::{LoamFeatureConfig, LoamFeatures};
pub use place_index::{
    PlaceCandidate, ScanContextIndex, ScanContextIndexConfig, ScanContextRecognizer,
};
pub use point_to_plane::PointToPlaneIcp;
pub use point_to_point::PointToPointIcp;
pub use scan_context::{SCAN_CONTEXT_RINGS, ScanContext, ScanContextConfig, ScanContextMatch};
pub use target::PreparedTarget;
pub use voxel_hash_map::VoxelHashMap;
