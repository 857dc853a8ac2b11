//! Scan Context (Kim & Kim, IROS 2018): a place descriptor of one LiDAR scan that does not
//! depend on the sensor's heading. The plane around the sensor is cut into rings (range) and
//! sectors (azimuth); each bin keeps the highest point in it. A turn of the sensor only shifts
//! the sectors, so comparing two scans means finding the column shift that makes them agree,
//! and that shift is the heading between them.

use slam_core::{InvalidSetting, PlaceRecognitionError, PointCloud};

/// Rings of a [`ScanContext`] (range bins): fixed, because the ring key indexes a k-d tree of
/// this dimension. 20 as in the paper.
pub const SCAN_CONTEXT_RINGS: usize = 20;

/// Settings of [`ScanContext`]. Lengths in metres.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct ScanContextConfig {
    /// Azimuth bins, 60 (6 degrees each, as in the paper); the heading comes out to half of that.
    pub sectors: usize,
    /// Points farther than this (horizontally) are left out, 20 m: a building's rooms and
    /// corridors (the paper's 80 m suits streets).
    pub max_range: f64,
    /// Points closer than this are left out (the robot's own body, no-returns), 0.5 m.
    pub min_range: f64,
    /// Added to each point's height in the scan's frame so that the floor counts as a positive
    /// height, 2 m (a sensor mounted less than 2 m above the floor).
    pub height_offset: f64,
    /// Every this many points of the cloud are described, 4: a VLP-16 ring keeps a point every
    /// 0.8 degrees, still several per 6-degree sector, for a quarter of the work. 1 takes all.
    pub point_stride: usize,
}

impl Default for ScanContextConfig {
    fn default() -> Self {
        Self {
            sectors: 60,
            max_range: 20.0,
            min_range: 0.5,
            height_offset: 2.0,
            point_stride: 4,
        }
    }
}

impl ScanContextConfig {
    /// At least 4 sectors, ranges finite with `0 <= min_range < max_range`, a finite offset.
    ///
    /// # Errors
    /// [`PlaceRecognitionError::InvalidConfig`] naming the first bad setting.
    pub fn validate(&self) -> Result<(), PlaceRecognitionError> {
        let invalid = |setting, value, expected| {
            PlaceRecognitionError::from(InvalidSetting {
                setting,
                value,
                expected,
            })
        };
        if !(4..=3600).contains(&self.sectors) {
            return Err(invalid(
                "ScanContextConfig::sectors",
                self.sectors as f64,
                "between 4 and 3600",
            ));
        }
        if !(self.min_range.is_finite() && self.min_range >= 0.0) {
            return Err(invalid(
                "ScanContextConfig::min_range",
                self.min_range,
                "finite and at least 0",
            ));
        }
        if !(self.max_range.is_finite() && self.max_range > self.min_range) {
            return Err(invalid(
                "ScanContextConfig::max_range",
                self.max_range,
                "finite and above min_range",
            ));
        }
        if self.point_stride == 0 {
            return Err(invalid(
                "ScanContextConfig::point_stride",
                0.0,
                "at least 1",
            ));
        }
        if !self.height_offset.is_finite() {
            return Err(invalid(
                "ScanContextConfig::height_offset",
                self.height_offset,
                "finite",
            ));
        }
        Ok(())
    }
}

/// The descriptor of one scan: rings x sectors of highest heights (0 where a bin is empty),
/// and its ring key (each ring's mean), which a turn of the sensor leaves unchanged.
#[derive(Clone, Debug, PartialEq)]
pub struct ScanContext {
    sectors: usize,
    /// Row-major: ring r, sector s at `r * sectors + s`.
    bins: Vec<f32>,
    /// Each column (sector) scaled to unit length, zero for an empty one, stored row-major
    /// like `bins`: a comparison correlates each ring's row with the other scan's at every
    /// shift, which reads contiguous slices.
    unit_rows: Vec<f32>,
    /// 1 for a sector with any height in it, 0 for an empty one.
    seen: Vec<f32>,
    ring_key: [f32; SCAN_CONTEXT_RINGS],
}

/// How well two descriptors agree at their best heading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScanContextMatch {
    /// Mean cosine distance between the columns both scans see, 0 (same) to 1.
    pub distance: f64,
    /// The heading of the query scan in the candidate's frame (radians, in (-pi, pi]): rotate
    /// the query by it about the vertical and it lines up with the candidate. Good to half a
    /// sector.
    pub yaw: f64,
}

impl ScanContext {
    /// The descriptor of `cloud`, its points in a frame whose z axis points up (the LiDAR's
    /// own frame on a level robot). Non-finite points and points outside the ranges are left
    /// out.
    ///
    /// # Errors
    /// [`PlaceRecognitionError::InvalidConfig`] for invalid settings;
    /// [`PlaceRecognitionError::TooFewPoints`] when no point falls within the ranges.
    pub fn from_cloud(
        cloud: &PointCloud,
        config: &ScanContextConfig,
    ) -> Result<Self, PlaceRecognitionError> {
        Self::seen_from(cloud, config, 0.0, 0.0)
    }

    /// The descriptor of `cloud` as a sensor at `(x, y)` of the cloud's frame, with the same
    /// heading, would see it (the points are not copied).
    ///
    /// # Errors
    /// As [`ScanContext::from_cloud`].
    pub fn seen_from(
        cloud: &PointCloud,
        config: &ScanContextConfig,
        x: f32,
        y: f32,
    ) -> Result<Self, PlaceRecognitionError> {
        config.validate()?;
        let sectors = config.sectors;
        let mut bins = vec![0.0f32; SCAN_CONTEXT_RINGS * sectors];
        // f32 throughout: the points are f32, and bins are metres and degrees wide.
        let (min_range, max_range, offset) = (
            config.min_range as f32,
            config.max_range as f32,
            config.height_offset as f32,
        );
        let rings_per_metre = SCAN_CONTEXT_RINGS as f32 / max_range;
        let sectors_per_radian = sectors as f32 / std::f32::consts::TAU;
        let (min2, max2) = (min_range * min_range, max_range * max_range);
        let mut used = 0usize;
        for p in cloud.points().iter().step_by(config.point_stride) {
            let (px, py) = (p.x - x, p.y - y);
            let range2 = px * px + py * py;
            if !(range2.is_finite() && p.z.is_finite()) || range2 < min2 || range2 >= max2 {
                continue;
            }
            let ring = ((range2.sqrt() * rings_per_metre) as usize).min(SCAN_CONTEXT_RINGS - 1);
            let azimuth = fast_azimuth(px, py);
            let sector = ((azimuth * sectors_per_radian) as usize).min(sectors - 1);
            // A point below the offset floor still marks its bin as seen.
            let height = (p.z + offset).max(1e-3);
            let bin = &mut bins[ring * sectors + sector];
            *bin = bin.max(height);
            used += 1;
        }
        if used == 0 {
            return Err(PlaceRecognitionError::TooFewPoints {
                points: 0,
                required: 1,
            });
        }
        let mut ring_key = [0.0f32; SCAN_CONTEXT_RINGS];
        for (r, key) in ring_key.iter_mut().enumerate() {
            let row = &bins[r * sectors..(r + 1) * sectors];
            *key = row.iter().sum::<f32>() / sectors as f32;
        }
        let mut unit_rows = bins.clone();
        let mut seen = vec![0.0f32; sectors];
        for (s, seen) in seen.iter_mut().enumerate() {
            let norm = (0..SCAN_CONTEXT_RINGS)
                .map(|r| bins[r * sectors + s] * bins[r * sectors + s])
                .sum::<f32>()
                .sqrt();
            if norm > 0.0 {
                *seen = 1.0;
                for r in 0..SCAN_CONTEXT_RINGS {
                    unit_rows[r * sectors + s] /= norm;
                }
            }
        }
        Ok(Self {
            sectors,
            bins,
            unit_rows,
            seen,
            ring_key,
        })
    }

    /// Azimuth bins.
    #[must_use]
    pub fn sectors(&self) -> usize {
        self.sectors
    }

    /// The highest height (plus the offset) in ring `ring`, sector `sector`; 0 when empty or
    /// out of range.
    #[must_use]
    pub fn bin(&self, ring: usize, sector: usize) -> f32 {
        if ring < SCAN_CONTEXT_RINGS && sector < self.sectors {
            self.bins[ring * self.sectors + sector]
        } else {
            0.0
        }
    }

    /// Each ring's mean height: the same whatever the sensor's heading.
    #[must_use]
    pub fn ring_key(&self) -> &[f32; SCAN_CONTEXT_RINGS] {
        &self.ring_key
    }

    /// The best agreement of `self` (the query) with `candidate` over every column shift, or
    /// `None` when they have different sector counts or no column that both see.
    ///
    /// At shift `k` the query's sector `s` faces the candidate's sector `s + k`; the distance
    /// is the mean of `1 - cos` over the pairs in which both sectors are seen. An unseen
    /// sector's unit column is zero, so the sum of the cosines over the seen pairs is the sum
    /// over all pairs: for every shift at once, that is the circular correlation of the two
    /// scans' unit rows, ring by ring, and the number of seen pairs the correlation of their
    /// `seen` rows.
    #[must_use]
    pub fn compare(&self, candidate: &Self) -> Option<ScanContextMatch> {
        if self.sectors != candidate.sectors {
            return None;
        }
        let n = self.sectors;
        let mut cosines = vec![0.0f32; n];
        let mut pairs = vec![0.0f32; n];
        // The query's row twice over: at shift k its sector u - k (mod n) is at n - k + u.
        let mut doubled = vec![0.0f32; 2 * n];
        let mut correlate = |mine: &[f32], theirs: &[f32], sums: &mut [f32]| {
            doubled[..n].copy_from_slice(mine);
            doubled[n..].copy_from_slice(mine);
            for (k, sum) in sums.iter_mut().enumerate() {
                *sum += dot(&doubled[n - k..2 * n - k], theirs);
            }
        };
        for r in 0..SCAN_CONTEXT_RINGS {
            let at = r * n..(r + 1) * n;
            correlate(
                &self.unit_rows[at.clone()],
                &candidate.unit_rows[at],
                &mut cosines,
            );
        }
        correlate(&self.seen, &candidate.seen, &mut pairs);
        let mut best: Option<(f64, usize)> = None;
        for (shift, (&cos, &count)) in cosines.iter().zip(&pairs).enumerate() {
            // Counts are small integers, exact in f32.
            if count < 0.5 {
                continue;
            }
            let distance = (f64::from(count) - f64::from(cos)) / f64::from(count);
            if best.is_none_or(|(d, _)| distance < d) {
                best = Some((distance, shift));
            }
        }
        let (distance, shift) = best?;
        let sector_width = std::f64::consts::TAU / n as f64;
        let mut yaw = shift as f64 * sector_width;
        if yaw > std::f64::consts::PI {
            yaw -= std::f64::consts::TAU;
        }
        Some(ScanContextMatch { distance, yaw })
    }
}

/// The dot product of two equally long slices, over eight lanes (a plain sum of f32 products
/// may not be reordered, so it would not vectorise).
fn dot(a: &[f32], b: &[f32]) -> f32 {
    let mut lanes = [0.0f32; 8];
    let (a8, b8) = (a.chunks_exact(8), b.chunks_exact(8));
    let tail: f32 = a8
        .remainder()
        .iter()
        .zip(b8.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in a8.zip(b8) {
        for l in 0..8 {
            lanes[l] += x[l] * y[l];
        }
    }
    lanes.iter().sum::<f32>() + tail
}

/// Azimuth of (x, y) in [0, 2 pi), within 0.005 rad (a tenth of a degree against 6-degree
/// sectors): a rational approximation of atan on [0, 1] (about 3 times faster than `atan2`,
/// which is most of the descriptor's cost).
fn fast_azimuth(x: f32, y: f32) -> f32 {
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};
    let (ax, ay) = (x.abs(), y.abs());
    let (small, large) = if ax >= ay { (ay, ax) } else { (ax, ay) };
    if large == 0.0 {
        return 0.0;
    }
    let z = small / large;
    // atan(z) for z in [0, 1], error below 0.0039 rad.
    let mut a = FRAC_PI_4 * z + 0.273 * z * (1.0 - z);
    if ay > ax {
        a = FRAC_PI_2 - a;
    }
    if x < 0.0 {
        a = PI - a;
    }
    if y < 0.0 {
        a = TAU - a;
    }
    if a >= TAU { 0.0 } else { a }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;
    use slam_core::pose3_from_xyz_rpy;

    /// An L-shaped room with a pillar, as a ring of wall points 1.5 m tall.
    fn room() -> PointCloud {
        let mut pts = Vec::new();
        for k in 0..400 {
            let t = f64::from(k) / 400.0;
            for z in [-0.5, 0.0, 0.5, 1.0] {
                pts.push(Point3::new(-3.0 + 10.0 * t, -2.0, z));
                pts.push(Point3::new(-3.0 + 4.0 * t, 6.0, z));
                pts.push(Point3::new(-3.0, -2.0 + 8.0 * t, z));
                pts.push(Point3::new(7.0, -2.0 + 3.0 * t, z));
                pts.push(Point3::new(1.0 + 6.0 * t, 1.0, z));
                pts.push(Point3::new(1.0, 1.0 + 5.0 * t, z));
            }
            let a = std::f64::consts::TAU * t;
            pts.push(Point3::new(4.0 + 0.3 * a.cos(), 3.0 + 0.3 * a.sin(), 0.8));
        }
        let pts = pts
            .into_iter()
            .map(|p| Point3::new(p.x as f32, p.y as f32, p.z as f32))
            .collect();
        PointCloud::from_points(pts)
    }

    #[test]
    fn a_turned_scan_matches_with_its_heading_and_the_same_ring_key() {
        let config = ScanContextConfig::default();
        let scan = room();
        let here = ScanContext::from_cloud(&scan, &config).unwrap();
        for degrees in [-170.0f64, -93.0, -30.0, 0.0, 12.0, 45.0, 100.0, 178.0] {
            let yaw = degrees.to_radians();
            // The query sensor is turned by `yaw`: its points are the room turned by -yaw.
            let turned =
                scan.transformed(&pose3_from_xyz_rpy(0.0, 0.0, 0.0, 0.0, 0.0, yaw).inverse());
            let query = ScanContext::from_cloud(&turned, &config).unwrap();
            let m = query.compare(&here).unwrap();
            let error = (m.yaw - yaw + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
            assert!(
                error.abs() <= 3.0f64.to_radians() + 1e-9,
                "{degrees}: yaw {}",
                m.yaw.to_degrees()
            );
            assert!(m.distance < 0.15, "{degrees}: distance {}", m.distance);
            // Ring keys agree up to sector discretisation.
            let (diff, norm) = query
                .ring_key()
                .iter()
                .zip(here.ring_key())
                .fold((0.0f32, 0.0f32), |(d, n), (a, b)| {
                    (d + (a - b).powi(2), n + b.powi(2))
                });
            assert!(
                diff.sqrt() < 0.15 * norm.sqrt(),
                "{degrees}: ring keys differ by {}",
                diff.sqrt() / norm.sqrt()
            );
        }
    }

    #[test]
    fn another_place_is_farther_than_the_same_place_turned() {
        let config = ScanContextConfig::default();
        let scan = room();
        let here = ScanContext::from_cloud(&scan, &config).unwrap();
        let turned = scan.transformed(&pose3_from_xyz_rpy(0.1, 0.0, 0.0, 0.0, 0.0, 1.0));
        let same = ScanContext::from_cloud(&turned, &config).unwrap();
        let moved = scan.transformed(&pose3_from_xyz_rpy(-3.0, -2.5, 0.0, 0.0, 0.0, 0.0));
        let other = ScanContext::from_cloud(&moved, &config).unwrap();
        let d_same = same.compare(&here).unwrap().distance;
        let d_other = other.compare(&here).unwrap().distance;
        assert!(d_same < 0.5 * d_other, "same {d_same}, other {d_other}");
    }

    #[test]
    fn the_fast_azimuth_is_within_a_tenth_of_a_degree_of_atan2() {
        for k in 0..100_000 {
            let t = k as f32 * 0.000_062_83;
            for r in [0.01f32, 1.0, 50.0] {
                let (x, y) = (r * t.cos(), r * t.sin());
                let exact = y.atan2(x).rem_euclid(std::f32::consts::TAU);
                let d = (fast_azimuth(x, y) - exact).abs();
                let d = d.min(std::f32::consts::TAU - d);
                assert!(
                    d < 0.005,
                    "({x}, {y}): {} against {exact}",
                    fast_azimuth(x, y)
                );
            }
        }
        assert!(fast_azimuth(0.0, 0.0).abs() < 1e-9);
    }

    #[test]
    fn seen_from_a_point_is_the_descriptor_of_the_cloud_moved_the_other_way() {
        let config = ScanContextConfig::default();
        let scan = room();
        let moved = scan.transformed(&pose3_from_xyz_rpy(-0.5, 0.25, 0.0, 0.0, 0.0, 0.0));
        let there = ScanContext::seen_from(&scan, &config, 0.5, -0.25).unwrap();
        let direct = ScanContext::from_cloud(&moved, &config).unwrap();
        let m = there.compare(&direct).unwrap();
        assert!(m.distance < 1e-5 && m.yaw.abs() < 1e-9, "{m:?}");
    }

    #[test]
    fn bad_settings_and_empty_scans_are_errors() {
        let scan = room();
        for config in [
            ScanContextConfig {
                sectors: 2,
                ..ScanContextConfig::default()
            },
            ScanContextConfig {
                max_range: f64::NAN,
                ..ScanContextConfig::default()
            },
            ScanContextConfig {
                min_range: 30.0,
                ..ScanContextConfig::default()
            },
            ScanContextConfig {
                height_offset: f64::INFINITY,
                ..ScanContextConfig::default()
            },
            ScanContextConfig {
                point_stride: 0,
                ..ScanContextConfig::default()
            },
        ] {
            assert!(matches!(
                ScanContext::from_cloud(&scan, &config),
                Err(PlaceRecognitionError::InvalidConfig(_))
            ));
        }
        let far = PointCloud::from_points(vec![Point3::new(100.0, 0.0, 0.0)]);
        assert!(matches!(
            ScanContext::from_cloud(&far, &ScanContextConfig::default()),
            Err(PlaceRecognitionError::TooFewPoints { .. })
        ));
    }

    /// The distance at every shift, every sector pair written out (`None` where no pair is
    /// seen by both): the oracle of the correlation in `compare`.
    fn distances_by_shift(a: &ScanContext, b: &ScanContext) -> Vec<Option<f64>> {
        let n = a.sectors();
        let column = |c: &ScanContext, s: usize| -> Vec<f64> {
            (0..SCAN_CONTEXT_RINGS)
                .map(|r| f64::from(c.bin(r, s)))
                .collect()
        };
        (0..n)
            .map(|shift| {
                let (mut sum, mut pairs) = (0.0, 0usize);
                for s in 0..n {
                    let (p, q) = (column(a, s), column(b, (s + shift) % n));
                    let (np, nq) = (
                        p.iter().map(|v| v * v).sum::<f64>().sqrt(),
                        q.iter().map(|v| v * v).sum::<f64>().sqrt(),
                    );
                    if np > 0.0 && nq > 0.0 {
                        let dot: f64 = p.iter().zip(&q).map(|(x, y)| x * y).sum();
                        sum += 1.0 - dot / (np * nq);
                        pairs += 1;
                    }
                }
                (pairs > 0).then(|| sum / pairs as f64)
            })
            .collect()
    }

    #[test]
    fn the_correlation_finds_the_distance_and_shift_of_the_pair_by_pair_comparison() {
        let config = ScanContextConfig::default();
        let mut state = 7u64;
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);

            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        // Random clutter, some of it in a few sectors only (so that some sectors are empty),
        // and the room, turned and moved.
        let clutter = |next: &mut dyn FnMut() -> f32, points: usize, spread: f32| {
            let pts: Vec<Point3<f32>> = (0..points)
                .map(|_| {
                    let (r, a) = (1.0 + 15.0 * next(), spread * std::f32::consts::TAU * next());
                    Point3::new(r * a.cos(), r * a.sin(), 3.0 * next() - 1.5)
                })
                .collect();
            PointCloud::from_points(pts)
        };
        let mut clouds = vec![
            room(),
            room().transformed(&pose3_from_xyz_rpy(0.4, -0.2, 0.0, 0.0, 0.0, 1.0)),
        ];
        for (points, spread) in [(3000, 1.0), (800, 0.3), (2000, 0.7), (50, 1.0)] {
            clouds.push(clutter(&mut next, points, spread));
        }
        let contexts: Vec<ScanContext> = clouds
            .iter()
            .map(|c| ScanContext::from_cloud(c, &config).unwrap())
            .collect();
        for a in &contexts {
            for b in &contexts {
                let got = a.compare(b).unwrap();
                let by_shift = distances_by_shift(a, b);
                let best = by_shift
                    .iter()
                    .flatten()
                    .copied()
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    (got.distance - best).abs() < 1e-5,
                    "{} vs {best}",
                    got.distance
                );
                // The shift it names is one whose distance is the best, to float precision.
                let width = std::f64::consts::TAU / a.sectors() as f64;
                let shift = (got.yaw.rem_euclid(std::f64::consts::TAU) / width).round() as usize
                    % a.sectors();
                let there = by_shift[shift].unwrap();
                assert!(
                    (there - best).abs() < 1e-5,
                    "shift {shift}: {there} vs {best}"
                );
            }
        }
    }
}
