//! Registration on real HDL-32E scans (see tests/data/README.md) against known transforms and the
//! published reference pose, and on degenerate input.
#![allow(clippy::unwrap_used)]

use std::path::PathBuf;

use nalgebra::{Matrix4, Point3, UnitQuaternion};
use registration::{IcpConfig, PointToPlaneIcp, PointToPointIcp};
use slam_core::io::read_ply;
use slam_core::{PointCloud, Pose3, RegistrationError, Registrator, pose3_from_xyz_rpy};

fn here(p: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(p)
}

fn target_scan() -> PointCloud {
    read_ply(here("../slam-core/tests/data/hdl32e_pair_target.ply")).unwrap()
}

fn reference() -> Pose3 {
    let txt = std::fs::read_to_string(here("tests/data/T_target_source.txt")).unwrap();
    let v: Vec<f64> = txt.split_whitespace().map(|s| s.parse().unwrap()).collect();
    let m = Matrix4::from_row_slice(&v);
    Pose3::from_parts(
        m.fixed_view::<3, 1>(0, 3).into_owned().into(),
        UnitQuaternion::from_matrix(&m.fixed_view::<3, 3>(0, 0).into_owned()),
    )
}

/// Rotation (degrees) and translation (metres) between two poses.
fn error(a: &Pose3, b: &Pose3) -> (f64, f64) {
    let e = a.inverse() * b;
    (e.rotation.angle().to_degrees(), e.translation.vector.norm())
}

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

/// A real scan split into two random halves (not even/odd: the lasers interleave), the source
/// half moved by a known transform: (source, target, `target_T_source`).
fn random_halves() -> (PointCloud, PointCloud, Pose3) {
    let scan = target_scan();
    let mut s: u64 = 0x1234_5678_9ABC_DEF1;
    let mut coin = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s & 1 == 1
    };
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for &p in scan.points() {
        if coin() {
            a.push(p);
        } else {
            b.push(p);
        }
    }
    let truth = pose3_from_xyz_rpy(0.4, -0.25, 0.1, 0.03, -0.05, 10f64.to_radians());
    (
        PointCloud::from_points(b).transformed(&truth.inverse()),
        PointCloud::from_points(a),
        truth,
    )
}

/// Split a real scan into two random halves (not even/odd: the lasers interleave), move one by a
/// known transform, and recover it.
#[test]
fn random_halves_of_a_real_scan() {
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

/// The same with point-to-point ICP. Known gap: on this ring-structured scan point-to-point pairs
/// snap to neighbouring laser rings and the rotation ends about 0.14 degrees off (translation
/// about 1 mm), short of the 0.1 degree target; run with `--ignored` to see the figure.
#[test]
#[ignore = "known gap: point-to-point ends 0.14 degrees off on ring-structured halves"]
fn random_halves_point_to_point() {
    let (source, target, truth) = random_halves();
    let dense = IcpConfig {
        source_voxel: 0.0,
        target_voxel: 0.0,
        max_correspondence_distance: 1.5,
        max_iterations: 200,
        ..IcpConfig::default()
    };
    let (rot, trans) = error(
        &truth,
        &run(
            &PointToPointIcp { config: dense },
            &source,
            &target,
            &Pose3::identity(),
        ),
    );
    assert!(
        rot < 0.1 && trans < 0.01,
        "point-to-point: {rot} deg, {trans} m"
    );
}

/// `small_gicp`'s HDL-32E pair against its reference pose, from identity and from 1 m and 10
/// degrees off the reference.
#[test]
fn hdl32e_pair_matches_the_reference() {
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

#[test]
fn degenerate_input_is_an_error_or_flagged() {
    let icp = PointToPlaneIcp::default();
    assert!(matches!(
        icp.prepare_source(&PointCloud::new()),
        Err(RegistrationError::TooFewPoints { .. })
    ));
    let nan = PointCloud::from_points(vec![Point3::new(f32::NAN, 0.0, 0.0); 500]);
    assert!(matches!(
        icp.prepare_target(&nan),
        Err(RegistrationError::TooFewPoints { .. })
    ));
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
        Err(e) => assert!(matches!(e, RegistrationError::Degenerate(_))),
    }
    let bad = Pose3::translation(f64::NAN, 0.0, 0.0);
    assert!(matches!(
        icp.align(&src, &tgt, &bad),
        Err(RegistrationError::NonFiniteInitialGuess)
    ));
}

/// Three consecutive OS1-128 frames at 2.5 m/s: each frame-to-frame step within 5 cm and 0.2
/// degrees of the shipped reference poses (themselves an estimate; eight other ICP variants agree
/// with them to 0.7-3.8 cm).
#[test]
fn os1_128_steps_match_the_reference_poses() {
    let poses =
        slam_core::io::read_kitti_poses(here("../slam-core/tests/data/os1_128_poses_kitti.txt"))
            .unwrap();
    let frames = [
        here("../slam-core/tests/data/os1_128_frame_00_fid1795.pcd"),
        here("tests/data/os1_128_frame_01_fid1796.pcd"),
        here("tests/data/os1_128_frame_02_fid1797.pcd"),
    ]
    .map(|p| slam_core::io::read_pcd(p).unwrap());
    let icp = PointToPlaneIcp::default();
    for k in 0..2 {
        let reference = poses[k].inverse() * poses[k + 1];
        let estimate = run(&icp, &frames[k + 1], &frames[k], &Pose3::identity());
        let (rot, trans) = error(&reference, &estimate);
        assert!(rot < 0.2 && trans < 0.05, "step {k}: {rot} deg, {trans} m");
    }
}
