//! The closed-form rigid fit against independent oracles: known random transforms recovered
//! exactly (3-D and planar point sets), a mirrored set against a brute-force search over
//! rotations, integer weights against repeated pairs, and every error.
#![allow(clippy::unwrap_used)]

use nalgebra::{Point3, UnitQuaternion, Vector3};
use proptest::prelude::*;
use slam_core::{
    Pose3, RigidFitError, WeightedPair, fit_rigid_transform, fit_weighted_rigid_transform,
    pose3_from_xyz_rpy,
};

fn point(max: f64) -> impl Strategy<Value = Point3<f64>> {
    (-max..max, -max..max, -max..max).prop_map(|(x, y, z)| Point3::new(x, y, z))
}

fn pose() -> impl Strategy<Value = Pose3> {
    (
        point(20.0),
        -std::f64::consts::PI..std::f64::consts::PI,
        -1.5..1.5,
        -std::f64::consts::PI..std::f64::consts::PI,
    )
        .prop_map(|(t, roll, pitch, yaw)| pose3_from_xyz_rpy(t.x, t.y, t.z, roll, pitch, yaw))
}

/// The second principal spread of the points over the first: how far they are from a line (0
/// on one). The fit's error grows quickly as this falls (three points at 0.1: about 1e-11; at
/// 0.01: up to 1e-7), so the exact-recovery tests ask for 0.1.
fn spread(points: &[Point3<f64>]) -> f64 {
    let mean = points.iter().map(|p| p.coords).sum::<Vector3<f64>>() / points.len() as f64;
    let cov = points
        .iter()
        .map(|p| (p.coords - mean) * (p.coords - mean).transpose())
        .sum::<nalgebra::Matrix3<f64>>();
    let mut s: Vec<f64> = cov.symmetric_eigenvalues().iter().copied().collect();
    s.sort_by(|a, b| b.total_cmp(a));
    (s[1].max(0.0) / s[0].max(f64::MIN_POSITIVE)).sqrt()
}

fn cost(t: &Pose3, from: &[Point3<f64>], to: &[Point3<f64>]) -> f64 {
    from.iter()
        .zip(to)
        .map(|(a, b)| (b - t * a).norm_squared())
        .sum()
}

/// The best translation for rotation `r` (the centroids' difference) and its cost.
fn cost_of_rotation(r: &UnitQuaternion<f64>, from: &[Point3<f64>], to: &[Point3<f64>]) -> f64 {
    let n = from.len() as f64;
    let (cf, ct) = (
        from.iter().map(|p| p.coords).sum::<Vector3<f64>>() / n,
        to.iter().map(|p| p.coords).sum::<Vector3<f64>>() / n,
    );
    cost(&Pose3::from_parts((ct - r * cf).into(), *r), from, to)
}

fn close(a: &Pose3, b: &Pose3, tol: f64) -> bool {
    (a.to_homogeneous() - b.to_homogeneous()).amax() < tol
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    /// Exact pairs give back the transform that made them.
    #[test]
    fn recovers_known_transforms(
        to_t_from in pose(),
        from in proptest::collection::vec(point(10.0), 3..60),
    ) {
        prop_assume!(spread(&from) > 0.1);
        let to: Vec<_> = from.iter().map(|p| to_t_from * p).collect();
        let fit = fit_rigid_transform(&from, &to).unwrap();
        prop_assert!(close(&fit, &to_t_from, 1e-9), "{fit} vs {to_t_from}");
    }

    /// Planar sets (z = 0): the cross-covariance has a zero singular value, where a fit without
    /// the reflection guard may return a mirror image.
    #[test]
    fn recovers_transforms_of_planar_sets(
        to_t_from in pose(),
        xy in proptest::collection::vec((-10.0..10.0f64, -10.0..10.0f64), 3..40),
    ) {
        let from: Vec<_> = xy.iter().map(|&(x, y)| Point3::new(x, y, 0.0)).collect();
        prop_assume!(spread(&from) > 0.1);
        let to: Vec<_> = from.iter().map(|p| to_t_from * p).collect();
        let fit = fit_rigid_transform(&from, &to).unwrap();
        prop_assert!(close(&fit, &to_t_from, 1e-9), "{fit} vs {to_t_from}");
    }

    /// Integer weights fit as the pairs repeated that many times; zero weights leave pairs out.
    #[test]
    fn weights_act_as_repetitions(
        to_t_from in pose(),
        pairs in proptest::collection::vec((point(10.0), point(0.5), 0u32..4), 3..30),
    ) {
        let (mut from, mut to, mut weighted) = (Vec::new(), Vec::new(), Vec::new());
        for &(p, noise, w) in &pairs {
            let q = to_t_from * p + noise.coords;
            weighted.push(WeightedPair { from: p, to: q, weight: f64::from(w) });
            for _ in 0..w {
                from.push(p);
                to.push(q);
            }
        }
        prop_assume!(pairs.iter().filter(|p| p.2 > 0).count() >= 3 && spread(&from) > 0.1);
        let a = fit_weighted_rigid_transform(weighted.iter().copied()).unwrap();
        let b = fit_rigid_transform(&from, &to).unwrap();
        prop_assert!(close(&a, &b, 1e-9), "{a} vs {b}");
    }

    /// Noisy pairs: no small turn or shift of the fit lowers the cost (a local optimality check
    /// that does not use the closed form).
    #[test]
    fn noisy_fit_is_a_minimum(
        to_t_from in pose(),
        pairs in proptest::collection::vec((point(10.0), point(0.3)), 4..40),
    ) {
        let from: Vec<_> = pairs.iter().map(|p| p.0).collect();
        prop_assume!(spread(&from) > 0.1);
        let to: Vec<_> = pairs.iter().map(|(p, n)| to_t_from * p + n.coords).collect();
        let fit = fit_rigid_transform(&from, &to).unwrap();
        let best = cost(&fit, &from, &to);
        for k in 0..6 {
            for s in [-1e-4, 1e-4] {
                let mut d = nalgebra::Vector6::zeros();
                d[k] = s;
                let moved = slam_core::se3_exp(&d) * fit;
                prop_assert!(cost(&moved, &from, &to) >= best - 1e-9 * (1.0 + best));
            }
        }
    }
}

/// A mirrored set has no exact rigid fit: the answer is a proper rotation, and no rotation of a
/// brute-force search (every 3 degrees of yaw, pitch and roll) does better.
#[test]
fn mirrored_set_gets_the_best_proper_rotation() {
    let from: Vec<Point3<f64>> = [
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 0.5],
        [1.0, 1.0, 1.0],
    ]
    .into_iter()
    .map(Point3::from)
    .collect();
    // Mirror in the plane z = 0.
    let to: Vec<_> = from.iter().map(|p| Point3::new(p.x, p.y, -p.z)).collect();
    let fit = fit_rigid_transform(&from, &to).unwrap();
    let r = fit.rotation.to_rotation_matrix();
    assert!((r.matrix().determinant() - 1.0).abs() < 1e-12);
    assert!((r.matrix() * r.matrix().transpose() - nalgebra::Matrix3::identity()).amax() < 1e-12);
    let best = cost(&fit, &from, &to);
    let step = 3f64.to_radians();
    let mut searched = f64::INFINITY;
    for i in 0..120 {
        for j in 0..61 {
            for k in 0..120 {
                let rotation = UnitQuaternion::from_euler_angles(
                    f64::from(i) * step - std::f64::consts::PI,
                    f64::from(j) * step - std::f64::consts::FRAC_PI_2,
                    f64::from(k) * step - std::f64::consts::PI,
                );
                searched = searched.min(cost_of_rotation(&rotation, &from, &to));
            }
        }
    }
    assert!(best <= searched + 1e-12, "fit {best}, search {searched}");
    // The mirror itself would be exact: a rigid fit cannot be.
    assert!(best > 0.1, "{best}");
}

#[test]
fn bad_input_is_an_error() {
    let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]].map(Point3::from);
    assert_eq!(
        fit_rigid_transform(&p, &p[..2]),
        Err(RigidFitError::LengthMismatch { from: 3, to: 2 })
    );
    assert_eq!(
        fit_rigid_transform(&p[..2], &p[..2]),
        Err(RigidFitError::TooFewPairs {
            pairs: 2,
            required: 3
        })
    );
    let mut nan = p;
    nan[1].y = f64::NAN;
    assert_eq!(
        fit_rigid_transform(&p, &nan),
        Err(RigidFitError::NonFinitePoint { index: 1 })
    );
    let pairs = |weights: [f64; 3]| {
        p.iter().zip(weights).map(|(&q, weight)| WeightedPair {
            from: q,
            to: q,
            weight,
        })
    };
    assert_eq!(
        fit_weighted_rigid_transform(pairs([1.0, -1.0, 1.0])),
        Err(RigidFitError::InvalidWeight {
            index: 1,
            weight: -1.0
        })
    );
    assert!(matches!(
        fit_weighted_rigid_transform(pairs([1.0, 1.0, f64::INFINITY])),
        Err(RigidFitError::InvalidWeight { index: 2, .. })
    ));
    // Zero weights leave pairs out: two left are too few.
    assert_eq!(
        fit_weighted_rigid_transform(pairs([1.0, 0.0, 1.0])),
        Err(RigidFitError::TooFewPairs {
            pairs: 2,
            required: 3
        })
    );
    assert!(fit_weighted_rigid_transform(pairs([1.0, 2.0, 0.5])).is_ok());
}
