use super::*;
use crate::nav::config::NavigatorConfig;
use gridmap::CellState;
use nalgebra::{Translation3, UnitQuaternion, Vector3};
use slam_core::Cell;

type Error = ExplorationError<std::io::Error>;

/// A scan of a corridor 2 m wide along x with walls 2.5 m high, seen from x = `at` (the LiDAR
/// 0.6 m above the floor): wall points at all heights, floor points, in the LiDAR frame.
fn corridor_scan(at: f64) -> (Pose3, PointCloud) {
    let mut points = Vec::new();
    for i in 0..120 {
        let x = -3.0 + 0.05 * f64::from(i);
        for k in 0..10 {
            let z = 0.25 * f64::from(k);
            points.push(Point3::new(x as f32, 1.0, (z - 0.6) as f32));
            points.push(Point3::new(x as f32, -1.0, (z - 0.6) as f32));
        }
        for k in 0..7 {
            let y = -0.9 + 0.3 * f64::from(k);
            points.push(Point3::new(x as f32, y as f32, -0.6));
        }
    }
    (
        Pose3::translation(at, 0.0, 0.6),
        PointCloud::from_points(points),
    )
}

fn map() -> GrowingMap {
    GrowingMap::new(NavigatorConfig::default().map_config(), 0.6, 1.0, 0.1, 4.0)
}

fn refs(scans: &[(Pose3, PointCloud)]) -> Vec<(Pose3, &PointCloud)> {
    scans.iter().map(|(p, c)| (*p, c)).collect()
}

/// `scans` added one at a time to 0.1 m centroids, and the oracle: the scans merged and thinned
/// at once by [`PointCloud::voxel_downsample`].
fn grown_and_thinned(scans: &[(Pose3, PointCloud)]) -> (VoxelCentroids, PointCloud) {
    let mut grown = VoxelCentroids::new(0.1);
    for (pose, cloud) in scans {
        grown.add(&[(*pose, cloud.points())]).unwrap();
    }
    let mut merged = PointCloud::new();
    for (pose, cloud) in scans {
        merged.extend_from(&cloud.transformed(pose)).unwrap();
    }
    (grown, merged.voxel_downsample(0.1).unwrap())
}

/// The map cloud grown scan by scan is the scans merged and thinned at once.
#[test]
fn centroids_grown_scan_by_scan_are_the_merged_scans_thinned() {
    let scans: Vec<_> = (0..5).map(|k| corridor_scan(0.7 * f64::from(k))).collect();
    let (grown, want) = grown_and_thinned(&scans);
    let got = grown.cloud();
    assert_eq!(got.len(), want.len());
    for (g, w) in got.points().iter().zip(want.points()) {
        assert!((g - w).norm() < 1e-5, "{g} vs {w}");
    }
    assert!(
        VoxelCentroids::new(f32::NAN)
            .add(&[(scans[0].0, scans[0].1.points())])
            .is_err()
    );
}

/// Voxels whose keys do not pack (beyond 2^20 voxels on an axis, in either direction) keep
/// their own centroids beside the packed ones: the cloud is still the merged scans thinned by
/// [`PointCloud::voxel_downsample`] (the oracle, with its own keys), non-finite points skipped.
#[test]
fn centroids_far_out_and_near_are_the_merged_scans_thinned() {
    // 2^20 voxels of 0.1 m are 104,858 m: points at ±105 km and beyond take the other map.
    let offsets = [0.0f32, 104_000.0, -104_800.0, 105_000.0, -106_000.0, 3.0e6];
    let scans: Vec<(Pose3, PointCloud)> = (0..4)
        .map(|k| {
            let mut points = Vec::new();
            for (j, &far) in offsets.iter().enumerate() {
                for i in 0..50 {
                    let f = (i + 7 * k) as f32;
                    let p = Point3::new(far + (f * 0.37).sin(), (f * 0.11).cos() * 0.5, 0.02 * f);
                    // The same place seen along each axis.
                    points.push([p, p.yzx(), p.zxy()][j % 3]);
                }
            }
            points.push(Point3::new(f32::NAN, 0.0, 0.0));
            points.push(Point3::new(0.0, f32::INFINITY, 0.0));
            let pose = Pose3::translation(0.05 * f64::from(k), -0.03 * f64::from(k), 0.0);
            (pose, PointCloud::from_points(points))
        })
        .collect();
    let (grown, want) = grown_and_thinned(&scans);
    assert!(!grown.far.is_empty() && !grown.index.is_empty());
    let got = grown.cloud();
    assert_eq!(got.len(), want.len());
    for (g, w) in got.points().iter().zip(want.points()) {
        let scale = w.coords.amax().max(1.0);
        assert!((g - w).amax() <= 1e-6 * scale, "{g} vs {w}");
    }
}

/// Keys pack 21 bits an axis within 2^20 voxels of the origin, and no farther.
#[test]
fn voxel_keys_pack_within_two_to_the_twenty() {
    let edge = 1i64 << 20;
    assert_eq!(
        packed([0, 0, 0]),
        Some((edge as u64) << 42 | (edge as u64) << 21 | edge as u64)
    );
    assert!(packed([-edge, edge - 1, 0]).is_some());
    for bad in [
        [edge, 0, 0],
        [0, -edge - 1, 0],
        [0, 0, i64::MAX],
        [i64::MIN, 0, 0],
    ] {
        assert_eq!(packed(bad), None, "{bad:?}");
    }
    let a = packed([-edge, 5, edge - 1]);
    assert_ne!(a, packed([-edge, 6, edge - 1]));
    assert_ne!(a, packed([edge - 1, 5, -edge]));
}

/// Keyframes walked along the corridor: one a square of 1 m and the newest are rendered, only
/// the new ones at each update; the grid is the one all of them give at once; a keyframe moved
/// by more than half a cell, or a map grown by half, is rendered afresh.
#[test]
fn the_map_grows_by_its_new_keyframes_and_is_rendered_afresh_when_they_move() {
    // Keyframes every 0.25 m: four a square.
    let scans: Vec<_> = (0..40)
        .map(|k| corridor_scan(0.25 * f64::from(k)))
        .collect();
    let mut m = map();
    let first = m
        .update_from::<std::io::Error>(&refs(&scans[..24])[..])
        .unwrap();
    assert_eq!(m.full_renders(), 1);
    // Squares 0-5 (keyframes 0, 4, ..., 20) and the newest (23).
    assert_eq!(
        m.rendered.iter().map(|r| r.0).collect::<Vec<_>>(),
        [0, 4, 8, 12, 16, 20, 23]
    );
    let second = m
        .update_from::<std::io::Error>(&refs(&scans[..28])[..])
        .unwrap();
    let cloud = m.cloud_within(Vector2::zeros(), f64::INFINITY);
    assert_eq!(
        m.full_renders(),
        1,
        "grown by two: added, not rendered afresh"
    );
    assert_eq!(
        m.rendered.iter().map(|r| r.0).collect::<Vec<_>>(),
        [0, 4, 8, 12, 16, 20, 23, 24, 27]
    );
    // The grid of every rendered keyframe added at once over the same floor.
    let rendered: Vec<(Pose3, &PointCloud)> = m
        .rendered
        .iter()
        .map(|&(k, _)| (scans[k].0, &scans[k].1))
        .collect();
    let mut all = FloorBandAccumulator::new(
        m.config.grid.clone(),
        first.floor().clone(),
        m.config.band.clone(),
    )
    .unwrap();
    all.add_scans(&rendered).unwrap();
    let want = all.grid().unwrap();
    assert_eq!(second.occupancy().geometry(), want.geometry());
    let (mut same, mut other) = (0, 0);
    for y in 0..want.height() {
        for x in 0..want.width() {
            let c = Cell::new(x, y);
            let (g, w) = (second.occupancy().state(c), want.state(c));
            if g == w {
                same += 1;
            } else {
                // Only a beam above the band beyond the grid of its time may be missing.
                assert_eq!((w, g), (CellState::Free, CellState::Unknown), "cell {c:?}");
                other += 1;
            }
        }
    }
    assert!(other * 100 <= same, "{other} of {same}");
    assert!(second.occupancy().counts().1 > 100);
    assert!(!cloud.is_empty());
    // A keyframe moved by 2 cm (a fifth of a cell): kept as rendered.
    let mut moved = scans.clone();
    moved[4].0 = Pose3::from_parts(Translation3::new(1.02, 0.0, 0.6), moved[4].0.rotation);
    m.update_from::<std::io::Error>(&refs(&moved[..29])[..])
        .unwrap();
    assert_eq!(m.full_renders(), 1);
    // Turned by 1 degree: a point 4 m out moves 7 cm, more than half a cell.
    moved[4].0.rotation = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 1f64.to_radians());
    m.update_from::<std::io::Error>(&refs(&moved[..30])[..])
        .unwrap();
    assert_eq!(m.full_renders(), 2);
    assert_eq!(
        m.rendered.iter().find(|r| r.0 == 4).map(|r| r.1),
        Some(moved[4].0)
    );
    // Grown by half since that render: the floor is estimated again.
    let before = m.rendered.len();
    let mut k = 30;
    while m.full_renders() == 2 && k < moved.len() {
        k += 1;
        m.update_from::<std::io::Error>(&refs(&moved[..k])[..])
            .unwrap();
    }
    assert_eq!(m.full_renders(), 3);
    assert!(m.rendered.len() <= before + before.div_ceil(2) + 1);
}

/// A full render read in batches (here of two keyframes' points) gives the floor, the grid and
/// the cloud of one read at once, and those of the oracles: the floor estimated from every
/// rendered scan, the builder's one-shot grid over it and the centroids of every scan added in
/// order.
#[test]
fn a_render_in_batches_is_the_render_of_every_keyframe_at_once() {
    // Keyframes every 0.3 m along the corridor, turning a little: 14 rendered, one a square.
    let scans: Vec<(Pose3, PointCloud)> = (0..45)
        .map(|k| {
            let (pose, cloud) = corridor_scan(0.3 * f64::from(k));
            let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.002 * f64::from(k));
            (Pose3::from_parts(pose.translation, turn), cloud)
        })
        .collect();
    let render = |batch_points: usize| {
        let mut m = map();
        m.batch_points = batch_points;
        let navigation = m.update_from::<std::io::Error>(&refs(&scans)[..]).unwrap();
        assert_eq!(m.full_renders(), 1);
        (m, navigation)
    };
    let (whole, at_once) = render(BLOCK_POINTS);
    let (batched, in_batches) = render(2 * scans[0].1.len());
    assert_eq!(whole.rendered, batched.rendered);
    assert_eq!(whole.rendered.len(), 14);
    assert_eq!(in_batches.floor(), at_once.floor());
    assert_eq!(in_batches.occupancy(), at_once.occupancy());
    assert_eq!(batched.cloud.cloud().points(), whole.cloud.cloud().points());
    // The oracles, from the rendered scans.
    let rendered: Vec<(Pose3, &PointCloud)> = whole
        .rendered
        .iter()
        .map(|&(k, _)| (scans[k].0, &scans[k].1))
        .collect();
    let poses: Vec<Pose3> = rendered.iter().map(|(p, _)| *p).collect();
    let config = &whole.config;
    let floor =
        FloorMap::estimate_from_scans(&rendered, &floor_hints_below(&poses, 0.6), &config.floor)
            .unwrap();
    assert_eq!(in_batches.floor(), &floor);
    let grid = gridmap::OccupancyGridBuilder::new(config.grid.clone())
        .unwrap()
        .build_floor_band_from_scans(&rendered, &floor, &config.band)
        .unwrap();
    assert_eq!(in_batches.occupancy(), &grid);
    assert!(
        grid.counts().0 > 100 && grid.counts().1 > 100,
        "{:?}",
        grid.counts()
    );
    let mut centroids = VoxelCentroids::new(0.1);
    for (pose, cloud) in &rendered {
        centroids.add(&[(*pose, cloud.points())]).unwrap();
    }
    assert_eq!(batched.cloud.cloud().points(), centroids.cloud().points());
}

/// A keyframe that cannot be read ends the render with its error.
#[test]
fn a_keyframe_that_cannot_be_read_ends_the_render() {
    struct Unreadable(Vec<(Pose3, PointCloud)>);
    impl Keyframes for Unreadable {
        fn count(&self) -> usize {
            self.0.len()
        }
        fn pose(&self, k: usize) -> Option<Pose3> {
            self.0.get(k).map(|(p, _)| *p)
        }
        fn scan(&self, k: usize) -> Result<Cow<'_, PointCloud>, KeyframeCloudError> {
            if k == 3 {
                return Err(KeyframeCloudError::Cloud(CloudError::InvalidVoxelSize {
                    size: -1.0,
                }));
            }
            Ok(Cow::Borrowed(&self.0[k].1))
        }
    }
    let scans = Unreadable((0..8).map(|k| corridor_scan(f64::from(k))).collect());
    for batch_points in [BLOCK_POINTS, 5000] {
        let mut m = map();
        m.batch_points = batch_points;
        let err = m.update_from::<std::io::Error>(&scans).unwrap_err();
        assert!(
            matches!(err, Error::Map(KeyframeCloudError::Cloud(_))),
            "{err:?}"
        );
    }
}

/// Scans without any point in the obstacle band give no map, and say why.
#[test]
fn a_map_without_obstacles_is_refused_by_name() {
    let floor_only = PointCloud::from_points(vec![Point3::new(1.0, 0.0, -0.6); 50]);
    let mut m = map();
    let err = m
        .update_from::<std::io::Error>(&[(Pose3::translation(0.0, 0.0, 0.6), &floor_only)][..])
        .unwrap_err();
    assert!(
        matches!(
            err,
            Error::Navigation(NavError::NavigationGrid(
                gridmap::GridMapError::EmptyBand { .. }
            ))
        ),
        "{err:?}"
    );
}

/// The voxels within reach are the whole cloud's points within reach (the definition: the
/// horizontal distance of each stored centroid), in the same order, for reaches that cut
/// through voxels, none and all.
#[test]
fn the_cloud_within_reach_is_the_whole_cloud_filtered() {
    let points: Vec<Point3<f32>> = (0..4000)
        .map(|i| {
            let f = i as f32;
            Point3::new((f * 0.37).sin() * 40.0, (f * 0.11).cos() * 25.0, f * 0.001)
        })
        .collect();
    let mut centroids = VoxelCentroids::new(0.2);
    centroids
        .add(&[(Pose3::identity(), points.as_slice())])
        .unwrap();
    let whole = centroids.cloud();
    for (at, reach) in [
        (Vector2::new(3.0, -2.0), 10.0),
        (Vector2::new(-30.0, 10.0), 4.5),
        (Vector2::zeros(), 0.0),
        (Vector2::zeros(), f64::INFINITY),
        (Vector2::new(1000.0, 0.0), 30.0),
    ] {
        let want =
            whole.filtered(|_, p| (f64::from(p.x) - at.x).hypot(f64::from(p.y) - at.y) <= reach);
        let got = centroids.within(at, reach);
        assert_eq!(got.points(), want.points(), "at {at}, reach {reach}");
    }
}
