//! `IcpConfig::degeneracy_threshold` on synthetic scenes whose answer is known by construction:
//! a corridor with nothing along its axis keeps the guess's position along it and still
//! corrects everything else; a closed room, which constrains every direction, aligns exactly as
//! without the setting.

use nalgebra::{Point3, Translation3, UnitQuaternion};
use registration::{IcpConfig, PointToPlaneIcp};
use slam_core::{Degeneracy, PointCloud, Pose3, RegistrationError, Registrator};

/// Points every `step` metres on the walls `y = +-1.2`, the floor `z = 0` and the ceiling
/// `z = 2.4` of a corridor from `x = -12` to `x = 12`, the lattice shifted by `phase` and
/// roughened by a deterministic ripple of a millimetre (no two samples at one place).
fn corridor(step: f64, phase: f64) -> PointCloud {
    cloud(&corridor_points(step, phase))
}

fn cloud(points: &[Point3<f64>]) -> PointCloud {
    PointCloud::from_points(points.iter().map(|p| p.cast::<f32>()).collect())
}

fn corridor_points(step: f64, phase: f64) -> Vec<Point3<f64>> {
    let mut points = Vec::new();
    let along = (24.0 / step) as i32;
    let across = (2.4 / step) as i32;
    for i in 0..along {
        let x = -12.0 + phase + f64::from(i) * step;
        for j in 0..=across {
            let t = f64::from(j) * step;
            let ripple = 0.001 * (7.0 * x + 3.0 * t).sin();
            points.push(Point3::new(x, -1.2 + ripple, t));
            points.push(Point3::new(x, 1.2 + ripple, t));
            points.push(Point3::new(x, -1.2 + t, ripple));
            points.push(Point3::new(x, -1.2 + t, 2.4 + ripple));
        }
    }
    points
}

/// `corridor` closed by end walls at `x = -3` and `x = 3`: a room, which fixes every direction.
fn room(step: f64, phase: f64) -> PointCloud {
    let mut points: Vec<Point3<f64>> = corridor_points(step, phase)
        .into_iter()
        .filter(|p| p.x.abs() <= 3.0)
        .collect();
    let n = (2.4 / step) as i32;
    for j in 0..=n {
        for k in 0..=n {
            let (y, z) = (-1.2 + f64::from(j) * step, f64::from(k) * step);
            points.push(Point3::new(-3.0, y, z + phase));
            points.push(Point3::new(3.0, y + phase, z));
        }
    }
    cloud(&points)
}

fn pose(x: f64, y: f64, z: f64, yaw: f64) -> Pose3 {
    Pose3::from_parts(
        Translation3::new(x, y, z),
        UnitQuaternion::from_euler_angles(0.0, 0.0, yaw),
    )
}

fn icp(threshold: f64) -> PointToPlaneIcp {
    PointToPlaneIcp {
        config: IcpConfig {
            source_voxel: 0.0,
            target_voxel: 0.0,
            max_correspondence_distance: 0.5,
            degeneracy_threshold: threshold,
            ..IcpConfig::default()
        },
    }
}

/// The source is the scene seen from `truth` (the target's points moved into the source's
/// frame, sampled on a shifted lattice); aligned from `guess`.
fn align(
    scene: fn(f64, f64) -> PointCloud,
    icp: &PointToPlaneIcp,
    truth: &Pose3,
    guess: &Pose3,
) -> Result<slam_core::Alignment, RegistrationError> {
    let target = icp.prepare_target(&scene(0.1, 0.0))?;
    let source = scene(0.1, 0.037).transformed(&truth.inverse());
    let source = icp.prepare_source(&source)?;
    icp.align(&source, &target, guess)
}

#[test]
fn a_blank_corridor_keeps_the_guess_along_its_axis_and_corrects_the_rest() {
    let truth = pose(0.4, 0.05, 0.03, 0.0);
    // The guess is 0.15 m off along the axis, and off across it and in height.
    let guess = pose(0.55, 0.12, -0.01, 0.0);
    let a = align(corridor, &icp(0.01), &truth, &guess).unwrap();
    assert!(a.converged);
    let t = a.pose.translation.vector;
    // Nothing constrains x: the guess's x stands (but for the lever arm of the
    // sub-milliradian turns the millimetre ripple asks for).
    assert!((t.x - 0.55).abs() < 5e-4, "x {}", t.x);
    // Everything else reaches the truth.
    assert!(
        (t.y - 0.05).abs() < 1e-3 && (t.z - 0.03).abs() < 1e-3,
        "{t:?}"
    );
    assert!(a.pose.rotation.angle() < 1e-3);
    // The information still reports the blind direction.
    assert!(a.min_eigenvalue_ratio < 1e-3, "{}", a.min_eigenvalue_ratio);
}

#[test]
fn a_blank_corridor_corrects_the_heading_without_sliding() {
    let truth = pose(0.4, 0.05, 0.03, 0.02);
    let guess = pose(0.55, 0.12, -0.01, 0.0);
    let a = align(corridor, &icp(0.01), &truth, &guess).unwrap();
    let yaw = a.pose.rotation.euler_angles().2;
    assert!((yaw - 0.02).abs() < 1e-3, "yaw {yaw}");
    // Turning about the origin moves the position along the axis by at most the turn times
    // the distance from it (0.02 rad x 0.13 m): the only motion along the axis.
    let t = a.pose.translation.vector;
    assert!((t.x - 0.55).abs() <= 0.02 * 0.13 + 1e-4, "x {}", t.x);
    assert!(
        (t.y - 0.05).abs() < 2e-3 && (t.z - 0.03).abs() < 2e-3,
        "{t:?}"
    );
}

#[test]
fn a_room_aligns_as_without_the_setting() {
    let truth = pose(0.1, 0.05, 0.03, 0.02);
    let guess = pose(0.0, 0.0, 0.0, 0.0);
    let with = align(room, &icp(0.01), &truth, &guess).unwrap();
    let without = align(room, &icp(0.0), &truth, &guess).unwrap();
    let off = with.pose.inverse() * without.pose;
    assert!(
        off.translation.vector.norm() < 1e-9 && off.rotation.angle() < 1e-9,
        "{off:?}"
    );
    assert_eq!(with.iterations, without.iterations);
    let t = with.pose.translation.vector;
    assert!((t - truth.translation.vector).norm() < 2e-3, "{t:?}");
}

#[test]
fn a_threshold_no_direction_meets_is_an_error() {
    let truth = pose(0.1, 0.05, 0.03, 0.02);
    match align(room, &icp(1e6), &truth, &Pose3::identity()) {
        Err(RegistrationError::Degenerate { cause }) => {
            assert_eq!(cause, Degeneracy::SingularNormalEquations);
        }
        other => panic!("{other:?}"),
    }
}
