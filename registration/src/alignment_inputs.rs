//! The checks every alignment starts with, before it searches anything.

use slam_core::{Pose3, RegistrationError, pose3_is_finite};

use crate::config::IcpConfig;
use crate::target::{PreparedTarget, TargetIndex};

/// `validated` (the configuration's own check), then a finite `initial` guess, in that order
/// (a caller sees the first that fails).
pub(crate) fn check_alignment_inputs<E: Into<RegistrationError>>(
    validated: Result<(), E>,
    initial: &Pose3,
) -> Result<(), RegistrationError> {
    validated.map_err(Into::into)?;
    if !pose3_is_finite(initial) {
        return Err(RegistrationError::NonFiniteInitialGuess);
    }
    Ok(())
}

/// An ICP alignment's checks ([`check_alignment_inputs`] of `config`), then `target`'s index.
pub(crate) fn checked_target_index<'t>(
    config: &IcpConfig,
    target: &'t PreparedTarget,
    initial: &Pose3,
) -> Result<&'t TargetIndex, RegistrationError> {
    check_alignment_inputs(config.validate(), initial)?;
    target.index()
}
