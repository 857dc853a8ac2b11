//! Information matrices of the engine's edges: fixed sigmas, and fixed sigmas combined with a
//! registration's own `J^T W J`.

use nalgebra::{Matrix6, Vector6};

use super::config::EdgeInformation;
use crate::Pose3;
use crate::geometry::se3_adjoint;
use crate::pose_graph::GraphPose;

/// The information of an edge of `kind` ending at `pose` (`map_T_lidar`), from the
/// registration's own `reg_info` where the kind uses it: fixed sigmas of 5 cm and 1° stand in for
/// a registration information that is missing or invalid.
pub(crate) fn edge_information(
    kind: EdgeInformation,
    reg_info: Option<&Matrix6<f64>>,
    pose: &Pose3,
) -> Matrix6<f64> {
    // Registration information is for a left perturbation of map_T_lidar; the edge error
    // perturbs the relative pose on the right: Omega' = Ad(X)^T Omega Ad(X).
    let in_edge_frame = |info: &Matrix6<f64>, scale: f64| {
        let ad = se3_adjoint(pose);
        let m = ad.transpose() * info * ad * scale;
        (m + m.transpose()) * 0.5
    };
    let fallback = || fixed_information(0.05, 1f64.to_radians());
    match (kind, reg_info) {
        (EdgeInformation::FromRegistration { scale }, Some(info)) => {
            let m = in_edge_frame(info, scale);
            if Pose3::information_is_valid(&m) {
                m
            } else {
                fallback()
            }
        }
        (
            EdgeInformation::Fixed {
                translation_sigma,
                rotation_sigma,
            },
            _,
        )
        | (
            EdgeInformation::FixedAndRegistration {
                translation_sigma,
                rotation_sigma,
                ..
            },
            None,
        ) => fixed_information(translation_sigma, rotation_sigma),
        (
            EdgeInformation::FixedAndRegistration {
                translation_sigma,
                rotation_sigma,
                scale,
            },
            Some(info),
        ) => {
            let fixed = fixed_information(translation_sigma, rotation_sigma);
            combined_information(&fixed, &in_edge_frame(info, scale)).unwrap_or(fixed)
        }
        (EdgeInformation::FromRegistration { .. }, None) => fallback(),
    }
}

/// Diagonal information from standard deviations (tangent order `[rho; phi]`).
/// `info` (an edge's, in its own frame) with the edge's relative tilt measured too: the
/// rotations about its x and y axes, each with standard deviation `sigma` (radians), added as
/// an independent measurement.
pub(crate) fn with_tilt(mut info: Matrix6<f64>, sigma: f64) -> Matrix6<f64> {
    let w = 1.0 / (sigma * sigma);
    info[(3, 3)] += w;
    info[(4, 4)] += w;
    info
}

pub(crate) fn fixed_information(translation_sigma: f64, rotation_sigma: f64) -> Matrix6<f64> {
    let (t, r) = (
        1.0 / (translation_sigma * translation_sigma),
        1.0 / (rotation_sigma * rotation_sigma),
    );
    Matrix6::from_diagonal(&Vector6::new(t, t, t, r, r, r))
}

/// The information of two independent errors of one edge, `(Σ_a + Σ_b)^-1`, computed as
/// `Ω_a (Ω_a + Ω_b)^-1 Ω_b` so that `b` may be singular (a registration blind along a
/// corridor's axis); `a` must be positive definite. An edge is never softer than 1 m / 1 rad
/// (information 1 added on the diagonal), so that a blind direction still ties its two nodes
/// together. `None` when the sum cannot be inverted or the result is not a valid information.
pub(crate) fn combined_information(a: &Matrix6<f64>, b: &Matrix6<f64>) -> Option<Matrix6<f64>> {
    let m = a * (a + b).try_inverse()? * b;
    Some((m + m.transpose()) * 0.5 + Matrix6::identity()).filter(Pose3::information_is_valid)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;

    /// A random symmetric positive definite matrix with eigenvalues in `[lo, hi]`.
    fn spd(seed: u64, lo: f64, hi: f64) -> Matrix6<f64> {
        let mut state = seed;
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let q = Matrix6::from_fn(|_, _| next() - 0.5).qr().q();
        let d = Vector6::from_fn(|_, _| lo + (hi - lo) * next());
        q * Matrix6::from_diagonal(&d) * q.transpose()
    }

    #[test]
    fn two_definite_informations_combine_as_their_covariances_add() {
        for seed in 0..20 {
            let (a, b) = (spd(seed, 1.0, 1e4), spd(seed + 100, 0.1, 1e3));
            let got = combined_information(&a, &b).unwrap();
            let want = (a.try_inverse().unwrap() + b.try_inverse().unwrap())
                .try_inverse()
                .unwrap()
                + Matrix6::identity();
            assert!((got - want).norm() <= 1e-9 * want.norm(), "seed {seed}");
        }
    }

    #[test]
    fn a_blind_direction_is_left_at_the_floor_and_the_rest_keeps_the_fixed_stiffness() {
        let fixed = fixed_information(0.01, 0.2f64.to_radians());
        // A registration a thousand times stiffer than the fixed sigmas, except along x,
        // which it did not see at all.
        let mut registration = fixed * 1000.0;
        registration[(0, 0)] = 0.0;
        let got = combined_information(&fixed, &registration).unwrap();
        assert!((got[(0, 0)] - 1.0).abs() < 1e-9, "{}", got[(0, 0)]);
        for k in 1..6 {
            let want = fixed[(k, k)] * 1000.0 / 1001.0 + 1.0;
            let rel = (got[(k, k)] - want).abs() / fixed[(k, k)];
            assert!(rel < 1e-12, "{k}: {}", got[(k, k)]);
        }
    }
}
