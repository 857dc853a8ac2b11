//! The error of the evaluation against ground truth.

use thiserror::Error;

/// Why two trajectories cannot be compared.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum EvalError {
    /// Two trajectories cannot be aligned (a non-finite position).
    #[error("the trajectories cannot be aligned")]
    Alignment(#[source] slam_core::RigidFitError),
    /// Two trajectories to compare have too few poses in common.
    #[error("{found} associated poses, at least {required} are needed")]
    TooFewPoses {
        /// Pairs found.
        found: usize,
        /// Pairs needed.
        required: usize,
    },
}
