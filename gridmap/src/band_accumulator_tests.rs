use super::*;
use crate::error::GridMapError;
use slam_core::Cell;

/// A 6 m x 4 m room with 2.5 m walls and a ceiling, seen from `at` (the sensor 0.6 m above the
/// floor): wall points at all heights (band points below 0.94 m, overhangs above), floor points
/// and ceiling points, in the sensor frame.
fn room_scan(at: (f64, f64), seed: u64) -> (Pose3, PointCloud) {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut rnd = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let pose = Pose3::translation(at.0, at.1, 0.6);
    let mut points = Vec::new();
    for _ in 0..600 {
        let z = rnd() * 2.5;
        let t = rnd();
        let wall = match (rnd() * 4.0) as u32 {
            0 => (t * 6.0, 0.0),
            1 => (t * 6.0, 4.0),
            2 => (0.0, t * 4.0),
            _ => (6.0, t * 4.0),
        };
        points.push((wall.0, wall.1, z));
    }
    for _ in 0..300 {
        points.push((0.2 + rnd() * 5.6, 0.2 + rnd() * 3.6, 0.0));
        points.push((0.2 + rnd() * 5.6, 0.2 + rnd() * 3.6, 2.5));
    }
    let local = points
        .into_iter()
        .map(|(x, y, z)| Point3::new((x - at.0) as f32, (y - at.1) as f32, (z - 0.6) as f32))
        .collect();
    (pose, PointCloud::from_points(local))
}

fn config() -> OccupancyGridConfig {
    OccupancyGridConfig {
        resolution: 0.1,
        min_points: 2,
        ..Default::default()
    }
}

fn one_shot(scans: &[(Pose3, PointCloud)]) -> OccupancyGrid {
    let refs: Vec<(Pose3, &PointCloud)> = scans.iter().map(|(p, c)| (*p, c)).collect();
    OccupancyGridBuilder::new(config())
        .unwrap()
        .build_floor_band_from_scans(
            &refs,
            &FloorMap::flat(0.0).unwrap(),
            &ObstacleBandConfig::default(),
        )
        .unwrap()
}

/// Nine scans of the room from along its middle.
fn nine_room_scans() -> Vec<(Pose3, PointCloud)> {
    (0..9u64)
        .map(|k| {
            let at = (0.5 + 0.6 * k as f64, 0.6 + 0.3 * (k % 3) as f64);
            room_scan(at, k + 1)
        })
        .collect()
}

/// An accumulator over the flat floor at 0 with the default band.
fn empty() -> FloorBandAccumulator {
    FloorBandAccumulator::new(
        config(),
        FloorMap::flat(0.0).unwrap(),
        ObstacleBandConfig::default(),
    )
    .unwrap()
}

/// The cells that differ between two grids of the same extent, as (one-shot, batched) states.
fn differences(a: &OccupancyGrid, b: &OccupancyGrid) -> Vec<(CellState, CellState)> {
    assert_eq!(a.geometry(), b.geometry());
    assert_eq!((a.width(), a.height()), (b.width(), b.height()));
    let mut out = Vec::new();
    for y in 0..a.height() {
        for x in 0..a.width() {
            let c = Cell::new(x, y);
            if a.state(c) != b.state(c) {
                out.push((a.state(c), b.state(c)));
            }
        }
    }
    out
}

/// Scans added in batches of every size give the grid of all of them added at once, but for
/// cells freed by a beam to an overhang beyond the grid of the batches before (left unknown).
#[test]
fn batches_give_the_grid_of_all_scans_at_once() {
    let scans = nine_room_scans();
    let whole = one_shot(&scans);
    let (free, occupied, unknown) = whole.counts();
    assert!(
        occupied > 200 && free > 1000 && unknown > 0,
        "{occupied} {free} {unknown}"
    );
    for batch in [1, 2, 4, 9] {
        let mut acc = empty();
        for part in scans.chunks(batch) {
            let refs: Vec<(Pose3, &PointCloud)> = part.iter().map(|(p, c)| (*p, c)).collect();
            acc.add_scans(&refs).unwrap();
        }
        assert_eq!(acc.scans(), scans.len());
        let got = acc.grid().unwrap();
        let diff = differences(&whole, &got);
        assert!(
            diff.iter()
                .all(|d| *d == (CellState::Free, CellState::Unknown)),
            "batch {batch}: {diff:?}"
        );
        // The room's walls bound every scan's floor: the first scan's grid already spans it.
        assert!(diff.len() <= free / 100, "batch {batch}: {}", diff.len());
        if batch == 9 {
            assert!(diff.is_empty());
        }
    }
}

/// Extended over every batch first, scans added in batches of every size give the grid of all
/// of them at once to the cell, overhangs included (the builder's one-shot grid is the oracle).
#[test]
fn batches_after_extending_over_them_all_give_the_one_shot_grid() {
    let scans = nine_room_scans();
    let whole = one_shot(&scans);
    let points: Vec<(Pose3, &[Point3<f32>])> =
        scans.iter().map(|(p, c)| (*p, c.points())).collect();
    for batch in [1, 2, 4, 9] {
        let mut acc = empty();
        for part in points.chunks(batch) {
            acc.extend_over(part).unwrap();
        }
        assert_eq!(acc.scans(), 0);
        for part in points.chunks(batch) {
            acc.add_scan_points(part).unwrap();
        }
        assert_eq!(acc.scans(), scans.len());
        let got = acc.grid().unwrap();
        assert!(differences(&whole, &got).is_empty(), "batch {batch}");
        assert_eq!(got.counts(), whole.counts(), "batch {batch}");
    }
    // A bad scan is refused before anything changes.
    let mut acc = empty();
    let bad = [Point3::new(f32::NAN, 0.0, 0.0)];
    assert!(matches!(
        acc.extend_over(&[(Pose3::identity(), &bad[..])]),
        Err(GridMapError::NonFinitePoints { .. })
    ));
    assert!(matches!(acc.grid(), Err(GridMapError::EmptyCloud)));
}

/// Without overhangs the order and batching of the scans changes no cell at all.
#[test]
fn without_overhangs_batches_change_nothing() {
    let low = |(pose, cloud): (Pose3, PointCloud)| {
        let kept = cloud.filtered(|_, p| f64::from(p.z) + 0.6 < 0.9);
        (pose, kept)
    };
    let scans: Vec<(Pose3, PointCloud)> = (0..6u64)
        .map(|k| {
            low(room_scan(
                (5.5 - 0.9 * k as f64, 3.4 - 0.5 * k as f64),
                40 + k,
            ))
        })
        .collect();
    let whole = one_shot(&scans);
    let mut acc = empty();
    for (pose, cloud) in scans.iter().rev() {
        acc.add_scans(&[(*pose, cloud)]).unwrap();
    }
    assert!(differences(&whole, &acc.grid().unwrap()).is_empty());
}

/// A scan with a non-finite point is refused whole, and the grid stays as it was; an empty
/// accumulator and one without band points say so.
#[test]
fn bad_scans_are_refused_and_change_nothing() {
    let mut acc = empty();
    assert!(matches!(acc.grid(), Err(GridMapError::EmptyCloud)));
    let floor_only = PointCloud::from_points(vec![Point3::new(1.0, 0.0, -0.6)]);
    acc.add_scans(&[(Pose3::translation(0.0, 0.0, 0.6), &floor_only)])
        .unwrap();
    assert!(matches!(acc.grid(), Err(GridMapError::EmptyBand { .. })));
    let (pose, good) = room_scan((2.0, 2.0), 7);
    acc.add_scans(&[(pose, &good)]).unwrap();
    let before = acc.grid().unwrap();
    let mut bad_points = good.points().to_vec();
    bad_points.push(Point3::new(f32::NAN, 0.0, 0.0));
    let bad = PointCloud::from_points(bad_points);
    let (pose2, good2) = room_scan((4.0, 1.0), 8);
    let err = acc.add_scans(&[(pose2, &good2), (pose, &bad)]).unwrap_err();
    assert!(
        matches!(err, GridMapError::NonFinitePoints { count: 1 }),
        "{err:?}"
    );
    assert_eq!(acc.scans(), 2);
    assert_eq!(acc.grid().unwrap(), before);
    // A point a light year away would need more cells than allowed.
    let far = PointCloud::from_points(vec![Point3::new(9.0e15, 0.0, 0.0)]);
    let err = acc
        .add_scans(&[(Pose3::translation(0.0, 0.0, 0.6), &far)])
        .unwrap_err();
    assert!(matches!(err, GridMapError::TooManyCells { .. }), "{err:?}");
    assert_eq!(acc.grid().unwrap(), before);
    assert!(
        FloorBandAccumulator::new(
            config(),
            FloorMap::flat(0.0).unwrap(),
            ObstacleBandConfig {
                above_floor: 1.0,
                up_to: 0.5
            }
        )
        .is_err()
    );
}
