//! Registration on real HDL-32E scans (see tests/data/README.md) against known transforms and the
//! published reference pose, and on degenerate input.
#![allow(clippy::unwrap_used)]

use crate::common::{error, here, random_halves, random_halves_with, reference, target_scan};
use nalgebra::Point3;
use registration::{IcpConfig, IcpKernel, PointToPlaneIcp, PointToPointIcp};
use slam_core::io::read_ply;
use slam_core::{
    InvalidSetting, PointCloud, Pose3, RegistrationError, Registrator, pose3_from_xyz_rpy,
};

fn run<R: Registrator>(r: &R, source: &PointCloud, target: &PointCloud, initial: &Pose3) -> Pose3 {
    let a = r
        .align(
            &r.prepare_source(source).unwrap(),
            &r.prepare_target(target).unwrap(),
            initial,
        )
        .unwrap();
    assert!(a.converged, "did not converge: {a:?}");
    assert!(a.inlier_ratio > 0.5 && a.rmse.is_finite() && a.min_eigenvalue_ratio > 1e-4);
    a.pose
}

/// Split a real scan into two random halves (not even/odd: the lasers interleave), move one by a
/// known transform, and recover it.
#[test]
fn random_halves_of_a_real_scan() {
    if slam_core::skip_without_test_data!("tests/data", "../slam-core/tests/data") {
        return;
    }
    let (source, target, truth) = random_halves();
    let fine = IcpConfig {
        source_voxel: 0.1,
        target_voxel: 0.0,
        max_correspondence_distance: 1.5,
        ..IcpConfig::default()
    };
    let (rot, trans) = error(
        &truth,
        &run(
            &PointToPlaneIcp { config: fine },
            &source,
            &target,
            &Pose3::identity(),
        ),
    );
    assert!(
        rot < 0.05 && trans < 0.005,
        "point-to-plane: {rot} deg, {trans} m"
    );
}

/// The same with point-to-point ICP on every point, over three random splits and three known
/// transforms (up to 0.45 m and 10 degrees). Each source point pairs with the midpoint of its two
/// nearest target points (the default `pair_target_points`): textbook nearest-point pairs end
/// 0.13-0.14 degrees off here, pulled onto the other half's sampling lattice.
#[test]
fn random_halves_point_to_point() {
    if slam_core::skip_without_test_data!("tests/data", "../slam-core/tests/data") {
        return;
    }
    let dense = IcpConfig {
        source_voxel: 0.0,
        target_voxel: 0.0,
        max_correspondence_distance: 1.5,
        max_iterations: 200,
        ..IcpConfig::default()
    };
    let truths = [
        pose3_from_xyz_rpy(0.4, -0.25, 0.1, 0.03, -0.05, 10f64.to_radians()),
        pose3_from_xyz_rpy(-0.3, 0.35, -0.05, -0.04, 0.02, -8f64.to_radians()),
        pose3_from_xyz_rpy(0.1, 0.45, 0.0, 0.08, 0.05, 4f64.to_radians()),
    ];
    for truth in &truths {
        for seed in [
            0x1234_5678_9ABC_DEF1,
            0xDEAD_BEEF_1234_5677,
            0x0F0F_1234_AAAA_5551,
        ] {
            let (source, target) = random_halves_with(seed, truth);
            let (rot, trans) = error(
                truth,
                &run(
                    &PointToPointIcp { config: dense },
                    &source,
                    &target,
                    &Pose3::identity(),
                ),
            );
            eprintln!("point-to-point halves: {rot:.3} deg, {:.2} mm", trans * 1e3);
            assert!(
                rot < 0.1 && trans < 0.01,
                "point-to-point: {rot} deg, {trans} m"
            );
        }
    }
}

/// `small_gicp`'s HDL-32E pair against its reference pose, from identity and from 1 m and 10
/// degrees off the reference.
#[test]
fn hdl32e_pair_matches_the_reference() {
    if slam_core::skip_without_test_data!("tests/data", "../slam-core/tests/data") {
        return;
    }
    let source = read_ply(here("tests/data/source.ply")).unwrap();
    let target = target_scan();
    let reference = reference();
    let off = reference * pose3_from_xyz_rpy(0.8, -0.6, 0.0, 0.0, 0.0, 10f64.to_radians());
    let wide = IcpConfig {
        max_correspondence_distance: 2.0,
        ..IcpConfig::default()
    };
    for initial in [Pose3::identity(), off] {
        let (rot, trans) = error(
            &reference,
            &run(
                &PointToPlaneIcp { config: wide },
                &source,
                &target,
                &initial,
            ),
        );
        assert!(
            rot < 0.3 && trans < 0.03,
            "point-to-plane: {rot} deg, {trans} m"
        );
        let p2p = IcpConfig {
            max_iterations: 300,
            ..wide
        };
        let (rot, trans) = error(
            &reference,
            &run(&PointToPointIcp { config: p2p }, &source, &target, &initial),
        );
        assert!(
            rot < 0.3 && trans < 0.03,
            "point-to-point: {rot} deg, {trans} m"
        );
    }
}

/// The coarse stage (a subsample with plain searches first) only shortens the way: both ICP
/// backends end where they end without it, from identity and from 1 m and 10 degrees off.
#[test]
fn coarse_stage_ends_at_the_same_pose() {
    if slam_core::skip_without_test_data!("tests/data", "../slam-core/tests/data") {
        return;
    }
    let source = read_ply(here("tests/data/source.ply")).unwrap();
    let target = target_scan();
    let off = reference() * pose3_from_xyz_rpy(0.8, -0.6, 0.0, 0.0, 0.0, 10f64.to_radians());
    let with = IcpConfig {
        max_correspondence_distance: 2.0,
        max_iterations: 300,
        ..IcpConfig::default()
    };
    let without = IcpConfig {
        coarse_stride: 1,
        ..with
    };
    for initial in [Pose3::identity(), off] {
        let plane = [with, without]
            .map(|config| run(&PointToPlaneIcp { config }, &source, &target, &initial));
        same_pose("point-to-plane", &plane[0], &plane[1]);
        let point = [with, without]
            .map(|config| run(&PointToPointIcp { config }, &source, &target, &initial));
        same_pose("point-to-point", &point[0], &point[1]);
    }
}

/// Within 0.01 degrees and 1 mm of each other (both stop once a step moves less than 0.1 mm,
/// so where they stop depends a little on the way there).
fn same_pose(what: &str, a: &Pose3, b: &Pose3) {
    let (rot, trans) = error(a, b);
    eprintln!(
        "{what}, coarse stage or not: {rot:.4} deg, {:.2} mm",
        trans * 1e3
    );
    assert!(rot < 0.01 && trans < 0.001, "{what}: {rot} deg, {trans} m");
}

/// Settings that must be refused, each with the setting the error names.
fn bad_settings(good: IcpConfig) -> Vec<(&'static str, IcpConfig)> {
    let with = |change: fn(&mut IcpConfig)| {
        let mut c = good;
        change(&mut c);
        c
    };
    vec![
        ("IcpConfig::source_voxel", with(|c| c.source_voxel = -0.1)),
        (
            "IcpConfig::target_voxel",
            with(|c| c.target_voxel = f32::NAN),
        ),
        (
            "IcpConfig::max_correspondence_distance",
            with(|c| c.max_correspondence_distance = 0.0),
        ),
        (
            "IcpConfig::max_correspondence_distance",
            with(|c| c.max_correspondence_distance = f64::INFINITY),
        ),
        (
            "IcpConfig::translation_tolerance",
            with(|c| c.translation_tolerance = -1.0),
        ),
        (
            "IcpConfig::kernel",
            with(|c| c.kernel = IcpKernel::Tukey { k: 0.0 }),
        ),
        (
            "IcpConfig::kernel",
            with(|c| c.kernel = IcpKernel::Huber { k: f64::NAN }),
        ),
        ("IcpConfig::max_iterations", with(|c| c.max_iterations = 0)),
        (
            "IcpConfig::normal_neighbours",
            with(|c| c.normal_neighbours = 2),
        ),
        (
            "IcpConfig::pair_target_points",
            with(|c| c.pair_target_points = 0),
        ),
        (
            "IcpConfig::pair_target_points",
            with(|c| c.pair_target_points = 17),
        ),
        ("IcpConfig::coarse_stride", with(|c| c.coarse_stride = 0)),
        (
            "IcpConfig::degeneracy_threshold",
            with(|c| c.degeneracy_threshold = -0.01),
        ),
        (
            "IcpConfig::degeneracy_threshold",
            with(|c| c.degeneracy_threshold = f64::NAN),
        ),
        ("IcpConfig::min_planarity", with(|c| c.min_planarity = -0.1)),
        ("IcpConfig::min_planarity", with(|c| c.min_planarity = 1.5)),
        (
            "IcpConfig::min_planarity",
            with(|c| c.min_planarity = f64::NAN),
        ),
    ]
}

/// Every bad setting is refused by preparation and by alignment, never silently changed.
#[test]
fn invalid_settings_are_errors() {
    if slam_core::skip_without_test_data!("tests/data", "../slam-core/tests/data") {
        return;
    }
    let cloud = target_scan();
    let good = IcpConfig::default();
    let p2p = PointToPointIcp { config: good };
    let (source, target) = (
        p2p.prepare_source(&cloud).unwrap(),
        p2p.prepare_target(&cloud).unwrap(),
    );
    for (setting, config) in bad_settings(good) {
        let invalid = |r: Result<(), RegistrationError>| match r {
            Err(RegistrationError::InvalidConfig(InvalidSetting { setting: s, .. })) => {
                s == setting
            }
            _ => false,
        };
        let (plane, point) = (PointToPlaneIcp { config }, PointToPointIcp { config });
        assert!(
            invalid(plane.prepare_source(&cloud).map(|_| ())),
            "{config:?}"
        );
        assert!(
            invalid(plane.prepare_target(&cloud).map(|_| ())),
            "{config:?}"
        );
        assert!(
            invalid(point.prepare_target(&cloud).map(|_| ())),
            "{config:?}"
        );
        assert!(
            invalid(
                point
                    .align(&source, &target, &Pose3::identity())
                    .map(|_| ())
            ),
            "{config:?}"
        );
    }
    // The message names the setting, its value as written and the valid range.
    let config = IcpConfig {
        source_voxel: -0.1,
        ..good
    };
    assert_eq!(
        config.validate().unwrap_err().to_string(),
        "IcpConfig::source_voxel = -0.1: must be finite and not negative"
    );
}

#[test]
fn degenerate_input_is_an_error_or_flagged() {
    let icp = PointToPlaneIcp::default();
    crate::common::rejects_empty_and_nan(&icp);
    // A single plane: translation along it and rotation about its normal are unobservable.
    let plane: Vec<Point3<f32>> = (0..4000)
        .map(|i| Point3::new((i % 80) as f32 * 0.1, (i / 80) as f32 * 0.1, 0.0))
        .collect();
    let plane = PointCloud::from_points(plane);
    let src = icp.prepare_source(&plane).unwrap();
    let tgt = icp.prepare_target(&plane).unwrap();
    match icp.align(&src, &tgt, &Pose3::translation(0.05, 0.05, 0.02)) {
        Ok(a) => {
            assert!(a.pose.translation.vector.iter().all(|v| v.is_finite()));
            assert!(
                a.min_eigenvalue_ratio < 1e-6,
                "degeneracy must show: {}",
                a.min_eigenvalue_ratio
            );
        }
        Err(e) => assert!(matches!(e, RegistrationError::Degenerate { .. })),
    }
    let bad = Pose3::translation(f64::NAN, 0.0, 0.0);
    assert!(matches!(
        icp.align(&src, &tgt, &bad),
        Err(RegistrationError::NonFiniteInitialGuess)
    ));
}

/// Issue 17: point-to-point ICP of a real scan against 5,000 identical target points took 18 s
/// (point-to-plane 2.9 s). Coincident and collinear targets are now refused when prepared.
#[test]
fn coincident_or_collinear_targets_are_refused() {
    if slam_core::skip_without_test_data!("tests/data", "../slam-core/tests/data") {
        return;
    }
    let scan = target_scan();
    let p = scan.points()[0];
    let same = PointCloud::from_points(vec![p; 5000]);
    let line = PointCloud::from_points(
        (0..5000)
            .map(|i| p + nalgebra::Vector3::new(0.3, -0.2, 0.1) * (i as f32 * 1e-3))
            .collect(),
    );
    let refused = |dimensions| {
        Err::<(), _>(RegistrationError::Degenerate {
            cause: slam_core::Degeneracy::DegenerateTarget { dimensions },
        })
    };
    // Every target point kept, as in the case (the default 0.25 m voxel would leave one
    // point of `same`, which is refused as too few).
    let config = IcpConfig {
        target_voxel: 0.0,
        ..IcpConfig::default()
    };
    let p2p = PointToPointIcp { config };
    let p2plane = PointToPlaneIcp { config };
    assert!(matches!(
        PointToPointIcp::default().prepare_target(&same),
        Err(RegistrationError::TooFewPoints { .. })
    ));
    assert_eq!(p2p.prepare_target(&same).map(|_| ()), refused(0));
    assert_eq!(p2plane.prepare_target(&same).map(|_| ()), refused(0));
    assert_eq!(p2p.prepare_target(&line).map(|_| ()), refused(1));
    assert_eq!(p2plane.prepare_target(&line).map(|_| ()), refused(1));
    // The real scan itself (3 dimensions) is still a target.
    assert!(p2p.prepare_target(&scan).is_ok());
}

/// Three consecutive OS1-128 frames at 2.5 m/s: each frame-to-frame step within 5 cm and 0.2
/// degrees of the shipped reference poses (themselves an estimate; eight other ICP variants agree
/// with them to 0.7-3.8 cm).
#[test]
fn os1_128_steps_match_the_reference_poses() {
    if slam_core::skip_without_test_data!("tests/data", "../slam-core/tests/data") {
        return;
    }
    let (frames, poses) = crate::common::os1_128();
    let icp = PointToPlaneIcp::default();
    for k in 0..2 {
        let reference = poses[k].inverse() * poses[k + 1];
        let estimate = run(&icp, &frames[k + 1], &frames[k], &Pose3::identity());
        let (rot, trans) = error(&reference, &estimate);
        assert!(rot < 0.2 && trans < 0.05, "step {k}: {rot} deg, {trans} m");
    }
}

/// Point-to-plane with only plane-like target neighbourhoods (`min_planarity` 0.2, the slam
/// bench ablation `p2plane-plane-like`) on the three real sets, within the bounds of the tests above: random
/// halves of an HDL-32E scan; the OS1-128 steps; and the HDL-32E pair from identity and from
/// 1 m / 10 degrees off, within 0.35 degrees and 3.5 cm of both published references, which
/// themselves differ by 0.23 degrees and 1.9 cm (it ends 0.31 degrees from `small_gicp`'s and
/// 0.23 from `fast_gicp`'s, where every normal kept ends 0.17 and 0.28 degrees from them).
#[test]
fn plane_like_normals_hold_on_real_scans() {
    if slam_core::skip_without_test_data!("tests/data", "../slam-core/tests/data") {
        return;
    }
    let plane_like = |config: IcpConfig| PointToPlaneIcp {
        config: IcpConfig {
            min_planarity: 0.2,
            ..config
        },
    };
    let (source, target, truth) = random_halves();
    let halves = plane_like(IcpConfig {
        source_voxel: 0.1,
        target_voxel: 0.0,
        max_correspondence_distance: 1.5,
        ..IcpConfig::default()
    });
    let (rot, trans) = error(&truth, &run(&halves, &source, &target, &Pose3::identity()));
    eprintln!("plane-like, halves: {rot:.3} deg, {:.2} mm", trans * 1e3);
    assert!(rot < 0.05 && trans < 0.005, "halves: {rot} deg, {trans} m");

    let (frames, poses) = crate::common::os1_128();
    let icp = plane_like(IcpConfig::default());
    for k in 0..2 {
        let reference = poses[k].inverse() * poses[k + 1];
        let estimate = run(&icp, &frames[k + 1], &frames[k], &Pose3::identity());
        let (rot, trans) = error(&reference, &estimate);
        eprintln!(
            "plane-like, OS1-128 step {k}: {rot:.3} deg, {:.2} cm",
            trans * 1e2
        );
        assert!(rot < 0.2 && trans < 0.05, "step {k}: {rot} deg, {trans} m");
    }

    let source = read_ply(here("tests/data/source.ply")).unwrap();
    let target = target_scan();
    let wide = plane_like(IcpConfig {
        max_correspondence_distance: 2.0,
        ..IcpConfig::default()
    });
    let off = reference() * pose3_from_xyz_rpy(0.8, -0.6, 0.0, 0.0, 0.0, 10f64.to_radians());
    for initial in [Pose3::identity(), off] {
        let estimate = run(&wide, &source, &target, &initial);
        for reference in [reference(), crate::common::fast_gicp_reference()] {
            let (rot, trans) = error(&reference, &estimate);
            eprintln!(
                "plane-like, HDL-32E pair: {rot:.3} deg, {:.2} cm",
                trans * 1e2
            );
            assert!(rot < 0.35 && trans < 0.035, "pair: {rot} deg, {trans} m");
        }
    }
}
