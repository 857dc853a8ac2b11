//! Settings of the ICP backends.

use crate::kernel::IcpKernel;

/// Settings of [`PointToPointIcp`](crate::PointToPointIcp) and
/// [`PointToPlaneIcp`](crate::PointToPlaneIcp). Lengths in metres, angles in radians.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IcpConfig {
    /// Voxel size of the source cloud (0 keeps every point).
    pub source_voxel: f32,
    /// Voxel size of the target cloud (0 keeps every point).
    pub target_voxel: f32,
    /// Correspondences farther apart than this are ignored.
    pub max_correspondence_distance: f64,
    /// Iteration cap.
    pub max_iterations: usize,
    /// Converged when an update moves less than this (metres, default 0.1 mm) ...
    pub translation_tolerance: f64,
    /// ... and turns less than this (radians, default 1e-4, 0.006°). Tighter settings only add
    /// iterations: on the HDL-32E pair 1e-5 m / 1e-6 rad takes 17 iterations to the same pose
    /// (within 0.01°) that these reach in 7.
    pub rotation_tolerance: f64,
    /// Neighbours for target normals (point-to-plane).
    pub normal_neighbours: usize,
    /// Robust weights of the residuals.
    pub kernel: IcpKernel,
    /// Fewer correspondences than this is an error.
    pub min_correspondences: usize,
}

impl Default for IcpConfig {
    fn default() -> Self {
        Self {
            source_voxel: 0.25,
            target_voxel: 0.25,
            max_correspondence_distance: 1.0,
            max_iterations: 50,
            translation_tolerance: 1e-4,
            rotation_tolerance: 1e-4,
            normal_neighbours: 10,
            kernel: IcpKernel::Huber { k: 0.1 },
            min_correspondences: 20,
        }
    }
}
