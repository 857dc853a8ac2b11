//! Property tests of the Lie-group maps against their definitions and finite differences.

use nalgebra::{Isometry2, Matrix3, Matrix6, UnitQuaternion, Vector3, Vector6};
use proptest::prelude::*;

use super::*;

fn vec3(max: f64) -> impl Strategy<Value = Vector3<f64>> {
    (-max..max, -max..max, -max..max).prop_map(|(a, b, c)| Vector3::new(a, b, c))
}

/// Rotation vectors from tiny to close to pi (the hard cases of `log`).
fn rotation_vector() -> impl Strategy<Value = Vector3<f64>> {
    let unit = vec3(1.0)
        .prop_filter("non-zero axis", |v| v.norm() > 1e-3)
        .prop_map(|v| v.normalize());
    let angle = prop_oneof![
        0.0..1e-7,
        1e-7..1e-3,
        1e-3..3.0,
        (std::f64::consts::PI - 1e-3)..std::f64::consts::PI,
        (std::f64::consts::PI - 1e-9)..std::f64::consts::PI,
    ];
    (unit, angle).prop_map(|(u, a)| u * a)
}

fn twist() -> impl Strategy<Value = Vector6<f64>> {
    (vec3(5.0), rotation_vector()).prop_map(|(r, p)| Vector6::new(r.x, r.y, r.z, p.x, p.y, p.z))
}

/// The `exp(log(.))` comparisons below compare group elements, so they treat rotations by pi
/// about `u` and `-u` as equal.
fn rotation_distance(a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>) -> f64 {
    a.angle_to(b)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn so3_hat_vee_and_cross(w in vec3(3.0), v in vec3(3.0)) {
        prop_assert!((so3_hat(&w) * v - w.cross(&v)).norm() < 1e-12);
        prop_assert!((so3_vee(&so3_hat(&w)) - w).norm() < 1e-15);
    }

    #[test]
    fn so3_log_exp(w in rotation_vector()) {
        let q = so3_exp(&w);
        let back = so3_log(&q);
        prop_assert!(rotation_distance(&so3_exp(&back), &q) < 1e-12);
        // Away from pi the vector itself comes back (at pi, w and -w are the same rotation).
        if w.norm() < std::f64::consts::PI - 1e-6 {
            prop_assert!((back - w).norm() < 1e-10, "{:?} vs {:?}", back, w);
        }
        prop_assert!(back.norm() <= std::f64::consts::PI + 1e-12);
    }

    #[test]
    fn se3_exp_log_round_trip(xi in twist()) {
        let t = se3_exp(&xi);
        let back = se3_log(&t);
        let t2 = se3_exp(&back);
        prop_assert!(rotation_distance(&t.rotation, &t2.rotation) < 1e-11);
        prop_assert!((t.translation.vector - t2.translation.vector).norm() < 1e-9);
        if xi.fixed_rows::<3>(3).norm() < std::f64::consts::PI - 1e-6 {
            prop_assert!((back - xi).norm() < 1e-8, "{:?} vs {:?}", back, xi);
        }
        prop_assert!((se3_vee(&se3_hat(&xi)) - xi).norm() < 1e-15);
    }

    #[test]
    fn se3_exp_matches_matrix_exponential(xi in twist()) {
        // Series of the 4x4 matrix exponential (converges fast after scaling and squaring).
        let m = se3_hat(&xi) / 1024.0;
        let mut term = nalgebra::Matrix4::identity();
        let mut sum = nalgebra::Matrix4::identity();
        for k in 1..20 {
            term = term * m / f64::from(k);
            sum += term;
        }
        for _ in 0..10 {
            sum = sum * sum;
        }
        let h = se3_exp(&xi).to_homogeneous();
        prop_assert!((sum - h).amax() < 1e-8, "{}", (sum - h).amax());
    }

    #[test]
    fn so3_left_jacobian_finite_differences(w in rotation_vector()) {
        // Skip angles where the left Jacobian is ill-conditioned for differences (near pi, the
        // log wraps).
        prop_assume!(w.norm() < 3.0);
        let j = so3_left_jacobian(&w);
        let h = 1e-6;
        let mut fd = Matrix3::zeros();
        for k in 0..3 {
            let mut d = Vector3::zeros();
            d[k] = h;
            let plus = so3_log(&(so3_exp(&(w + d)) * so3_exp(&w).inverse()));
            let minus = so3_log(&(so3_exp(&(w - d)) * so3_exp(&w).inverse()));
            fd.set_column(k, &((plus - minus) / (2.0 * h)));
        }
        prop_assert!((fd - j).amax() < 1e-6, "{}", (fd - j).amax());
        prop_assert!((so3_left_jacobian_inverse(&w) * j - Matrix3::identity()).amax() < 1e-9);
    }

    #[test]
    fn se3_left_jacobian_finite_differences(xi in twist()) {
        prop_assume!(xi.fixed_rows::<3>(3).norm() < 3.0);
        let j = se3_left_jacobian(&xi);
        let h = 1e-6;
        let base_inv = se3_exp(&xi).inverse();
        let mut fd = Matrix6::zeros();
        for k in 0..6 {
            let mut d = Vector6::zeros();
            d[k] = h;
            let plus = se3_log(&(se3_exp(&(xi + d)) * base_inv));
            let minus = se3_log(&(se3_exp(&(xi - d)) * base_inv));
            fd.set_column(k, &((plus - minus) / (2.0 * h)));
        }
        prop_assert!((fd - j).amax() < 1e-5, "{}\n{}\n{}", (fd - j).amax(), fd, j);
    }

    #[test]
    fn se3_adjoint_conjugates(xi in twist(), a in twist()) {
        let t = se3_exp(&a);
        let small = xi * 1e-3;
        let lhs = t * se3_exp(&small) * t.inverse();
        let rhs = se3_exp(&(se3_adjoint(&t) * small));
        prop_assert!((lhs.to_homogeneous() - rhs.to_homogeneous()).amax() < 1e-10);
    }

    #[test]
    fn se2_round_trip(x in -10.0..10.0f64, y in -10.0..10.0f64, th in -3.1f64..3.1) {
        let xi = Vector3::new(x, y, th);
        let t = se2_exp(&xi);
        prop_assert!((se2_log(&t) - xi).norm() < 1e-9);
        let p = Isometry2::new(nalgebra::Vector2::new(x, y), th);
        let back = se2_exp(&se2_log(&p));
        prop_assert!((back.to_homogeneous() - p.to_homogeneous()).amax() < 1e-12);
    }

    #[test]
    fn interpolation_end_points_and_midpoint(a in twist(), b in twist()) {
        let (pa, pb) = (se3_exp(&a), se3_exp(&b));
        let p0 = interpolate(&pa, &pb, 0.0);
        let p1 = interpolate(&pa, &pb, 1.0);
        prop_assert!((p0.to_homogeneous() - pa.to_homogeneous()).amax() < 1e-9);
        prop_assert!((p1.to_homogeneous() - pb.to_homogeneous()).amax() < 1e-8);
        // The midpoint splits the relative motion into two equal halves.
        let m = interpolate(&pa, &pb, 0.5);
        let h1 = pa.inverse() * m;
        let h2 = m.inverse() * pb;
        prop_assert!((h1.to_homogeneous() - h2.to_homogeneous()).amax() < 1e-8);
    }
}

#[test]
fn angles_wrap_into_minus_pi_to_pi() {
    use std::f64::consts::PI;
    for (a, want) in [
        (0.0, 0.0),
        (PI, PI),
        (-PI, PI),
        (1.5 * PI, -0.5 * PI),
        (-1.5 * PI, 0.5 * PI),
        (7.0, 7.0 - 2.0 * PI),
    ] {
        assert!(
            (wrap_angle(a) - want).abs() < 1e-12,
            "{a} -> {}",
            wrap_angle(a)
        );
    }
}

#[test]
fn quaternion_component_orders() {
    let q = UnitQuaternion::from_euler_angles(0.3, -0.2, 1.0);
    let xyzw = quaternion_to_xyzw(&q);
    let wxyz = quaternion_to_wxyz(&q);
    assert_eq!(xyzw[3].to_bits(), wxyz[0].to_bits());
    assert_eq!(xyzw[0].to_bits(), wxyz[1].to_bits());
    assert!(quaternion_from_xyzw(xyzw).unwrap().angle_to(&q) < 1e-12);
    assert!(quaternion_from_wxyz(wxyz).unwrap().angle_to(&q) < 1e-12);
    assert!(quaternion_from_xyzw([0.0, 0.0, 0.0, 0.0]).is_none());
    assert!(quaternion_from_xyzw([f64::NAN, 0.0, 0.0, 1.0]).is_none());
    // Identity in TUM's order is 0 0 0 1.
    assert!(quaternion_from_xyzw([0.0, 0.0, 0.0, 1.0]).unwrap().angle() < 1e-15);
    let p = pose3_from_xyz_rpy(1.0, 2.0, 3.0, 0.1, 0.2, 0.3);
    let (r, pi, y) = p.rotation.euler_angles();
    assert!((r - 0.1).abs() < 1e-12 && (pi - 0.2).abs() < 1e-12 && (y - 0.3).abs() < 1e-12);
    assert!(pose3_is_finite(&p));
}
