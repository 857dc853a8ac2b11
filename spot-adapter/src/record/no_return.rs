//! No-return points: what a LiDAR driver writes where a beam came back with nothing. Drivers
//! mark them as NaN, as exact zeros (Ouster, many Velodyne configurations), or as a point at a
//! few centimetres (the sensor's own housing). Left in, each keyframe puts an obstacle at the
//! sensor's own position and registration pairs them with one another. Every reader removes them
//! and counts them.

use nalgebra::Point3;
use slam_core::PointCloud;

/// Points removed from the clouds read so far, by cause.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DroppedPoints {
    /// A coordinate was NaN or infinite.
    pub non_finite: usize,
    /// The point was exactly at the origin or closer than the minimum range.
    pub no_return: usize,
}

impl DroppedPoints {
    /// Both counts of `other` added to these.
    pub fn add(&mut self, other: Self) {
        self.non_finite += other.non_finite;
        self.no_return += other.no_return;
    }
}

/// Which points count as returns.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct ReturnFilter {
    /// Points closer than this to the sensor (metres) are no-returns; usual value 0.1 m (the
    /// housing of a VLP-16 or an OS1 is about 0.05 m from its optical centre). Exact zeros are
    /// no-returns even when this is 0.
    pub min_range: f32,
}

impl Default for ReturnFilter {
    fn default() -> Self {
        Self { min_range: 0.1 }
    }
}

/// What [`ReturnFilter::classify`] says of one point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PointKind {
    /// A measured point.
    Return,
    /// A coordinate is not finite.
    NonFinite,
    /// At the origin or inside the minimum range.
    NoReturn,
}

impl ReturnFilter {
    /// Whether `p` is a return.
    #[must_use]
    pub fn classify(&self, p: &Point3<f32>) -> PointKind {
        if !p.iter().all(|v| v.is_finite()) {
            return PointKind::NonFinite;
        }
        let r2 = p.coords.norm_squared();
        if r2 == 0.0 || r2 < self.min_range * self.min_range {
            PointKind::NoReturn
        } else {
            PointKind::Return
        }
    }

    /// `cloud` with its non-finite and no-return points removed (channels follow), and how many
    /// of each there were. A cloud without any is returned unchanged (no copy).
    #[must_use]
    pub fn apply(&self, cloud: PointCloud) -> (PointCloud, DroppedPoints) {
        let mut dropped = DroppedPoints::default();
        for p in cloud.points() {
            match self.classify(p) {
                PointKind::Return => {}
                PointKind::NonFinite => dropped.non_finite += 1,
                PointKind::NoReturn => dropped.no_return += 1,
            }
        }
        if dropped == DroppedPoints::default() {
            return (cloud, dropped);
        }
        let kept = cloud.filtered(|_, p| self.classify(p) == PointKind::Return);
        (kept, dropped)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zeros_near_points_and_nans_are_counted_apart() {
        let cloud = PointCloud::from_points(vec![
            Point3::new(1.0, 0.0, 0.0),
            Point3::origin(),
            Point3::new(0.03, 0.0, 0.0),
            Point3::new(f32::NAN, 0.0, 0.0),
            Point3::new(0.0, 0.0, 20.0),
        ])
        .with_ring(vec![0, 1, 2, 3, 4])
        .unwrap();
        let (kept, dropped) = ReturnFilter::default().apply(cloud.clone());
        assert_eq!(
            dropped,
            DroppedPoints {
                non_finite: 1,
                no_return: 2
            }
        );
        assert_eq!(kept.ring(), Some(&[0, 4][..]));
        // With no minimum range only the exact zero is a no-return.
        let (kept, dropped) = ReturnFilter { min_range: 0.0 }.apply(cloud);
        assert_eq!((kept.len(), dropped.no_return), (3, 1));
    }
}
