//! Settings of the ICP backends.

use slam_core::RegistrationError;

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
    /// Point-to-point: each source point pairs with the mean of its this many nearest target
    /// points (at most 16). 1 is textbook ICP, whose pairs pull the source onto the target's
    /// sampling lattice: two random halves of a real HDL-32E scan, one moved by a known
    /// transform, end 0.11-0.14° off with it (one azimuth step of that LiDAR is 0.16°), and
    /// 0.01-0.04° off with the default 2, which pairs a point with the midpoint of two target
    /// samples (3 splits x 3 transforms x 4 voxel settings). A source point with fewer target
    /// points within reach is left out. Point-to-plane always pairs with the nearest point and
    /// its normal.
    pub pair_target_points: usize,
    /// Coarse stage: every `coarse_stride`-th source point aligns first, with one plain
    /// nearest-neighbour search per point and iteration, until an update moves less than 1 cm
    /// and turns less than 0.1 degrees; then every point refines with neighbours reused across
    /// iterations. 1 skips the stage. Default 4: on the HDL-32E pair the alignment then runs
    /// 6,200 single-nearest and 6,200 four-nearest searches where it ran 13,700 four-nearest
    /// ones, and ends 0.006° and 0.05 mm from the pose it reaches without the stage
    /// (point-to-point: 0.004° and 0.6 mm).
    pub coarse_stride: usize,
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
            pair_target_points: 2,
            coarse_stride: 4,
        }
    }
}

impl IcpConfig {
    /// Checks every setting: voxels finite and not negative; reach, kernel threshold and
    /// tolerances finite and positive (tolerances may be 0); at least one iteration, 3 normal
    /// neighbours, one correspondence; `pair_target_points` 1 to 16; `coarse_stride` at least 1.
    /// Preparation and alignment call it, so a bad setting is an error, not a silent change.
    ///
    /// # Errors
    /// [`RegistrationError::InvalidConfig`] naming the first bad setting.
    pub fn validate(&self) -> Result<(), RegistrationError> {
        let bad = |what: &str| Err(RegistrationError::InvalidConfig(format!("ICP: {what}")));
        let voxel_ok = |v: f32| v.is_finite() && v >= 0.0;
        if !(voxel_ok(self.source_voxel) && voxel_ok(self.target_voxel)) {
            return bad("voxel sizes must be finite and not negative");
        }
        if !(self.max_correspondence_distance.is_finite() && self.max_correspondence_distance > 0.0)
        {
            return bad("max_correspondence_distance must be finite and positive");
        }
        let tolerance_ok = |v: f64| v.is_finite() && v >= 0.0;
        if !(tolerance_ok(self.translation_tolerance) && tolerance_ok(self.rotation_tolerance)) {
            return bad("tolerances must be finite and not negative");
        }
        if let IcpKernel::Huber { k } | IcpKernel::Tukey { k } = self.kernel
            && !(k.is_finite() && k > 0.0)
        {
            return bad("kernel threshold must be finite and positive");
        }
        if self.max_iterations == 0 || self.min_correspondences == 0 {
            return bad("max_iterations and min_correspondences must be at least 1");
        }
        if self.normal_neighbours < 3 {
            return bad("normal_neighbours must be at least 3");
        }
        if !(1..=16).contains(&self.pair_target_points) {
            return bad("pair_target_points must be 1 to 16");
        }
        if self.coarse_stride == 0 {
            return bad("coarse_stride must be at least 1 (1 skips the coarse stage)");
        }
        Ok(())
    }
}
