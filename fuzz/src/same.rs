//! What "reads back the same" means for each kind of data.

use slam_core::{PointCloud, Pose2, Pose3};

/// Two f32 values are the same datum: equal bits, or both NaN (a NaN's payload may change
/// through the readers' f64 conversion and through text).
fn same_f32(a: f32, b: f32) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

fn same_channel(a: Option<&[f32]>, b: Option<&[f32]>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => a.len() == b.len() && a.iter().zip(b).all(|(x, y)| same_f32(*x, *y)),
        _ => false,
    }
}

/// Panic unless `back` holds the same points and channels as `cloud`, value for value.
pub fn assert_same_cloud(cloud: &PointCloud, back: &PointCloud, what: &str) {
    assert_eq!(cloud.len(), back.len(), "{what}: point count");
    for (i, (p, q)) in cloud.points().iter().zip(back.points()).enumerate() {
        assert!(
            (0..3).all(|k| same_f32(p[k], q[k])),
            "{what}: point {i} {p:?} read back as {q:?}"
        );
    }
    assert_eq!(cloud.ring(), back.ring(), "{what}: ring");
    assert!(
        same_channel(cloud.intensity(), back.intensity()),
        "{what}: intensity"
    );
    assert!(same_channel(cloud.time(), back.time()), "{what}: time");
}

/// Panic unless two poses agree to `tol` (metres, and radians of rotation).
pub fn assert_close_pose(a: &Pose3, b: &Pose3, tol: f64, what: &str) {
    let dt = (a.translation.vector - b.translation.vector).norm();
    let scale = a.translation.vector.norm().max(1.0);
    assert!(dt <= tol * scale, "{what}: translation moved {dt}");
    let dr = a.rotation.angle_to(&b.rotation);
    assert!(dr <= tol, "{what}: rotation moved {dr} rad");
}

/// Panic unless two planar poses agree to `tol` (metres, and radians of rotation).
pub fn assert_close_pose2(a: &Pose2, b: &Pose2, tol: f64, what: &str) {
    let dt = (a.translation.vector - b.translation.vector).norm();
    let scale = a.translation.vector.norm().max(1.0);
    assert!(dt <= tol * scale, "{what}: translation moved {dt}");
    let dr = a.rotation.angle_to(&b.rotation).abs();
    assert!(dr <= tol, "{what}: rotation moved {dr} rad");
}
