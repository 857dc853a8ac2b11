//! # slam-core
//!
//! The shared foundation of spot-nav: rigid-body geometry (SE(3)/SE(2) with their exponential
//! maps and Jacobians, and the closed-form rigid fit of paired points, [`fit_rigid_transform`]),
//! [`PointCloud`] with voxel downsampling, the bit-packed occupancy
//! [`BitGrid`] shared by the map builder and the planners, the [`PoseGraph`] data type, file
//! formats ([`io`]: PCD, PLY, KITTI scans and poses, TUM trajectories), and the three traits that
//! the backends implement: [`Registrator`], [`Optimizer`] and [`Planner`].
//!
//! ```
//! use nalgebra::{Point3, Vector6};
//! use slam_core::{PointCloud, se3_exp, se3_log};
//!
//! // A pose from a twist and back.
//! let xi = Vector6::new(0.5, -0.2, 0.1, 0.05, -0.3, 1.2);
//! let pose = se3_exp(&xi);
//! assert!((se3_log(&pose) - xi).norm() < 1e-12);
//!
//! // Move a cloud by it and thin it to 10 cm voxels.
//! let cloud = PointCloud::from_points((0..1000).map(|i| Point3::new(i as f32 * 0.001, 0.0, 0.0)).collect());
//! let moved = cloud.transformed(&pose);
//! assert!((moved.centroid().unwrap() - pose * cloud.centroid().unwrap()).norm() < 1e-5);
//! let thinned = cloud.voxel_downsample(0.1)?;
//! assert_eq!(thinned.len(), 10);
//! # Ok::<(), slam_core::CloudError>(())
//! ```
//!
//! Conventions: ROS REP-103 frames (x forward, y left, z up), poses named `a_T_b` (mapping points
//! in b into a), metres, radians, seconds; f32 for stored points, f64 for poses and maths. SE(3)
//! tangents are `[rho; phi]` with left perturbations.
//!
//! When not to use it: for dense RGB-D or mesh processing, a general library (`Open3D`, `PCL`) has
//! far more; `slam-core` keeps only what the LiDAR SLAM and planning pipeline needs.

pub mod cloud;
pub mod error;
pub mod geometry;
pub mod grid;
pub mod io;
pub mod pose_graph;
pub mod robust_kernel;
pub mod slam;
mod test_data;
pub mod tracking;
pub mod traits;
mod voxel;

/// The linear algebra of every signature here (points, vectors, isometries), re-exported so
/// that users build against the same version: `slam_core::nalgebra::Point3`.
pub use nalgebra;

pub use cloud::{Aabb, PointCloud};
pub use error::{
    BackendError, CloudError, Degeneracy, FactorizationFailure, FormatError, GraphValue, GridError,
    InvalidSetting, OptimizeError, PlaceRecognitionError, PlanError, RegistrationError,
    RigidFitError,
};
pub use geometry::*;
pub use grid::{BitGrid, Cell, GridGeometry, MAX_GRID_CELLS};
pub use pose_graph::{Edge, GraphPose, Node, PoseGraph};
pub use robust_kernel::RobustKernel;
pub use slam::{
    EdgeInformation, GraphSlam, GraphSlamConfig, KeyframeCloudError, LoopOutcome, LoopRejection,
    LoopRejections, ScanInput, ScanOutcome, SkipReason, SlamReport, SweepPath, TurnPrediction,
    deskew, level_on_gravity,
};
pub use traits::optimizer::{
    IncrementalOptimizer, IncrementalReport, OptimizationReport, Optimizer, StopReason,
};
pub use traits::place_recognizer::{PlaceMatch, PlaceRecognizer};
pub use traits::planner::{GridPath, Planner, validate_endpoints};
pub use traits::registrator::{
    Alignment, MapRegistrator, Reach, Registrator, SweepAlignment, WholeMapRegistrator,
};
pub use voxel::pack_voxel_key;
