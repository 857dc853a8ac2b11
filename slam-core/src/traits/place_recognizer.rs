//! The place-recognition trait: keyframe scans in, look-alike keyframes out, so that the
//! Graph-SLAM engine can seek a loop where the robot has been, whatever its drift.

use crate::cloud::PointCloud;
use crate::error::PlaceRecognitionError;

/// A keyframe that looks like a query scan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaceMatch {
    /// The keyframe's index, as given to [`PlaceRecognizer::add_keyframe`].
    pub keyframe: usize,
    /// The query sensor's heading in the keyframe sensor's frame (radians, about the vertical):
    /// the start of the geometric check.
    pub yaw: f64,
    /// The descriptor's distance (smaller is more alike; its scale is the recognizer's).
    pub distance: f64,
}

/// Recognises places from single scans, independently of the pose estimate.
pub trait PlaceRecognizer {
    /// Remember keyframe `keyframe`'s scan (points in the sensor frame, z up).
    ///
    /// # Errors
    /// The recognizer's reason for refusing the scan (too few points in range, index full).
    fn add_keyframe(
        &mut self,
        keyframe: usize,
        scan: &PointCloud,
    ) -> Result<(), PlaceRecognitionError>;

    /// Remembered keyframes that look like `scan`, best first. The recognizer leaves out the
    /// most recent keyframes (the robot's own trail, not a revisit).
    ///
    /// # Errors
    /// The recognizer's reason for refusing the scan.
    fn candidates(&self, scan: &PointCloud) -> Result<Vec<PlaceMatch>, PlaceRecognitionError>;

    /// [`PlaceRecognizer::candidates`] for keyframe `keyframe`'s scan, then
    /// [`PlaceRecognizer::add_keyframe`]: what the engine calls for each new keyframe (a
    /// recognizer may describe the scan once for both).
    ///
    /// # Errors
    /// As either; the scan is not added when the query fails.
    fn candidates_then_add(
        &mut self,
        keyframe: usize,
        scan: &PointCloud,
    ) -> Result<Vec<PlaceMatch>, PlaceRecognitionError> {
        let found = self.candidates(scan)?;
        self.add_keyframe(keyframe, scan)?;
        Ok(found)
    }
}
