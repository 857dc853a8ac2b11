//! How far a scan reaches: the range at which a rotation error is turned into a displacement.

use crate::cloud::PointCloud;

/// A robust extent of `cloud` (metres from the sensor): the 90th percentile of the ranges of an
/// evenly spread sample of at most 1,024 points, so a few far returns do not set it; 0 for an
/// empty cloud.
///
/// ```
/// use nalgebra::Point3;
/// use slam_core::PointCloud;
/// use slam_core::tracking::scan_extent;
///
/// let points = (1..=100).map(|i| Point3::new(i as f32 * 0.1, 0.0, 0.0)).collect();
/// let extent = scan_extent(&PointCloud::from_points(points));
/// assert!((extent - 9.1).abs() < 1e-3);
/// ```
#[must_use]
pub fn scan_extent(cloud: &PointCloud) -> f64 {
    let points = cloud.points();
    let step = points.len().div_ceil(1024).max(1);
    let mut ranges: Vec<f32> = points
        .iter()
        .step_by(step)
        .map(|p| p.coords.norm())
        .filter(|r| r.is_finite())
        .collect();
    if ranges.is_empty() {
        return 0.0;
    }
    let rank = (ranges.len() * 9 / 10).min(ranges.len() - 1);
    let (_, r, _) = ranges.select_nth_unstable_by(rank, f32::total_cmp);
    f64::from(*r)
}
