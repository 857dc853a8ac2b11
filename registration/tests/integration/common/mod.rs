//! Data shared by the registration tests: the bundled real scans, the reference pose and a
//! pose-error measure.
#![allow(clippy::unwrap_used, dead_code)]

use std::path::PathBuf;

use nalgebra::{Matrix4, UnitQuaternion};
use slam_core::io::read_ply;
use slam_core::{PointCloud, Pose3, pose3_from_xyz_rpy};

pub fn here(p: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(p)
}

pub fn target_scan() -> PointCloud {
    read_ply(here("../slam-core/tests/data/hdl32e_pair_target.ply")).unwrap()
}

/// `small_gicp`'s reference `target_T_source` for the HDL-32E pair.
pub fn reference() -> Pose3 {
    reference_from("tests/data/T_target_source.txt")
}

/// `fast_gicp`'s reference for the same pair (0.23 degrees and 1.9 cm from `small_gicp`'s).
pub fn fast_gicp_reference() -> Pose3 {
    reference_from("tests/data/fast_gicp_T_target_source.txt")
}

fn reference_from(path: &str) -> Pose3 {
    let txt = std::fs::read_to_string(here(path)).unwrap();
    let v: Vec<f64> = txt.split_whitespace().map(|s| s.parse().unwrap()).collect();
    let m = Matrix4::from_row_slice(&v);
    Pose3::from_parts(
        m.fixed_view::<3, 1>(0, 3).into_owned().into(),
        UnitQuaternion::from_matrix(&m.fixed_view::<3, 3>(0, 0).into_owned()),
    )
}

/// Rotation (degrees) and translation (metres) between two poses.
pub fn error(a: &Pose3, b: &Pose3) -> (f64, f64) {
    let e = a.inverse() * b;
    (e.rotation.angle().to_degrees(), e.translation.vector.norm())
}

/// A real scan split into two random halves (not even/odd: the lasers interleave), the source
/// half moved by a known transform: (source, target, `target_T_source`).
pub fn random_halves() -> (PointCloud, PointCloud, Pose3) {
    let truth = pose3_from_xyz_rpy(0.4, -0.25, 0.1, 0.03, -0.05, 10f64.to_radians());
    let (source, target) = random_halves_with(0x1234_5678_9ABC_DEF1, &truth);
    (source, target, truth)
}

/// The scan split by coin flips from `seed` (xorshift, not 0), the source half moved by
/// `truth` (`target_T_source`): (source, target).
pub fn random_halves_with(seed: u64, truth: &Pose3) -> (PointCloud, PointCloud) {
    let scan = target_scan();
    let mut s = seed;
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
    (
        PointCloud::from_points(b).transformed(&truth.inverse()),
        PointCloud::from_points(a),
    )
}

/// The three OS1-128 frames and their reference poses (frame 0 at the identity).
pub fn os1_128() -> ([PointCloud; 3], Vec<Pose3>) {
    let poses =
        slam_core::io::read_kitti_poses(here("../slam-core/tests/data/os1_128_poses_kitti.txt"))
            .unwrap();
    let frames = [
        here("../slam-core/tests/data/os1_128_frame_00_fid1795.pcd"),
        here("tests/data/os1_128_frame_01_fid1796.pcd"),
        here("tests/data/os1_128_frame_02_fid1797.pcd"),
    ]
    .map(|p| slam_core::io::read_pcd(p).unwrap());
    (frames, poses)
}

/// The static HDL-32E garage sequence: all 30 frames from the shared data set when it is
/// present (`SPOT_NAV_DATA`, default `../shared/data`), else the first 10 bundled in
/// `tests/data/hdl32e_garage`.
pub fn garage_frames() -> Vec<PointCloud> {
    let root =
        std::env::var_os("SPOT_NAV_DATA").map_or_else(|| here("../../shared/data"), PathBuf::from);
    let shared = root.join("lidar/hdl32e_garage_seq");
    let dir = if shared.is_dir() {
        shared
    } else {
        eprintln!(
            "{} is absent: using the 10 bundled garage frames",
            shared.display()
        );
        here("tests/data/hdl32e_garage")
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "pcd"))
        .collect();
    files.sort();
    files
        .iter()
        .map(|p| slam_core::io::read_pcd(p).unwrap())
        .collect()
}

/// An empty source and an all-NaN target are `TooFewPoints` errors, never a panic.
pub fn rejects_empty_and_nan<R: slam_core::Registrator>(r: &R) {
    use slam_core::RegistrationError;
    assert!(matches!(
        r.prepare_source(&PointCloud::new()),
        Err(RegistrationError::TooFewPoints { .. })
    ));
    let nan = PointCloud::from_points(vec![nalgebra::Point3::new(f32::NAN, 0.0, 0.0); 5000]);
    assert!(matches!(
        r.prepare_target(&nan),
        Err(RegistrationError::TooFewPoints { .. })
    ));
}
