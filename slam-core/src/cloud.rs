//! `PointCloud`: f32 positions with optional per-point ring, intensity and time channels.

use nalgebra::{Isometry3, Point3, Vector3};

use crate::error::CloudError;

/// Axis-aligned bounds of a cloud.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Aabb {
    /// Smallest x, y, z.
    pub min: Point3<f32>,
    /// Largest x, y, z.
    pub max: Point3<f32>,
}

impl Aabb {
    /// Size along each axis.
    #[must_use]
    pub fn extent(&self) -> Vector3<f32> {
        self.max - self.min
    }
}

/// A point cloud in one frame. Positions are f32 metres; the optional channels have one value per
/// point when present:
/// - `ring`: laser (beam) index of a spinning LiDAR, zero-based;
/// - `intensity`: return strength as the sensor reports it;
/// - `time`: seconds since the start of the sweep (for deskewing).
///
/// ```
/// use nalgebra::Point3;
/// use slam_core::PointCloud;
/// let mut cloud = PointCloud::from_points(vec![
///     Point3::new(1.0, 0.0, 0.0),
///     Point3::new(f32::NAN, 0.0, 0.0),
///     Point3::new(0.0, 5.0, 0.0),
/// ]);
/// assert_eq!(cloud.remove_non_finite(), 1);
/// assert_eq!(cloud.crop_range(0.5, 2.0).len(), 1);
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PointCloud {
    points: Vec<Point3<f32>>,
    ring: Option<Vec<u16>>,
    intensity: Option<Vec<f32>>,
    time: Option<Vec<f32>>,
}

impl PointCloud {
    /// An empty cloud with no channels.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// A cloud of the given positions with no channels.
    #[must_use]
    pub fn from_points(points: Vec<Point3<f32>>) -> Self {
        Self {
            points,
            ..Self::default()
        }
    }

    fn check_len(&self, channel: &'static str, got: usize) -> Result<(), CloudError> {
        if got == self.points.len() {
            Ok(())
        } else {
            Err(CloudError::ChannelLength {
                channel,
                expected: self.points.len(),
                got,
            })
        }
    }

    /// Attach a ring channel (one value per point).
    ///
    /// # Errors
    /// [`CloudError::ChannelLength`] when the length differs from the point count.
    pub fn with_ring(mut self, ring: Vec<u16>) -> Result<Self, CloudError> {
        self.check_len("ring", ring.len())?;
        self.ring = Some(ring);
        Ok(self)
    }

    /// Attach an intensity channel (one value per point).
    ///
    /// # Errors
    /// [`CloudError::ChannelLength`] when the length differs from the point count.
    pub fn with_intensity(mut self, intensity: Vec<f32>) -> Result<Self, CloudError> {
        self.check_len("intensity", intensity.len())?;
        self.intensity = Some(intensity);
        Ok(self)
    }

    /// Attach a per-point time channel (seconds since the sweep's start).
    ///
    /// # Errors
    /// [`CloudError::ChannelLength`] when the length differs from the point count.
    pub fn with_time(mut self, time: Vec<f32>) -> Result<Self, CloudError> {
        self.check_len("time", time.len())?;
        self.time = Some(time);
        Ok(self)
    }

    /// Number of points.
    #[must_use]
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the cloud has no points.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Positions (metres).
    #[must_use]
    pub fn points(&self) -> &[Point3<f32>] {
        &self.points
    }

    /// Mutable positions (the count cannot change through this).
    pub fn points_mut(&mut self) -> &mut [Point3<f32>] {
        &mut self.points
    }

    /// Ring channel, if present.
    #[must_use]
    pub fn ring(&self) -> Option<&[u16]> {
        self.ring.as_deref()
    }

    /// Intensity channel, if present.
    #[must_use]
    pub fn intensity(&self) -> Option<&[f32]> {
        self.intensity.as_deref()
    }

    /// Time channel, if present.
    #[must_use]
    pub fn time(&self) -> Option<&[f32]> {
        self.time.as_deref()
    }

    /// Split into positions and channels (ring, intensity, time).
    #[must_use]
    #[allow(clippy::type_complexity)]
    pub fn into_parts(
        self,
    ) -> (
        Vec<Point3<f32>>,
        Option<Vec<u16>>,
        Option<Vec<f32>>,
        Option<Vec<f32>>,
    ) {
        (self.points, self.ring, self.intensity, self.time)
    }

    /// The cloud with its positions and intensities only (the ring and time channels dropped).
    #[must_use]
    pub fn without_ring_and_time(self) -> Self {
        Self {
            ring: None,
            time: None,
            ..self
        }
    }

    /// The cloud with every point mapped by `a_T_b` (this cloud is in frame b; the result in a).
    #[must_use]
    pub fn transformed(&self, a_t_b: &Isometry3<f64>) -> Self {
        let mut out = self.clone();
        out.transform_in_place(a_t_b);
        out
    }

    /// Map every point by `a_T_b` in place.
    pub fn transform_in_place(&mut self, a_t_b: &Isometry3<f64>) {
        let t: Isometry3<f32> = nalgebra::convert(*a_t_b);
        for p in &mut self.points {
            *p = t * *p;
        }
    }

    /// Append `other`'s points. Both clouds must carry the same channels, so that no value is
    /// dropped or invented.
    ///
    /// # Errors
    /// [`CloudError::ChannelMismatch`] when one cloud has a channel the other lacks (an empty
    /// cloud takes the other's channels).
    pub fn extend_from(&mut self, other: &PointCloud) -> Result<(), CloudError> {
        if other.is_empty() {
            return Ok(());
        }
        if self.is_empty() {
            *self = other.clone();
            return Ok(());
        }
        if self.ring.is_some() != other.ring.is_some() {
            return Err(CloudError::ChannelMismatch { channel: "ring" });
        }
        if self.intensity.is_some() != other.intensity.is_some() {
            return Err(CloudError::ChannelMismatch {
                channel: "intensity",
            });
        }
        if self.time.is_some() != other.time.is_some() {
            return Err(CloudError::ChannelMismatch { channel: "time" });
        }
        self.points.extend_from_slice(&other.points);
        if let (Some(a), Some(b)) = (&mut self.ring, &other.ring) {
            a.extend_from_slice(b);
        }
        if let (Some(a), Some(b)) = (&mut self.intensity, &other.intensity) {
            a.extend_from_slice(b);
        }
        if let (Some(a), Some(b)) = (&mut self.time, &other.time) {
            a.extend_from_slice(b);
        }
        Ok(())
    }

    /// The points (with their channels) for which `keep(index, point)` is true.
    #[must_use]
    pub fn filtered(&self, mut keep: impl FnMut(usize, &Point3<f32>) -> bool) -> Self {
        let idx: Vec<usize> = self
            .points
            .iter()
            .enumerate()
            .filter(|(i, p)| keep(*i, p))
            .map(|(i, _)| i)
            .collect();
        self.select(&idx)
    }

    /// The points at `indices`, in that order, with their channels.
    ///
    /// # Panics
    /// If an index is out of range.
    #[must_use]
    pub fn select(&self, indices: &[usize]) -> Self {
        Self {
            points: indices.iter().map(|&i| self.points[i]).collect(),
            ring: self
                .ring
                .as_ref()
                .map(|v| indices.iter().map(|&i| v[i]).collect()),
            intensity: self
                .intensity
                .as_ref()
                .map(|v| indices.iter().map(|&i| v[i]).collect()),
            time: self
                .time
                .as_ref()
                .map(|v| indices.iter().map(|&i| v[i]).collect()),
        }
    }

    /// Points whose distance from the origin lies in `[min_range, max_range]` metres.
    #[must_use]
    pub fn crop_range(&self, min_range: f32, max_range: f32) -> Self {
        let (lo, hi) = (min_range * min_range, max_range * max_range);
        self.filtered(|_, p| {
            let r2 = p.coords.norm_squared();
            r2 >= lo && r2 <= hi
        })
    }

    /// Points inside the box (inclusive).
    #[must_use]
    pub fn crop_box(&self, bounds: &Aabb) -> Self {
        self.filtered(|_, p| (0..3).all(|k| p[k] >= bounds.min[k] && p[k] <= bounds.max[k]))
    }

    /// Drop every point with a non-finite coordinate; returns how many were dropped.
    pub fn remove_non_finite(&mut self) -> usize {
        let before = self.len();
        if self.points.iter().all(|p| p.iter().all(|v| v.is_finite())) {
            return 0;
        }
        *self = self.filtered(|_, p| p.iter().all(|v| v.is_finite()));
        before - self.len()
    }

    /// Axis-aligned bounds of the finite points, `None` when there are none.
    #[must_use]
    pub fn bounds(&self) -> Option<Aabb> {
        let mut it = self
            .points
            .iter()
            .filter(|p| p.iter().all(|v| v.is_finite()));
        let first = *it.next()?;
        let (mut min, mut max) = (first, first);
        for p in it {
            for k in 0..3 {
                min[k] = min[k].min(p[k]);
                max[k] = max[k].max(p[k]);
            }
        }
        Some(Aabb { min, max })
    }

    /// Centroid of the points (f64), `None` for an empty cloud.
    #[must_use]
    pub fn centroid(&self) -> Option<Point3<f64>> {
        if self.is_empty() {
            return None;
        }
        let sum = self.points.iter().fold(Vector3::<f64>::zeros(), |acc, p| {
            acc + nalgebra::convert::<_, Vector3<f64>>(p.coords)
        });
        Some(Point3::from(sum / self.len() as f64))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    fn cloud() -> PointCloud {
        PointCloud::from_points(vec![
            Point3::new(1.0, 2.0, 3.0),
            Point3::new(-1.0, 0.5, 0.0),
            Point3::new(f32::INFINITY, 0.0, 0.0),
            Point3::new(10.0, 0.0, 0.0),
        ])
        .with_ring(vec![0, 1, 2, 3])
        .unwrap()
        .with_intensity(vec![0.1, 0.2, 0.3, 0.4])
        .unwrap()
    }

    #[test]
    fn without_ring_and_time_keeps_positions_and_intensities() {
        let c = cloud().with_time(vec![0.0, 0.1, 0.2, 0.3]).unwrap();
        let kept = c.clone().without_ring_and_time();
        assert_eq!(kept.points(), c.points());
        assert_eq!(kept.intensity(), c.intensity());
        assert_eq!((kept.ring(), kept.time()), (None, None));
    }

    #[test]
    fn channels_follow_points() {
        let mut c = cloud();
        assert_eq!(c.remove_non_finite(), 1);
        assert_eq!(c.ring(), Some(&[0, 1, 3][..]));
        let near = c.crop_range(0.0, 5.0);
        assert_eq!(near.len(), 2);
        assert_eq!(near.intensity(), Some(&[0.1, 0.2][..]));
        let b = c.bounds().unwrap();
        assert_eq!(b.min, Point3::new(-1.0, 0.0, 0.0));
        assert_eq!(b.max, Point3::new(10.0, 2.0, 3.0));
    }

    #[test]
    fn channel_length_and_mismatch_are_errors() {
        let c = PointCloud::from_points(vec![Point3::origin(); 3]);
        assert!(matches!(
            c.clone().with_ring(vec![1]),
            Err(CloudError::ChannelLength { .. })
        ));
        let mut a = cloud();
        assert!(matches!(
            a.extend_from(&c),
            Err(CloudError::ChannelMismatch { .. })
        ));
        let n = a.len();
        a.extend_from(&cloud()).unwrap();
        assert_eq!(a.len(), 2 * n);
        assert_eq!(a.ring().unwrap().len(), 2 * n);
    }

    #[test]
    fn transform_matches_isometry() {
        let t = Isometry3::from_parts(
            Translation3::new(1.0, -2.0, 0.5),
            UnitQuaternion::from_euler_angles(0.1, -0.2, 0.3),
        );
        let c = cloud();
        let moved = c.transformed(&t);
        for (p, q) in c.points().iter().zip(moved.points()) {
            if !p.iter().all(|v| v.is_finite()) {
                continue;
            }
            let expect = t * nalgebra::convert::<_, Point3<f64>>(*p);
            assert!((nalgebra::convert::<_, Point3<f64>>(*q) - expect).norm() < 1e-5);
        }
    }
}
