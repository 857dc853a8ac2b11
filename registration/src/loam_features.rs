//! LOAM feature extraction (Zhang & Singh 2014; thesis section 4.1.1.1): edge and planar points
//! picked per laser ring by roughness.

use nalgebra::{Point3, Vector3};
use slam_core::{PointCloud, RegistrationError};

use crate::config::{NON_NEGATIVE, check, check_f32};
use crate::lidar_layout::LidarLayout;

/// Settings of [`LoamFeatures::extract`]. Lengths in metres.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct LoamFeatureConfig {
    /// Ring layout used when the cloud has no ring field (default: VLP-16).
    pub layout: LidarLayout,
    /// Neighbours on each side of a point in its ring for the roughness (thesis eq. 4.3: 5).
    pub neighbours: usize,
    /// Equal parts each ring is split into, so features spread around the sensor (6).
    pub sectors: usize,
    /// Edge points kept per sector and ring at most (20).
    pub max_edges_per_sector: usize,
    /// Planar points kept per sector and ring at most (40).
    pub max_planes_per_sector: usize,
    /// An edge has roughness (eq. 4.3, m²) above this: 0.1, LOAM's value, which is about three
    /// standard deviations above what 1.5 cm range noise gives a point on a plane.
    pub edge_min_roughness: f64,
    /// An edge also has sharpness (`|sum|` over the summed neighbour distances: 0 on a straight
    /// evenly sampled scan line, `cos(a/2)` at a corner of angle `a`) above this: 0.2, corners sharper than
    /// about 157°, so gently curved far surfaces are not taken for edges.
    pub edge_min_sharpness: f64,
    /// A planar point has roughness below this (m², 0.1 as in LOAM).
    pub plane_max_roughness: f64,
    /// Points nearer than this are dropped (the robot's own body; Spot: 1 m).
    pub min_range: f32,
    /// Points farther than this are dropped (too sparse to describe a surface): 80 m.
    pub max_range: f32,
    /// Voxel of the edge points kept for maps and targets: 0 keeps every one. A patch of a
    /// thinned map mixes points of several lasers, whose ranges carry each laser's own
    /// calibration offset, and the tilt that gives a fitted line or plane biases every
    /// alignment the same way: on the static garage sequence, 1 cm planar voxels drift 0.19°
    /// over 29 steps where the full set drifts 0.02°. Local maps of many scans are thinned
    /// instead (see `LoamConfig`).
    pub map_edge_voxel: f32,
    /// Voxel of the planar points kept for maps and targets: 0 keeps every one.
    pub map_plane_voxel: f32,
    /// Neighbours in a ring farther apart than this break the ring (an occlusion boundary or
    /// missing returns): LOAM's 0.1 m², as a distance, about 0.32 m.
    pub break_distance: f64,
    /// A point whose gaps to both ring neighbours exceed this fraction of its range lies on a
    /// surface nearly parallel to the beam and is not picked: LOAM's 0.0002 on squares, about
    /// 0.014.
    pub parallel_gap_ratio: f64,
}

impl Default for LoamFeatureConfig {
    fn default() -> Self {
        Self {
            layout: LidarLayout::VLP16,
            neighbours: 5,
            sectors: 6,
            max_edges_per_sector: 20,
            max_planes_per_sector: 40,
            edge_min_roughness: 0.1,
            edge_min_sharpness: 0.2,
            plane_max_roughness: 0.1,
            min_range: 1.0,
            max_range: 80.0,
            map_edge_voxel: 0.0,
            map_plane_voxel: 0.0,
            break_distance: 0.1f64.sqrt(),
            parallel_gap_ratio: 0.0002f64.sqrt(),
        }
    }
}

impl LoamFeatureConfig {
    fn validate(&self) -> Result<(), RegistrationError> {
        self.layout.validate()?;
        for (setting, v) in [
            ("LoamFeatureConfig::neighbours", self.neighbours),
            ("LoamFeatureConfig::sectors", self.sectors),
        ] {
            check(v >= 1, setting, v as f64, "at least 1")?;
        }
        for (setting, v) in [
            (
                "LoamFeatureConfig::edge_min_roughness",
                self.edge_min_roughness,
            ),
            (
                "LoamFeatureConfig::edge_min_sharpness",
                self.edge_min_sharpness,
            ),
            (
                "LoamFeatureConfig::plane_max_roughness",
                self.plane_max_roughness,
            ),
            ("LoamFeatureConfig::break_distance", self.break_distance),
            (
                "LoamFeatureConfig::parallel_gap_ratio",
                self.parallel_gap_ratio,
            ),
        ] {
            check(v.is_finite() && v >= 0.0, setting, v, NON_NEGATIVE)?;
        }
        for (setting, v) in [
            ("LoamFeatureConfig::min_range", self.min_range),
            ("LoamFeatureConfig::map_edge_voxel", self.map_edge_voxel),
            ("LoamFeatureConfig::map_plane_voxel", self.map_plane_voxel),
        ] {
            check_f32(v.is_finite() && v >= 0.0, setting, v, NON_NEGATIVE)?;
        }
        check_f32(
            self.max_range.partial_cmp(&self.min_range) == Some(std::cmp::Ordering::Greater),
            "LoamFeatureConfig::max_range",
            self.max_range,
            "greater than min_range",
        )
    }
}

/// Edge and planar points of one scan, in the sensor frame: a few picked per sector to be
/// aligned, and every reliable one (voxel-thinned) to build maps and targets from, as LOAM's
/// "sharp"/"flat" and "less sharp"/"less flat" sets: a target fitted only to the sparse picks
/// would often offer a patch of points from one scan line, which fixes no plane.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LoamFeatures {
    /// Picked points on sharp edges (high roughness): at most `max_edges_per_sector` per sector.
    pub edges: Vec<Point3<f64>>,
    /// Picked points on planar surfaces (low roughness): at most `max_planes_per_sector`.
    pub planes: Vec<Point3<f64>>,
    /// Every reliable edge point (one per `map_edge_voxel` when set).
    pub edge_map: Vec<Point3<f64>>,
    /// Every reliable planar point (one per `map_plane_voxel` when set).
    pub plane_map: Vec<Point3<f64>>,
}

/// The first point of `points` in each voxel of size `voxel` (all of them when `voxel` is 0).
/// A kept point is a measured point: a voxel centroid would pull the map off curved and noisy
/// surfaces towards the voxel's centre, and that bias adds up over frames.
pub(crate) fn voxel_thin(points: Vec<Point3<f64>>, voxel: f32) -> Vec<Point3<f64>> {
    if voxel <= 0.0 || points.is_empty() {
        return points;
    }
    let inv = 1.0 / f64::from(voxel);
    let mut seen = rustc_hash::FxHashSet::default();
    seen.reserve(points.len());
    points
        .into_iter()
        .filter(|p| {
            // 21 bits per axis: voxel indices wrap beyond ±10^6 voxels (±50 km at 5 cm), far
            // outside any local map. Saturating casts keep absurd coordinates finite.
            let axis = |v: f64| u64::from(((v * inv).floor() as i32 as u32) & 0x1F_FFFF);
            seen.insert(axis(p.x) | (axis(p.y) << 21) | (axis(p.z) << 42))
        })
        .collect()
}

/// One ring in azimuth order.
struct Ring {
    points: Vec<Point3<f64>>,
}

/// A pseudo-angle in `[0, 4)` that grows with the azimuth: orders points around the sensor
/// without a trigonometric call per point.
fn pseudo_azimuth(x: f64, y: f64) -> f64 {
    let s = x.abs() + y.abs();
    if s == 0.0 {
        return 0.0;
    }
    match (x >= 0.0, y >= 0.0) {
        (true, true) => y / s,
        (false, true) => 1.0 - x / s,
        (false, false) => 2.0 - y / s,
        (true, false) => 3.0 + x / s,
    }
}

/// The cloud's finite points within range, grouped by ring and ordered by azimuth.
fn rings(cloud: &PointCloud, config: &LoamFeatureConfig) -> Vec<Ring> {
    let field = cloud.ring();
    let count = field.map_or(usize::from(config.layout.rings), |r| {
        r.iter().copied().max().map_or(0, |m| usize::from(m) + 1)
    });
    let per_ring = cloud.len() / count.max(1) + cloud.len() / 8;
    let mut keyed: Vec<Vec<(f64, Point3<f64>)>> =
        (0..count).map(|_| Vec::with_capacity(per_ring)).collect();
    let (lo, hi) = (config.min_range, config.max_range);
    for (i, p) in cloud.points().iter().enumerate() {
        let range = p.coords.norm();
        if !(range.is_finite() && range >= lo && range <= hi) {
            continue;
        }
        let ring = match field {
            Some(r) => Some(r[i]),
            None => config.layout.ring_of(p),
        };
        if let Some(bucket) = ring.and_then(|k| keyed.get_mut(usize::from(k))) {
            let q = p.cast::<f64>();
            bucket.push((pseudo_azimuth(q.x, q.y), q));
        }
    }
    keyed
        .into_iter()
        .map(|mut v| {
            order_by_azimuth(&mut v);
            Ring {
                points: v.into_iter().map(|(_, p)| p).collect(),
            }
        })
        .collect()
}

/// Order a ring by ascending azimuth. A sensor's own order is already monotonic from the start
/// of the sweep (either way round), so a ring that is, up to one wrap, is only rotated (and
/// reversed when clockwise); any other order is sorted.
fn order_by_azimuth(v: &mut [(f64, Point3<f64>)]) {
    let (mut ups, mut downs, mut first_up, mut first_down) = (0usize, 0usize, 0, 0);
    for i in 1..v.len() {
        if v[i].0 > v[i - 1].0 {
            if ups == 0 {
                first_up = i;
            }
            ups += 1;
        } else if v[i].0 < v[i - 1].0 {
            if downs == 0 {
                first_down = i;
            }
            downs += 1;
        }
        if ups > 1 && downs > 1 {
            break;
        }
    }
    let (first, last) = (
        v.first().map_or(0.0, |p| p.0),
        v.last().map_or(0.0, |p| p.0),
    );
    if downs == 0 || (downs == 1 && last <= first) {
        v.rotate_left(first_down);
    } else if ups == 0 || (ups == 1 && last >= first) {
        // Clockwise, as Velodyne sensors turn: the same ascending order as sorting gives.
        v.rotate_left(first_up);
        v.reverse();
    } else {
        v.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    }
}

/// Per-point state of a ring while picking.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Pick {
    Free,
    /// Never picked: unreliable (occluded side, beam-parallel surface, ring break).
    Unreliable,
    /// Picked, or next to a pick.
    Taken,
}

impl LoamFeatures {
    /// Extract edge and planar points from a scan in the sensor frame. The ring of each point is
    /// the cloud's ring field when it has one, else computed from its elevation with
    /// `config.layout`; each ring is ordered by azimuth, so any point order works.
    ///
    /// # Errors
    /// [`RegistrationError::InvalidConfig`] for an invalid configuration.
    pub fn extract(
        cloud: &PointCloud,
        config: &LoamFeatureConfig,
    ) -> Result<Self, RegistrationError> {
        config.validate()?;
        // Most points of a scan are reliable planar points: room for all of them up front.
        let mut out = Self {
            plane_map: Vec::with_capacity(cloud.len()),
            ..Self::default()
        };
        for ring in rings(cloud, config) {
            extract_ring(&ring.points, config, &mut out);
        }
        out.edge_map = voxel_thin(std::mem::take(&mut out.edge_map), config.map_edge_voxel);
        out.plane_map = voxel_thin(std::mem::take(&mut out.plane_map), config.map_plane_voxel);
        Ok(out)
    }

    /// Number of picked feature points (edges and planes).
    #[must_use]
    pub fn len(&self) -> usize {
        self.edges.len() + self.planes.len()
    }

    /// Whether no feature was picked.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.edges.is_empty() && self.planes.is_empty()
    }
}

/// Roughness (thesis eq. 4.3: `|sum_j (x_i - x_j)|²` over `n` neighbours on each side) and
/// sharpness (`|sum|` over `sum_j |x_i - x_j|`, that sum estimated as `(n + 1) / 2` times the
/// window's path length, exact for evenly spaced points on a line) of every point with a full
/// neighbourhood. `gaps[i]` is `|x_{i+1} - x_i|`.
fn roughness(points: &[Point3<f64>], gaps: &[f64], n: usize) -> (Vec<f64>, Vec<f64>) {
    let m = points.len();
    let mut rough = vec![f64::NAN; m];
    let mut sharp = vec![f64::NAN; m];
    if m < 2 * n + 1 {
        return (rough, sharp);
    }
    let (two_n, half) = ((2 * n) as f64, (n + 1) as f64 / 2.0);
    // Running sums over the window: O(1) per point.
    let mut window: Vector3<f64> = points[..=2 * n].iter().map(|p| p.coords).sum();
    let mut path: f64 = gaps[..2 * n].iter().sum();
    for i in n..m - n {
        if i > n {
            window += points[i + n].coords - points[i - n - 1].coords;
            path += gaps[i + n - 1] - gaps[i - n - 1];
        }
        let sum = points[i].coords * (two_n + 1.0) - window;
        rough[i] = sum.norm_squared();
        sharp[i] = if path > 0.0 {
            sum.norm() / (half * path)
        } else {
            0.0
        };
    }
    (rough, sharp)
}

/// Mark points whose neighbourhood LOAM deems unreliable: the far side of an occlusion boundary,
/// both sides of other ring breaks, and surfaces nearly parallel to the beam.
fn unreliable(
    points: &[Point3<f64>],
    gaps: &[f64],
    config: &LoamFeatureConfig,
    state: &mut [Pick],
) {
    let n = config.neighbours;
    let m = points.len();
    let mark = |range: std::ops::Range<usize>, state: &mut [Pick]| {
        for s in &mut state[range] {
            *s = Pick::Unreliable;
        }
    };
    for i in 0..m.saturating_sub(1) {
        if gaps[i] <= config.break_distance {
            continue;
        }
        let (a, b) = (points[i].coords, points[i + 1].coords);
        let (da, db) = (a.norm(), b.norm());
        // Nearly the same bearing at different depths: the farther side is occluded and its
        // edge moves with the viewpoint.
        if da > db && (b - a * (db / da)).norm() / db < 0.1 {
            mark(i.saturating_sub(n)..i + 1, state);
        } else if db > da && (a - b * (da / db)).norm() / da < 0.1 {
            mark(i + 1..(i + n + 2).min(m), state);
        } else {
            mark(i.saturating_sub(n - 1)..(i + n + 1).min(m), state);
        }
    }
    for i in 1..m.saturating_sub(1) {
        let limit = points[i].coords.norm() * config.parallel_gap_ratio;
        if gaps[i - 1] > limit && gaps[i] > limit {
            state[i] = Pick::Unreliable;
        }
    }
}

/// After picking `i`, its neighbours up to the next ring break may not be picked.
fn take_neighbours(gaps: &[f64], i: usize, n: usize, state: &mut [Pick]) {
    // LOAM's 0.05 m² between ring neighbours.
    const CONTIGUOUS: f64 = 0.223_606_797_749_979;
    state[i] = Pick::Taken;
    for j in i + 1..=(i + n).min(state.len() - 1) {
        if gaps[j - 1] > CONTIGUOUS {
            break;
        }
        if state[j] == Pick::Free {
            state[j] = Pick::Taken;
        }
    }
    for j in (i.saturating_sub(n)..i).rev() {
        if gaps[j] > CONTIGUOUS {
            break;
        }
        if state[j] == Pick::Free {
            state[j] = Pick::Taken;
        }
    }
}

fn extract_ring(points: &[Point3<f64>], config: &LoamFeatureConfig, out: &mut LoamFeatures) {
    let n = config.neighbours;
    let m = points.len();
    if m < 2 * n + 1 {
        return;
    }
    let gaps: Vec<f64> = points.windows(2).map(|w| (w[1] - w[0]).norm()).collect();
    let (rough, sharp) = roughness(points, &gaps, n);
    let mut state = vec![Pick::Free; m];
    unreliable(points, &gaps, config, &mut state);
    let (first, end) = (n, m - n);
    for i in first..end {
        if state[i] == Pick::Unreliable {
            continue;
        }
        if rough[i] > config.edge_min_roughness && sharp[i] >= config.edge_min_sharpness {
            out.edge_map.push(points[i]);
        } else if rough[i] < config.plane_max_roughness {
            out.plane_map.push(points[i]);
        }
    }
    let sectors = config.sectors.min(end - first);
    // Sector members keyed by roughness (as f32 bits, which order like the non-negative
    // values) above their index: one integer sort per sector.
    let mut order: Vec<u64> = Vec::new();
    let key = |i: usize| (u64::from((rough[i] as f32).to_bits()) << 32) | i as u64;
    let index = |k: u64| (k & 0xFFFF_FFFF) as usize;
    for s in 0..sectors {
        let lo = first + (end - first) * s / sectors;
        let hi = first + (end - first) * (s + 1) / sectors;
        order.clear();
        order.extend((lo..hi).map(key));
        order.sort_unstable();
        let mut edges = 0;
        for &k in order.iter().rev() {
            let i = index(k);
            if edges == config.max_edges_per_sector || rough[i] <= config.edge_min_roughness {
                break;
            }
            if state[i] == Pick::Free && sharp[i] >= config.edge_min_sharpness {
                out.edges.push(points[i]);
                take_neighbours(&gaps, i, n, &mut state);
                edges += 1;
            }
        }
        let mut planes = 0;
        for &k in &order {
            let i = index(k);
            if planes == config.max_planes_per_sector || rough[i] >= config.plane_max_roughness {
                break;
            }
            if state[i] == Pick::Free {
                out.planes.push(points[i]);
                take_neighbours(&gaps, i, n, &mut state);
                planes += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roughness_matches_the_definition() {
        let pts: Vec<Point3<f64>> = (0..20)
            .map(|i| {
                let t = f64::from(i) * 0.1;
                Point3::new(t, (t * 3.0).sin(), t * t)
            })
            .collect();
        let gaps: Vec<f64> = pts.windows(2).map(|w| (w[1] - w[0]).norm()).collect();
        let (rough, sharp) = roughness(&pts, &gaps, 5);
        for i in 5..15 {
            let sum: Vector3<f64> = (i - 5..=i + 5)
                .filter(|&j| j != i)
                .map(|j| pts[i] - pts[j])
                .sum();
            let path: f64 = gaps[i - 5..i + 5].iter().sum();
            assert!((rough[i] - sum.norm_squared()).abs() < 1e-12);
            assert!((sharp[i] - sum.norm() / (3.0 * path)).abs() < 1e-12);
        }
        // On evenly spaced points the estimate is exact: a right-angle corner gives cos(45°).
        let corner: Vec<Point3<f64>> = (0..11)
            .map(|i: i32| {
                let t = f64::from(i - 5);
                if t < 0.0 {
                    Point3::new(-t, 0.0, 0.0)
                } else {
                    Point3::new(0.0, t, 0.0)
                }
            })
            .collect();
        let gaps: Vec<f64> = corner.windows(2).map(|w| (w[1] - w[0]).norm()).collect();
        let (_, sharp) = roughness(&corner, &gaps, 5);
        assert!((sharp[5] - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-12);
        assert!(rough[4].is_nan() && rough[15].is_nan());
    }

    #[test]
    fn pseudo_azimuth_is_monotonic() {
        let mut last = -1.0;
        for k in 0..3600 {
            let a = f64::from(k).to_radians() * 0.1;
            let v = pseudo_azimuth(a.cos(), a.sin());
            assert!(v > last, "{k}: {v} <= {last}");
            last = v;
        }
    }
}
