//! LOAM on real scans: known transforms between random halves of an HDL-32E scan, the reference
//! pose of the HDL-32E pair, the OS1-128 reference steps, zero drift on a static sequence, and
//! degenerate input.
#![allow(clippy::unwrap_used)]

use crate::common::{error, garage_frames, here, os1_128, random_halves, reference, target_scan};
use registration::{LidarLayout, LoamConfig, LoamFeatures, LoamRegistrator};
use slam_core::io::read_ply;
use slam_core::{
    InvalidSetting, PointCloud, Pose3, RegistrationError, Registrator, pose3_from_xyz_rpy,
};

fn hdl32e() -> LoamRegistrator {
    let mut config = LoamConfig::default();
    config.features.layout = LidarLayout::HDL32E;
    // Starts up to a metre and 10 degrees off.
    config.initial_tukey_threshold = 1.0;
    LoamRegistrator { config }
}

fn run(r: &LoamRegistrator, source: &PointCloud, target: &PointCloud, initial: &Pose3) -> Pose3 {
    let a = r
        .align(
            &r.prepare_source(source).unwrap(),
            &r.prepare_target(target).unwrap(),
            initial,
        )
        .unwrap();
    assert!(a.converged, "did not converge: {a:?}");
    assert!(
        a.inlier_ratio > 0.3 && a.rmse.is_finite() && a.min_eigenvalue_ratio > 1e-4,
        "{a:?}"
    );
    a.pose
}

#[test]
fn features_of_a_real_scan() {
    if slam_core::skip_without_test_data!("tests/data", "../slam-core/tests/data") {
        return;
    }
    let f = LoamFeatures::extract(&target_scan(), &hdl32e().config.features).unwrap();
    // 32 rings x 6 sectors x (20 + 40) is the cap.
    assert!(
        f.edges.len() > 200 && f.edges.len() <= 32 * 6 * 20,
        "{} edges",
        f.edges.len()
    );
    assert!(
        f.planes.len() > 2000 && f.planes.len() <= 32 * 6 * 40,
        "{} planes",
        f.planes.len()
    );
    // Ring order must not matter: the same features from a shuffled cloud.
    let scan = target_scan();
    let mut idx: Vec<usize> = (0..scan.len()).collect();
    idx.reverse();
    idx.rotate_left(12_345);
    let g = LoamFeatures::extract(&scan.select(&idx), &hdl32e().config.features).unwrap();
    assert_eq!(f.edges.len(), g.edges.len());
    assert_eq!(f.planes.len(), g.planes.len());
}

#[test]
fn random_halves_of_a_real_scan() {
    if slam_core::skip_without_test_data!("tests/data", "../slam-core/tests/data") {
        return;
    }
    let (source, target, truth) = random_halves();
    let (rot, trans) = error(
        &truth,
        &run(&hdl32e(), &source, &target, &Pose3::identity()),
    );
    eprintln!("halves: {rot:.4} deg, {:.2} mm", trans * 1e3);
    assert!(rot < 0.05 && trans < 0.005, "LOAM: {rot} deg, {trans} m");
}

#[test]
fn hdl32e_pair_matches_the_reference() {
    if slam_core::skip_without_test_data!("tests/data", "../slam-core/tests/data") {
        return;
    }
    let source = read_ply(here("tests/data/source.ply")).unwrap();
    let target = target_scan();
    let reference = reference();
    let off = reference * pose3_from_xyz_rpy(0.8, -0.6, 0.0, 0.0, 0.0, 10f64.to_radians());
    for initial in [Pose3::identity(), off] {
        let (rot, trans) = error(&reference, &run(&hdl32e(), &source, &target, &initial));
        eprintln!("pair: {rot:.3} deg, {:.2} cm", trans * 100.0);
        assert!(rot < 0.3 && trans < 0.03, "LOAM: {rot} deg, {trans} m");
    }
}

#[test]
fn os1_128_steps_match_the_reference_poses() {
    if slam_core::skip_without_test_data!("tests/data", "../slam-core/tests/data") {
        return;
    }
    let (frames, poses) = os1_128();
    let loam = LoamRegistrator::default();
    for k in 0..2 {
        let reference = poses[k].inverse() * poses[k + 1];
        let estimate = run(&loam, &frames[k + 1], &frames[k], &Pose3::identity());
        let (rot, trans) = error(&reference, &estimate);
        eprintln!("OS1-128 step {k}: {rot:.3} deg, {:.2} cm", trans * 100.0);
        assert!(rot < 0.2 && trans < 0.05, "step {k}: {rot} deg, {trans} m");
    }
}

/// The garage sensor did not move: frame-to-frame odometry over the sequence must end where it
/// started.
#[test]
fn static_garage_sequence_does_not_drift() {
    let frames = garage_frames();
    let loam = LoamRegistrator::default();
    let prepared: Vec<_> = frames
        .iter()
        .map(|f| loam.prepare_source(f).unwrap())
        .collect();
    let mut pose = Pose3::identity();
    for k in 1..frames.len() {
        let target = loam.prepare_target(&frames[k - 1]).unwrap();
        let a = loam
            .align(&prepared[k], &target, &Pose3::identity())
            .unwrap();
        pose *= a.pose;
    }
    let (rot, trans) = error(&Pose3::identity(), &pose);
    eprintln!(
        "{} frames: end {rot:.4} deg, {:.2} cm",
        frames.len(),
        trans * 100.0
    );
    assert!(
        rot < 0.2 && trans < 0.02,
        "{} frames: {rot} deg, {trans} m",
        frames.len()
    );
}

#[test]
fn degenerate_input_is_an_error_or_flagged() {
    if slam_core::skip_without_test_data!("tests/data", "../slam-core/tests/data") {
        return;
    }
    let loam = LoamRegistrator::default();
    crate::common::rejects_empty_and_nan(&loam);
    let mut bad = loam;
    bad.config.tukey_threshold = -1.0;
    assert!(matches!(
        bad.prepare_target(&target_scan()),
        Err(RegistrationError::InvalidConfig(InvalidSetting {
            setting: "LoamConfig::tukey_threshold",
            ..
        }))
    ));
    let source = loam.prepare_source(&target_scan()).unwrap();
    let target = loam.prepare_target(&target_scan()).unwrap();
    assert!(matches!(
        loam.align(&source, &target, &Pose3::translation(f64::NAN, 0.0, 0.0)),
        Err(RegistrationError::NonFiniteInitialGuess)
    ));
}
