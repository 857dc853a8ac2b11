//! File formats: point clouds (PCD, PLY, KITTI `.bin`) and trajectories (KITTI poses, TUM).
//!
//! Every reader parses from memory (`parse_*`) or from a path (`read_*`); every writer writes to
//! any `Write` (`write_*_to`) or to a path. Malformed input gives a [`FormatError`] with the line
//! or byte where it went wrong, never a panic.
//!
//! ```
//! use nalgebra::Point3;
//! use slam_core::PointCloud;
//! use slam_core::io::{PcdEncoding, parse_pcd, write_pcd_to};
//!
//! let cloud = PointCloud::from_points(vec![Point3::new(1.0, 2.0, 3.0), Point3::new(-0.5, 0.25, 8.0)])
//!     .with_ring(vec![3, 7])?;
//! let mut bytes = Vec::new();
//! write_pcd_to(&mut bytes, &cloud, PcdEncoding::Binary)?;
//! assert_eq!(parse_pcd(&bytes)?, cloud);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! [`FormatError`]: crate::FormatError

mod cloud_file;
mod kitti;
mod lzf;
mod pcd;
mod ply;
mod point_record;
mod reading;
mod scalar;
mod tum;

pub use cloud_file::read_cloud;
pub use kitti::{
    KITTI_ROTATION_TOLERANCE, parse_kitti_bin, parse_kitti_poses, read_kitti_bin, read_kitti_poses,
    write_kitti_bin, write_kitti_bin_to, write_kitti_poses, write_kitti_poses_to,
};
pub use pcd::{PcdEncoding, parse_pcd, read_pcd, write_pcd, write_pcd_to};
pub use ply::{PlyEncoding, parse_ply, read_ply, write_ply, write_ply_to};
pub use scalar::Scalar;
pub use tum::{
    StampedPose, TUM_HEADER, parse_tum, read_tum, write_tum, write_tum_line, write_tum_to,
};
