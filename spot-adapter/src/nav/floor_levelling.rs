//! The scan levelled on the map's floor before it is fused into the live layer.
//!
//! The live layer tells obstacles from floor by height above the map's floor, so it needs the
//! scan's height and tilt to a few centimetres. The registration pins the estimate's x, y and
//! heading well (walls), but its height, roll and pitch less so: with the thinned walking scans
//! an estimate 0.9° tilted and 4.7 cm high (mission seed 2, goal 3) lifted the floor returns 3.4 m
//! ahead 10 cm, into the obstacle band, and a ring of them shut the way to the goal. The floor
//! returns around the robot show that error directly: a plane fitted to their heights above the
//! map's floor is the correction.

use gridmap::FloorMap;
use nalgebra::{Matrix3, Point3, Translation3, UnitQuaternion, Vector3};
use slam_core::{PointCloud, Pose3};

/// Points within this height of the map's floor (metres) are taken for floor returns ...
const FLOOR_WITHIN: f64 = 0.15;
/// ... and, once a first plane is fitted, within this of the plane, 0.03 m (the floor's noise;
/// a low obstacle's top lies farther).
const PLANE_WITHIN: f64 = 0.03;
/// Floor returns from this far (horizontally, metres) from the sensor: a little more than the
/// live layer's half window.
const RANGE: f64 = 5.0;
/// At least this many floor returns, else the scan is fused as the estimate places it.
const MIN_RETURNS: usize = 50;
/// The slopes are pulled toward level as if by returns this spread (square metres, variance
/// about the sensor, per return): a direction the returns hardly spread along (across a narrow
/// corridor) keeps a slope near 0 rather than a guess, one they spread along is barely pulled.
const SLOPE_PRIOR: f64 = 0.01;
/// Corrections beyond this tilt (radians, about 3°) are not a small estimate error: the scan
/// is fused as placed.
const MAX_TILT: f64 = 0.05;

/// `map_t_lidar` corrected so that the floor returns of `cloud` (lidar frame) lie on `floor`:
/// the plane through their heights above the floor, fitted about the sensor and trimmed of
/// outliers, is taken out; with `tilt_known` (the estimate's roll and pitch are the odometry's
/// gravity) only their median height, so that a floor map a centimetre uneven across a room
/// does not tilt a level scan. `map_t_lidar` itself when too few floor returns are seen.
pub(crate) fn level_on_floor(
    cloud: &PointCloud,
    map_t_lidar: &Pose3,
    floor: &FloorMap,
    tilt_known: bool,
) -> Pose3 {
    let sensor = map_t_lidar.translation.vector;
    // Each return as (dx, dy, height above the floor), relative to the sensor's plan position.
    let returns: Vec<Vector3<f64>> = cloud
        .points()
        .iter()
        .filter_map(|p| {
            let q = map_t_lidar * Point3::new(f64::from(p.x), f64::from(p.y), f64::from(p.z));
            let (dx, dy) = (q.x - sensor.x, q.y - sensor.y);
            let above = q.z - floor.floor_at(q.x, q.y);
            (dx.hypot(dy) <= RANGE && above.abs() <= FLOOR_WITHIN)
                .then(|| Vector3::new(dx, dy, above))
        })
        .collect();
    if tilt_known {
        return match median_height(&returns) {
            Some(height) => Translation3::new(0.0, 0.0, -height) * map_t_lidar,
            None => *map_t_lidar,
        };
    }
    let Some(first) = fit_plane(returns.iter()) else {
        return *map_t_lidar;
    };
    let near = returns
        .iter()
        .filter(|r| (r.z - first.height_at(r.x, r.y)).abs() <= PLANE_WITHIN);
    let Some(plane) = fit_plane(near) else {
        return *map_t_lidar;
    };
    if plane.slope_x.hypot(plane.slope_y) > MAX_TILT {
        return *map_t_lidar;
    }
    // A return at (dx, dy) sits `offset + slope_x dx + slope_y dy` too high: lower the sensor by
    // the offset and turn the scan about it (to first order, turning by `slope_x` about y lowers
    // a point by `slope_x dx`, and by `-slope_y` about x lowers it by `slope_y dy`).
    let turn = UnitQuaternion::from_euler_angles(-plane.slope_y, plane.slope_x, 0.0);
    let about_sensor = Translation3::from(sensor) * turn * Translation3::from(-sensor);
    Translation3::new(0.0, 0.0, -plane.offset) * about_sensor * map_t_lidar
}

/// The median height of the returns (robust to a low obstacle's top, a wall's foot and an
/// uneven part of the floor map), or `None` with fewer than [`MIN_RETURNS`].
fn median_height(returns: &[Vector3<f64>]) -> Option<f64> {
    if returns.len() < MIN_RETURNS {
        return None;
    }
    let mut heights: Vec<f64> = returns.iter().map(|r| r.z).collect();
    let middle = heights.len() / 2;
    Some(*heights.select_nth_unstable_by(middle, f64::total_cmp).1)
}

/// Heights above the floor as a plane about the sensor: `offset + slope_x dx + slope_y dy`.
#[derive(Clone, Copy, Debug)]
struct Plane {
    offset: f64,
    slope_x: f64,
    slope_y: f64,
}

impl Plane {
    fn height_at(&self, dx: f64, dy: f64) -> f64 {
        self.offset + self.slope_x * dx + self.slope_y * dy
    }
}

/// The least-squares plane through `returns` (dx, dy, height), its slopes held by
/// [`SLOPE_PRIOR`], or `None` with fewer than [`MIN_RETURNS`].
fn fit_plane<'a>(returns: impl Iterator<Item = &'a Vector3<f64>>) -> Option<Plane> {
    let (mut n, mut sum, mut sum_outer) = (0usize, Vector3::zeros(), Matrix3::zeros());
    for r in returns {
        let a = Vector3::new(1.0, r.x, r.y);
        n += 1;
        sum += a * r.z;
        sum_outer += a * a.transpose();
    }
    if n < MIN_RETURNS {
        return None;
    }
    let prior = SLOPE_PRIOR * n as f64;
    sum_outer[(1, 1)] += prior;
    sum_outer[(2, 2)] += prior;
    let solution = sum_outer.cholesky()?.solve(&sum);
    Some(Plane {
        offset: solution[0],
        slope_x: solution[1],
        slope_y: solution[2],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Floor returns on a 0.5 m grid out to 4 m around a sensor 0.8 m above a flat floor at
    /// height 0, plus a few wall returns that must not count.
    fn scan() -> PointCloud {
        let mut points = Vec::new();
        for i in -8i32..=8 {
            for j in -8i32..=8 {
                let (x, y) = (0.5 * f64::from(i), 0.5 * f64::from(j));
                if x.hypot(y) > 0.6 && x.hypot(y) <= 4.0 {
                    points.push(Point3::new(x as f32, y as f32, -0.8));
                }
            }
        }
        for k in 0..20 {
            points.push(Point3::new(3.0, -1.0 + 0.1 * k as f32, 0.0));
        }
        PointCloud::from_points(points)
    }

    #[test]
    fn a_tilted_and_raised_estimate_is_levelled_onto_the_floor() {
        let floor = FloorMap::flat(0.0).unwrap();
        let truth = Pose3::from_parts(
            Translation3::new(2.0, 3.0, 0.8),
            UnitQuaternion::from_euler_angles(0.0, 0.0, 1.2),
        );
        // 4.7 cm high and 0.9° off in roll and pitch, as mission seed 2's estimate was.
        let off = Pose3::from_parts(
            Translation3::new(0.0, 0.0, 0.047),
            UnitQuaternion::from_euler_angles(0.015, -0.015, 0.0),
        );
        let levelled = level_on_floor(&scan(), &(truth * off), &floor, false);
        for p in scan().points() {
            let p = Point3::new(f64::from(p.x), f64::from(p.y), f64::from(p.z));
            let error = (levelled * p - truth * p).z.abs();
            assert!(error < 0.005, "{p:?} {error}");
        }
        // The plan position and heading stay the estimate's.
        let moved = (levelled.translation.vector - (truth * off).translation.vector).xy();
        assert!(moved.norm() < 0.005, "{moved:?}");
        // A level estimate stays as it is (to the points' f32 rounding).
        let same = level_on_floor(&scan(), &truth, &floor, false);
        assert!((same.translation.vector - truth.translation.vector).norm() < 1e-6);
        assert!(same.rotation.angle_to(&truth.rotation) < 1e-6);
    }

    /// With the tilt known from gravity, only the height is corrected: returns on one side of
    /// the room 2 cm above the floor map (a map a little uneven) would tilt the plane fit, and
    /// must not turn the scan.
    #[test]
    fn a_known_tilt_is_kept_and_only_the_height_corrected() {
        let floor = FloorMap::flat(0.0).unwrap();
        let uneven = PointCloud::from_points(
            scan()
                .points()
                .iter()
                .map(|p| {
                    let raised = p.z < -0.5 && p.x > 1.0;
                    Point3::new(p.x, p.y, if raised { p.z + 0.02 } else { p.z })
                })
                .collect(),
        );
        let truth = Pose3::from_parts(
            Translation3::new(2.0, 3.0, 0.8),
            UnitQuaternion::from_euler_angles(0.0, 0.0, 1.2),
        );
        let high = Translation3::new(0.0, 0.0, 0.047) * truth;
        let levelled = level_on_floor(&uneven, &high, &floor, true);
        assert_eq!(levelled.rotation, high.rotation);
        assert!((levelled.translation.vector.xy() - truth.translation.vector.xy()).norm() < 1e-9);
        // Lowered to the median floor return (the raised side is the smaller part).
        assert!(
            (levelled.translation.z - 0.8).abs() < 0.003,
            "{}",
            levelled.translation.z
        );
        // The plane fit turns the same scan.
        let fitted = level_on_floor(&uneven, &high, &floor, false);
        assert!(fitted.rotation.angle_to(&high.rotation) > 1e-3);
    }

    #[test]
    fn too_few_floor_returns_leave_the_pose_as_it_is() {
        let floor = FloorMap::flat(0.0).unwrap();
        let walls = PointCloud::from_points(vec![Point3::new(1.0, 0.0, 0.0); 10]);
        let pose = Pose3::from_parts(
            Translation3::new(0.0, 0.0, 0.9),
            UnitQuaternion::from_euler_angles(0.02, 0.0, 0.0),
        );
        assert_eq!(level_on_floor(&walls, &pose, &floor, false), pose);
        assert_eq!(level_on_floor(&walls, &pose, &floor, true), pose);
    }
}
