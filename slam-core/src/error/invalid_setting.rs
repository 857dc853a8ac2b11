//! A setting out of its valid range: the one error type every crate reports bad settings with.

use thiserror::Error;

/// A setting or an argument is out of its valid range: which one, the value given and the range
/// in words. Every crate of the workspace reports bad settings with it (through its own error's
/// `InvalidConfig` variant where it has one), so a caller matches one type.
///
/// ```
/// use slam_core::{GraphSlamConfig, InvalidSetting};
/// let bad = GraphSlamConfig { keyframe_distance: -1.0, ..GraphSlamConfig::default() };
/// let InvalidSetting { setting, value, .. } = bad.validate().unwrap_err();
/// assert_eq!((setting, value), ("GraphSlamConfig::keyframe_distance", -1.0));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Error)]
#[error("{setting} = {value}: must be {expected}")]
pub struct InvalidSetting {
    /// The setting, as `Type::field` (`Type::function argument` for an argument).
    pub setting: &'static str,
    /// The value given (counts and integers converted).
    pub value: f64,
    /// The valid range, in words.
    pub expected: &'static str,
}

impl InvalidSetting {
    /// `Ok` when `ok`, else the error for `setting` at `value`.
    ///
    /// # Errors
    /// [`InvalidSetting`] unless `ok`.
    pub fn check(
        ok: bool,
        setting: &'static str,
        value: f64,
        expected: &'static str,
    ) -> Result<(), Self> {
        if ok {
            Ok(())
        } else {
            Err(Self {
                setting,
                value,
                expected,
            })
        }
    }

    /// [`InvalidSetting::check`] for an `f32` setting, whose value the error gives as written
    /// (`-0.1`, not the `-0.10000000149011612` of its exact `f64` conversion).
    ///
    /// # Errors
    /// [`InvalidSetting`] unless `ok`.
    pub fn check_f32(
        ok: bool,
        setting: &'static str,
        value: f32,
        expected: &'static str,
    ) -> Result<(), Self> {
        if ok {
            return Ok(());
        }
        // The shortest decimal that reads back as the f32 ("NaN" and "inf" included).
        let value = value.to_string().parse().unwrap_or(f64::from(value));
        Self::check(false, setting, value, expected)
    }

    /// The error for the first of `settings` (name, value) that is not finite and not negative
    /// (distances, angles, tolerances).
    ///
    /// ```
    /// use slam_core::InvalidSetting;
    /// assert!(InvalidSetting::check_non_negative(&[("A::a", 0.0), ("A::b", 2.0)]).is_ok());
    /// let err = InvalidSetting::check_non_negative(&[("A::a", 1.0), ("A::b", f64::NAN)]);
    /// assert_eq!(err.unwrap_err().setting, "A::b");
    /// ```
    ///
    /// # Errors
    /// [`InvalidSetting`] for the first setting out of range.
    pub fn check_non_negative(settings: &[(&'static str, f64)]) -> Result<(), Self> {
        for &(setting, v) in settings {
            Self::check(
                v.is_finite() && v >= 0.0,
                setting,
                v,
                "finite and not negative",
            )?;
        }
        Ok(())
    }
}
