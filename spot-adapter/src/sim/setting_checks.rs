//! Checks shared by the simulator's settings: each finds the first bad setting of a list and
//! names it in an [`SimError::InvalidConfig`].

use crate::sim::SimError;

/// The first of `settings` (name, value, what is expected with its unit) that is not finite and
/// positive, as an error.
pub(crate) fn require_positive(
    settings: &[(&'static str, f64, &'static str)],
) -> Result<(), SimError> {
    match settings
        .iter()
        .find(|(_, v, _)| !(v.is_finite() && *v > 0.0))
    {
        Some(&(setting, value, expected)) => Err(SimError::invalid(setting, value, expected)),
        None => Ok(()),
    }
}

/// The first of `settings` (name, value) that is negative or not finite, as an error.
pub(crate) fn require_non_negative(settings: &[(&'static str, f64)]) -> Result<(), SimError> {
    match settings.iter().find(|(_, v)| !(v.is_finite() && *v >= 0.0)) {
        Some(&(setting, value)) => {
            Err(SimError::invalid(setting, value, "finite and non-negative"))
        }
        None => Ok(()),
    }
}
