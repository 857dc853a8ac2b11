//! Tests of `target.rs`.

use super::*;

#[test]
fn normals_up_front_equal_the_normals_computed_on_first_use() {
    // A box's faces and a tilted plane, with a little jitter.
    let mut points = Vec::new();
    for i in 0..40 {
        for j in 0..40 {
            let (a, b) = (f64::from(i) * 0.05, f64::from(j) * 0.05);
            let jitter = 0.002 * f64::from((i * 7 + j * 13) % 5);
            points.push(Point3::new(a, b, jitter));
            points.push(Point3::new(a, jitter, b));
            points.push(Point3::new(3.0 + jitter, a, b + 0.3 * a));
        }
    }
    let lazy = TargetIndex::new(points.clone(), Some((10, 0.0)), 3).unwrap();
    let eager = TargetIndex::new(points, Some((10, 0.0)), 3).unwrap();
    eager.compute_all_normals();
    let cache = eager.normals.as_ref().unwrap();
    assert!(cache.cells.iter().all(|c| c.get().is_some()));
    for i in 0..lazy.points.len() {
        assert_eq!(lazy.normal(i), eager.normal(i), "point {i}");
    }
    // A wall's normal is its axis (either sign).
    assert!(lazy.normal((20 * 40 + 20) * 3 + 1).unwrap().y.abs() > 0.99);
}

#[test]
fn only_plane_like_neighbourhoods_get_a_normal_with_min_planarity() {
    // A floor patch, and far from it a row of points along x (one LiDAR ring thinned to
    // a voxel row): the row's covariance has one large eigenvalue, its normal any
    // direction across x.
    let mut points = Vec::new();
    for i in 0..20 {
        for j in 0..20 {
            points.push(Point3::new(f64::from(i) * 0.1, f64::from(j) * 0.1, 0.0));
        }
    }
    let row = points.len();
    for i in 0..20 {
        let wobble = 0.002 * f64::from(i % 3);
        points.push(Point3::new(f64::from(i) * 0.25, 10.0 + wobble, 0.0));
    }
    let every = TargetIndex::new(points.clone(), Some((10, 0.0)), 3).unwrap();
    let planes = TargetIndex::new(points, Some((10, 0.2)), 3).unwrap();
    for i in 0..row {
        let n = planes.normal(i).expect("a floor point has a normal");
        assert!(n.z.abs() > 0.999, "{n:?}");
        assert_eq!(every.normal(i), planes.normal(i));
    }
    for i in row..row + 20 {
        assert!(every.normal(i).is_some());
        assert_eq!(planes.normal(i), None, "row point {i}");
        assert_eq!(planes.pairing_normal(i), None, "row point {i}");
    }
}

/// An in-place local map slid over keyframes aligns a scan to the pose a map built whole
/// from the same keyframes gives, and an empty one refuses to align with a named error.
fn in_place_aligns_as_whole<R>(icp: &R)
where
    R: slam_core::MapRegistrator<Source = Vec<Point3<f64>>, Target = PreparedTarget>,
{
    // A room: floor, two walls and a box, sampled every 5 cm.
    let mut room = Vec::new();
    for i in 0..80 {
        for j in 0..60 {
            let (a, b) = (f64::from(i) * 0.05, f64::from(j) * 0.05);
            room.push(Point3::new(a, b, 0.0));
            room.push(Point3::new(a, 0.0, b * 0.5));
            room.push(Point3::new(0.0, b, a * 0.3));
            if i < 10 && j < 10 {
                room.push(Point3::new(2.0 + a, 1.5, b));
            }
        }
    }
    let empty = icp.empty_map().unwrap();
    assert!(empty.is_empty());
    assert!(matches!(
        empty.index(),
        Err(RegistrationError::TooFewPoints {
            what: "target",
            points: 0,
            ..
        })
    ));
    let cloud = PointCloud::from_points(room.iter().map(|p| p.cast::<f32>()).collect());
    let source = icp.prepare_source(&cloud).unwrap();
    let poses: Vec<Pose3> = (0..5)
        .map(|k| {
            Pose3::new(
                nalgebra::Vector3::new(0.02 * f64::from(k), 0.0, 0.0),
                nalgebra::Vector3::zeros(),
            )
        })
        .collect();
    let mut in_place = empty;
    let guess = Pose3::new(
        nalgebra::Vector3::new(0.1, -0.05, 0.03),
        nalgebra::Vector3::new(0.0, 0.0, 0.03),
    );
    for (k, pose) in (0u32..).zip(&poses) {
        icp.add_to_map(&mut in_place, k, &source, pose);
        if let Some(old) = k.checked_sub(3) {
            icp.remove_from_map(&mut in_place, old);
        }
        // Aligned after every change: each query sees the map as it is now.
        let first = k.saturating_sub(2) as usize;
        let parts: Vec<_> = poses[first..=k as usize]
            .iter()
            .map(|p| (&source, *p))
            .collect();
        let whole = icp.target_from_sources(&parts).unwrap();
        assert_eq!(in_place.len(), whole.len(), "keyframe {k}");
        let a = icp.align(&source, &in_place, &guess).unwrap();
        let b = icp.align(&source, &whole, &guess).unwrap();
        let apart = a.pose.inverse() * b.pose;
        assert!(
            apart.translation.vector.norm() < 1e-4,
            "keyframe {k}: {apart:?}"
        );
        assert!(apart.rotation.angle() < 1e-4, "keyframe {k}: {apart:?}");
    }
}

#[test]
fn an_in_place_map_aligns_as_the_map_built_whole() {
    in_place_aligns_as_whole(&crate::PointToPlaneIcp::default());
    in_place_aligns_as_whole(&crate::PointToPointIcp::default());
}

#[test]
fn a_map_readied_beside_other_work_aligns_as_one_indexed_on_first_use() {
    use slam_core::{MapRegistrator, Registrator};
    let icp = crate::PointToPlaneIcp::default();
    let room = room_with(&[]);
    let source = icp.prepare_source(&room).unwrap();
    let (mut readied, mut lazy) = (icp.empty_map().unwrap(), icp.empty_map().unwrap());
    let guess = Pose3::new(
        nalgebra::Vector3::new(0.08, -0.04, 0.02),
        nalgebra::Vector3::new(0.0, 0.0, 0.02),
    );
    let mut ran = 0;
    for k in 0u32..4 {
        let pose = Pose3::translation(0.03 * f64::from(k), 0.0, 0.0);
        for map in [&mut readied, &mut lazy] {
            icp.add_to_map(map, k, &source, &pose);
            if let Some(old) = k.checked_sub(2) {
                icp.remove_from_map(map, old);
            }
        }
        assert!(readied.index.get().is_none(), "a change drops the index");
        icp.ready_map_beside(&mut readied, &mut || ran += 1);
        assert!(matches!(readied.index.get(), Some(Ok(_))), "keyframe {k}");
        // Ready already: the work runs all the same.
        icp.ready_map_beside(&mut readied, &mut || ran += 1);
        assert!(lazy.index.get().is_none());
        let a = icp.align(&source, &readied, &guess).unwrap();
        let b = icp.align(&source, &lazy, &guess).unwrap();
        assert_eq!(a, b, "keyframe {k}");
    }
    assert_eq!(ran, 8, "the work beside ran once a call");
}

/// A map indexed ahead on another thread aligns every scan exactly as one indexed on its first
/// query, keyframe after keyframe (the normals each index keeps for the next included), and an
/// index built ahead for a window that changes before any query is dropped unused.
#[test]
fn a_map_indexed_ahead_aligns_as_one_indexed_on_first_use() {
    use slam_core::{MapRegistrator, Registrator};
    let icp = crate::PointToPlaneIcp::default();
    let room = room_with(&[]);
    let source = icp.prepare_source(&room).unwrap();
    let (mut ahead, mut lazy) = (icp.empty_map().unwrap(), icp.empty_map().unwrap());
    let guess = Pose3::new(
        nalgebra::Vector3::new(0.08, -0.04, 0.02),
        nalgebra::Vector3::new(0.0, 0.0, 0.02),
    );
    let mut ran = 0;
    for k in 0u32..12 {
        let pose = Pose3::new(
            nalgebra::Vector3::new(0.03 * f64::from(k), 0.01 * f64::from(k % 3), 0.0),
            nalgebra::Vector3::new(0.0, 0.0, 0.003 * f64::from(k % 4)),
        );
        for map in [&mut ahead, &mut lazy] {
            icp.add_to_map(map, k, &source, &pose);
            if let Some(old) = k.checked_sub(3) {
                icp.remove_from_map(map, old);
            }
        }
        icp.ready_map_ahead(&mut ahead);
        if k % 4 == 1 {
            // Changed again before any query: the index under way is dropped, the next one
            // built for the map as it is then; the lazy twin sees the same changes.
            assert!(ahead.pending.get_mut().is_some(), "keyframe {k}");
            for map in [&mut ahead, &mut lazy] {
                icp.remove_from_map(map, k);
                icp.add_to_map(map, k, &source, &pose);
            }
            assert!(ahead.pending.get_mut().is_none(), "keyframe {k}: dropped");
            icp.ready_map_ahead(&mut ahead);
        }
        if k % 2 == 0 {
            icp.ready_map_beside(&mut ahead, &mut || ran += 1);
            assert!(matches!(ahead.index.get(), Some(Ok(_))), "keyframe {k}");
            assert!(ahead.pending.get_mut().is_none(), "keyframe {k}: claimed");
        }
        let a = icp.align(&source, &ahead, &guess).unwrap();
        let b = icp.align(&source, &lazy, &guess).unwrap();
        assert_eq!(a, b, "keyframe {k}");
    }
    assert_eq!(ran, 6, "the work beside ran once a call");
    // A target prepared whole has nothing to build.
    let mut whole = icp
        .target_from_sources(&[(&source, Pose3::identity())])
        .unwrap();
    icp.ready_map_ahead(&mut whole);
    assert!(whole.pending.get_mut().is_none());
}

#[test]
fn without_a_target_voxel_the_map_is_built_whole() {
    use slam_core::MapRegistrator;
    let mut icp = crate::PointToPlaneIcp::default();
    icp.config.target_voxel = 0.0;
    assert!(icp.empty_map().is_none());
    icp.config.target_voxel = f32::NAN;
    assert!(icp.empty_map().is_none());
}

/// A room's points, plus `extra`.
fn room_with(extra: &[Point3<f32>]) -> PointCloud {
    let mut room = Vec::new();
    for i in 0..80 {
        for j in 0..60 {
            let (a, b) = (i as f32 * 0.05, j as f32 * 0.05);
            room.push(Point3::new(a, b, 0.0));
            room.push(Point3::new(a, 0.0, b * 0.5));
            room.push(Point3::new(0.0, b, a * 0.3));
            if i < 10 && j < 10 {
                room.push(Point3::new(2.0 + a, 1.5, b));
            }
        }
    }
    room.extend_from_slice(extra);
    PointCloud::from_points(room)
}

#[test]
fn one_absurd_point_leaves_a_scan_registering_as_without_it() {
    use slam_core::Registrator;
    // A return a driver garbled into 1e30 m, one far-away point in a real range (1e5 m)
    // and one at 1e12 m (beyond any voxel key at 1 nm, but finite).
    let absurd = [
        Point3::new(1e30, 0.0, 0.0),
        Point3::new(0.0, -1e5, 3.0),
        Point3::new(2e12, 1.0, 1.0),
    ];
    let guess = Pose3::new(
        nalgebra::Vector3::new(0.1, -0.05, 0.03),
        nalgebra::Vector3::new(0.0, 0.0, 0.03),
    );
    for icp in [
        crate::PointToPlaneIcp::default(),
        crate::PointToPlaneIcp {
            config: IcpConfig {
                source_voxel: 0.0,
                target_voxel: 0.0,
                ..IcpConfig::default()
            },
        },
    ] {
        let clean = room_with(&[]);
        let dirty = room_with(&absurd);
        let want = icp
            .align(
                &icp.prepare_source(&clean).unwrap(),
                &icp.prepare_target(&clean).unwrap(),
                &guess,
            )
            .unwrap();
        let source = icp.prepare_source(&dirty).unwrap();
        let target = icp.prepare_target(&dirty).unwrap_or_else(|e| panic!("{e}"));
        let got = icp.align(&source, &target, &guess).unwrap();
        let apart = want.pose.inverse() * got.pose;
        assert!(apart.translation.vector.norm() < 1e-6, "{apart:?}");
        assert!(apart.rotation.angle() < 1e-6, "{apart:?}");
    }
}

/// Normals kept from one index of an in-place map for the next agree with the normals the
/// current centroids give (computed afresh on an index of the same points), are recomputed
/// after `MAX_NORMAL_REUSE` indexes, and are not reused for a voxel whose points doubled.
#[test]
fn kept_normals_agree_with_fresh_ones_and_expire() {
    use crate::voxel_window::MAX_NORMAL_REUSE;
    use slam_core::{MapRegistrator, Registrator};
    let icp = crate::PointToPlaneIcp::default();
    // A room: floor and two walls, every 5 cm.
    let mut room = Vec::new();
    for i in 0..60 {
        for j in 0..40 {
            let (a, b) = (f64::from(i) * 0.05, f64::from(j) * 0.05);
            room.push(Point3::new(a, b, 0.0));
            room.push(Point3::new(a, 0.0, b * 0.5));
            room.push(Point3::new(0.0, b, a * 0.3));
        }
    }
    let cloud = PointCloud::from_points(room.iter().map(|p| p.cast::<f32>()).collect());
    let source = icp.prepare_source(&cloud).unwrap();
    let mut map = icp.empty_map().unwrap();
    let mut reused_seen = 0;
    let mut inside = 0;
    for k in 0u32..(2 * MAX_NORMAL_REUSE + 4) {
        // Keyframes a few centimetres apart, three in the window.
        let pose = Pose3::new(
            nalgebra::Vector3::new(0.013 * f64::from(k), 0.007 * f64::from(k % 3), 0.0),
            nalgebra::Vector3::new(0.0, 0.0, 0.002 * f64::from(k % 4)),
        );
        icp.add_to_map(&mut map, k, &source, &pose);
        if let Some(old) = k.checked_sub(3) {
            icp.remove_from_map(&mut map, old);
        }
        let window = map.window.as_ref().unwrap();
        let kept = window.voxels.snapshot().kept;
        let index = map.index().unwrap();
        let fresh = TargetIndex::new(index.points.clone(), Some((10, 0.0)), 3).unwrap();
        for (i, kept) in kept.iter().enumerate() {
            let Some(kept) = kept else { continue };
            reused_seen += 1;
            assert!(kept.reused < MAX_NORMAL_REUSE, "keyframe {k}: {kept:?}");
            assert_eq!(
                index.normal(i),
                kept.normal,
                "a kept normal is the one used"
            );
            let (Some(a), Some(b)) = (kept.normal, fresh.normal(i)) else {
                panic!("keyframe {k}, point {i}: a plane's normal is missing");
            };
            // Inside a face (a fresh normal within 2 degrees of an axis; at an edge the ten
            // neighbours mix two faces and any normal between them is as good), the kept
            // normal is within 3 degrees of the fresh one, either sign.
            if b.amax() > 2f64.to_radians().cos() {
                assert!(a.dot(&b).abs() > 3f64.to_radians().cos(), "{a:?} vs {b:?}");
                inside += 1;
            }
        }
        // Every normal used, as an alignment against a map touches most of them.
        index.compute_all_normals();
    }
    assert!(
        reused_seen > 1000 && inside * 2 > reused_seen,
        "normals were reused: {reused_seen}, {inside} inside a face"
    );
    // A voxel whose points more than doubled since its normal was computed gets a fresh one.
    let mut map = icp.empty_map().unwrap();
    let at = Pose3::identity();
    icp.add_to_map(&mut map, 0, &source, &at);
    map.index().unwrap().compute_all_normals();
    icp.add_to_map(&mut map, 1, &source, &at);
    let kept = map.window.as_ref().unwrap().voxels.snapshot().kept;
    assert!(kept.iter().all(Option::is_some), "twice the points: kept");
    icp.add_to_map(&mut map, 2, &source, &at);
    let kept = map.window.as_ref().unwrap().voxels.snapshot().kept;
    assert!(
        kept.iter().all(Option::is_none),
        "three times: computed afresh"
    );
}
