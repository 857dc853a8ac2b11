//! The ring layout of a spinning LiDAR, for clouds that carry no ring field.

use nalgebra::Point3;
use slam_core::RegistrationError;

use crate::config::check;

/// Rings evenly spread between two elevations: enough to recover a point's ring (laser) from its
/// vertical angle when the cloud has no ring field.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct LidarLayout {
    /// Number of rings (lasers).
    pub rings: u16,
    /// Elevation of the lowest ring, degrees.
    pub lowest_elevation_deg: f64,
    /// Elevation of the highest ring, degrees.
    pub highest_elevation_deg: f64,
}

impl LidarLayout {
    /// Velodyne VLP-16 (Spot's EAP payload): 16 rings from -15° to +15°, 2° apart.
    pub const VLP16: Self = Self {
        rings: 16,
        lowest_elevation_deg: -15.0,
        highest_elevation_deg: 15.0,
    };
    /// Velodyne HDL-32E: 32 rings from -30.67° to +10.67°, 1.33° apart.
    pub const HDL32E: Self = Self {
        rings: 32,
        lowest_elevation_deg: -30.67,
        highest_elevation_deg: 10.67,
    };
    /// Ouster OS1-128 (uniform beams): 128 rings over ±22.5°.
    pub const OS1_128: Self = Self {
        rings: 128,
        lowest_elevation_deg: -22.5,
        highest_elevation_deg: 22.5,
    };

    /// Whether the layout can assign rings (at least one ring, finite increasing elevations).
    #[must_use]
    pub fn is_valid(&self) -> bool {
        self.validate().is_ok()
    }

    /// Checks that the layout can assign rings: at least one ring, finite elevations, the
    /// highest above the lowest when there are several rings.
    ///
    /// # Errors
    /// [`RegistrationError::InvalidConfig`] naming the first bad field.
    pub fn validate(&self) -> Result<(), RegistrationError> {
        check(
            self.rings > 0,
            "LidarLayout::rings",
            self.rings.into(),
            "at least 1",
        )?;
        check(
            self.lowest_elevation_deg.is_finite(),
            "LidarLayout::lowest_elevation_deg",
            self.lowest_elevation_deg,
            "finite",
        )?;
        check(
            self.highest_elevation_deg.is_finite()
                && (self.rings == 1 || self.highest_elevation_deg > self.lowest_elevation_deg),
            "LidarLayout::highest_elevation_deg",
            self.highest_elevation_deg,
            "finite, and above lowest_elevation_deg when there are several rings",
        )
    }

    /// The ring of a point in the sensor frame: the nearest ring by elevation, or `None` for a
    /// non-finite point, the origin, or an elevation more than half a ring spacing outside the
    /// layout.
    #[must_use]
    pub fn ring_of(&self, p: &Point3<f32>) -> Option<u16> {
        let (x, y, z) = (f64::from(p.x), f64::from(p.y), f64::from(p.z));
        let horizontal = x.hypot(y);
        if !(horizontal.is_finite() && z.is_finite()) || (horizontal == 0.0 && z == 0.0) {
            return None;
        }
        if self.rings == 1 {
            return Some(0);
        }
        let elevation = z.atan2(horizontal).to_degrees();
        let spacing =
            (self.highest_elevation_deg - self.lowest_elevation_deg) / f64::from(self.rings - 1);
        let k = ((elevation - self.lowest_elevation_deg) / spacing).round();
        // In range by the check above, so the cast is exact.
        (k >= 0.0 && k < f64::from(self.rings)).then_some(k as u16)
    }
}

impl Default for LidarLayout {
    /// [`LidarLayout::VLP16`], Spot's LiDAR.
    fn default() -> Self {
        Self::VLP16
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rings_from_elevation() {
        let at = |deg: f64| {
            let (s, c) = deg.to_radians().sin_cos();
            Point3::new((10.0 * c) as f32, 0.0, (10.0 * s) as f32)
        };
        let l = LidarLayout::VLP16;
        assert_eq!(l.ring_of(&at(-15.0)), Some(0));
        assert_eq!(l.ring_of(&at(-13.2)), Some(1));
        assert_eq!(l.ring_of(&at(15.0)), Some(15));
        assert_eq!(l.ring_of(&at(16.5)), None);
        assert_eq!(l.ring_of(&at(-17.0)), None);
        assert_eq!(l.ring_of(&Point3::origin()), None);
        assert_eq!(l.ring_of(&Point3::new(f32::NAN, 0.0, 0.0)), None);
        let h = LidarLayout::HDL32E;
        assert_eq!(h.ring_of(&at(-30.67)), Some(0));
        assert_eq!(h.ring_of(&at(10.67)), Some(31));
        assert_eq!(h.ring_of(&at(-10.67)), Some(15));
    }
}
