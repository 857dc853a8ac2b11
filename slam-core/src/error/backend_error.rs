//! A third-party backend's own error inside one of ours.

use std::sync::Arc;

/// A third-party backend's own error, kept as the source of the `Backend` variants of
/// [`RegistrationError`](super::RegistrationError), [`OptimizeError`](super::OptimizeError),
/// [`PlanError`](super::PlanError) and [`PlaceRecognitionError`](super::PlaceRecognitionError).
///
/// It dereferences to the backend's error (`dyn Error + Send + Sync`), which is also what the
/// variant's [`source`](std::error::Error::source) returns, so a caller downcasts it to the
/// backend's type. It is shared, so the errors that hold it stay `Clone`; two are equal when they
/// are the same error (one a clone of the other), as errors of unknown types cannot be compared.
///
/// ```
/// use slam_core::BackendError;
/// let e = BackendError::new(std::io::Error::other("device lost"));
/// assert_eq!(e.to_string(), "device lost");
/// assert!(e.downcast_ref::<std::io::Error>().is_some());
/// assert_eq!(e.clone(), e);
/// assert_ne!(BackendError::new("device lost"), e);
/// ```
#[derive(Clone)]
pub struct BackendError(Arc<dyn std::error::Error + Send + Sync>);

impl BackendError {
    /// `error` (any error type, or a message) as a backend's error.
    pub fn new(error: impl Into<Box<dyn std::error::Error + Send + Sync>>) -> Self {
        Self(Arc::from(error.into()))
    }
}

// Deliberately not `std::error::Error` itself: thiserror then returns the backend's error (the
// target of this `Deref`) as the source, so it downcasts to the backend's type.
impl std::ops::Deref for BackendError {
    type Target = dyn std::error::Error + Send + Sync;

    fn deref(&self) -> &Self::Target {
        &*self.0
    }
}

impl std::fmt::Debug for BackendError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        std::fmt::Debug::fmt(&*self.0, f)
    }
}

impl std::fmt::Display for BackendError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        std::fmt::Display::fmt(&*self.0, f)
    }
}

impl PartialEq for BackendError {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

impl Eq for BackendError {}
