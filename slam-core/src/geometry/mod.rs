//! Rigid-body geometry: pose aliases, the SO(3)/SE(3)/SE(2) exponential and logarithm maps with
//! their Jacobians, quaternion conversions, pose interpolation and the least-squares rigid fit of
//! paired points.
//!
//! Tangent vectors of SE(3) are ordered `[rho; phi]` (translation part first, then rotation), as in
//! Barfoot's *State Estimation for Robotics* and Sophus; GTSAM orders them the other way round.
//! Perturbations are on the left: `T' = exp(delta) * T`.

mod pose;
mod rigid_fit;
mod se2;
mod se3;
mod so3;

pub use pose::{
    Pose2, Pose3, interpolate, pose3_from_xyz_rpy, pose3_is_finite, quaternion_from_wxyz,
    quaternion_from_xyzw, quaternion_to_wxyz, quaternion_to_xyzw,
};
pub use rigid_fit::{WeightedPair, fit_rigid_transform, fit_weighted_rigid_transform};
pub use se2::{se2_exp, se2_log, wrap_angle};
pub use se3::{se3_adjoint, se3_exp, se3_hat, se3_left_jacobian, se3_log, se3_vee};
pub use so3::{so3_exp, so3_hat, so3_left_jacobian, so3_left_jacobian_inverse, so3_log, so3_vee};

#[cfg(test)]
mod tests;
