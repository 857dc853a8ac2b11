//! Obstacles from the floor up: the floor per tile, the obstacle band from a map cloud and from
//! scans with free space from their beams, unknown cells in the ROS map.
#![allow(clippy::unwrap_used, clippy::panic)]

use crate::common::room;
use gridmap::{
    CellState, FloorConfig, FloorMap, GridMapError, ObstacleBandConfig, OccupancyGrid,
    OccupancyGridBuilder, OccupancyGridConfig, UnknownCells, floor_hints_below, read_ros_map,
    write_ros_map,
};
use nalgebra::{Point3, Vector2};
use slam_core::{InvalidSetting, PointCloud, Pose3};

/// The map frame starts at the first LiDAR pose: the floor is 0.80 m below it.
const FLOOR: f64 = -0.80;

fn builder() -> OccupancyGridBuilder {
    OccupancyGridBuilder::new(OccupancyGridConfig::default()).unwrap()
}

fn state_at(grid: &OccupancyGrid, x: f64, y: f64) -> CellState {
    grid.state(grid.occupied().cell_at(Vector2::new(x, y)).unwrap())
}

/// Sensor positions along the room's middle (y = 3 m), through the door at x = 8 m.
fn poses() -> Vec<Point3<f64>> {
    [1.0, 3.0, 4.5, 6.5, 9.0, 11.0]
        .into_iter()
        .map(|x| Point3::new(x, 3.0, FLOOR + 0.80))
        .collect()
}

#[test]
fn floor_follows_a_gentle_ramp_and_skips_the_crate() {
    // A 12 m x 6 m floor rising 1 cm per metre, sampled every 5 cm, and a 0.56 m crate covering
    // the whole tile [2, 3) x [4, 5) (no floor point there).
    let truth = |x: f64| FLOOR + 0.01 * x;
    let mut pts = Vec::new();
    for i in 0..240 {
        for j in 0..120 {
            let (x, y) = (f64::from(i) * 0.05 + 0.025, f64::from(j) * 0.05 + 0.025);
            let on_crate = (2.0..3.0).contains(&x) && (4.0..5.0).contains(&y);
            let z = if on_crate { truth(x) + 0.56 } else { truth(x) };
            pts.push(Point3::new(x as f32, y as f32, z as f32));
        }
    }
    let cloud = PointCloud::from_points(pts);
    // Hints from the feet along y = 3 m, a few centimetres off.
    let hints: Vec<Point3<f64>> = (0..12)
        .map(|k| {
            let x = f64::from(k) + 0.5;
            Point3::new(x, 3.0, truth(x) + if k % 2 == 0 { 0.04 } else { -0.03 })
        })
        .collect();
    let floor = FloorMap::estimate(&cloud, &hints, &FloorConfig::default()).unwrap();
    assert_eq!(floor.tiles().0, 12);
    assert_eq!(
        floor.measured_tiles(),
        12 * 6 - 1,
        "all but the crate's tile"
    );
    for i in 0..12 {
        for j in 0..6 {
            let (x, y) = (f64::from(i) + 0.5, f64::from(j) + 0.5);
            let err = floor.floor_at(x, y) - truth(x);
            // The tile's mean floor, and the crate's tile its neighbours' mean.
            assert!(err.abs() < 0.012, "tile ({i}, {j}): off by {err}");
        }
    }
    // No point within the span (1 m) of the hints: the hints' height, flat.
    let high = PointCloud::from_points(vec![Point3::new(1.0, 1.0, 2.5); 10]);
    let flat = FloorMap::estimate(&high, &hints[..1], &FloorConfig::default()).unwrap();
    assert_eq!(
        (flat.measured_tiles(), flat.floor_at(9.0, 9.0)),
        (0, hints[0].z)
    );
    // Outside the tiles: the nearest tile.
    assert!((floor.floor_at(-50.0, 3.0) - floor.floor_at(0.5, 3.0)).abs() < 1e-12);
    // One flat height would be 6 cm off at the ends (the hints' mean): inside the default band's
    // 8 cm, but an estimate per tile follows the floor wherever it goes.
}

/// The floor of scans handed over in batches, pass after pass, is the floor of their points
/// merged into one map cloud (the oracle), whatever the batches; bad input is refused as one
/// batch of all the scans is.
#[test]
fn floor_from_scans_in_batches_is_the_merged_clouds() {
    // The ramp and crate above on a lattice of 1/16 m, heights to 1/1024 m: values f32 holds
    // exactly, so a scan placed by a whole-metre translation lands exactly where the merged
    // cloud has its points.
    let truth = |x: f64| ((FLOOR + 0.01 * x) * 1024.0).round() / 1024.0;
    let mut world = Vec::new();
    for i in 0..192 {
        for j in 0..96 {
            let (x, y) = (f64::from(i) / 16.0, f64::from(j) / 16.0);
            let on_crate = (2.0..3.0).contains(&x) && (4.0..5.0).contains(&y);
            world.push(Point3::new(
                x,
                y,
                truth(x) + if on_crate { 0.5625 } else { 0.0 },
            ));
        }
    }
    let merged = PointCloud::from_points(world.iter().map(|p| p.cast::<f32>()).collect());
    // Scans of 2 m strips, each in the frame of a sensor standing in its strip.
    let scans: Vec<(Pose3, Vec<Point3<f32>>)> = (0..6)
        .map(|k: i32| {
            let at = Vector2::new(2.0 * f64::from(k) + 1.0, 3.0);
            let local = world
                .iter()
                .filter(|p| (p.x / 2.0).floor() as i32 == k)
                .map(|p| Point3::new(p.x - at.x, p.y - at.y, p.z).cast::<f32>())
                .collect();
            (Pose3::translation(at.x, at.y, 0.0), local)
        })
        .collect();
    let points: Vec<(Pose3, &[Point3<f32>])> = scans
        .iter()
        .map(|(pose, p)| (*pose, p.as_slice()))
        .collect();
    let hints: Vec<Point3<f64>> = (0..12)
        .map(|k| Point3::new(f64::from(k) + 0.5, 3.0, truth(f64::from(k) + 0.5) + 0.03))
        .collect();
    let config = FloorConfig::default();
    let oracle = FloorMap::estimate(&merged, &hints, &config).unwrap();
    assert_eq!(oracle.measured_tiles(), 12 * 6 - 1);
    for batch in [1, 2, 4, 6] {
        let passes = std::cell::Cell::new(0);
        let floor = FloorMap::estimate_from_scan_passes(
            |visit| {
                passes.set(passes.get() + 1);
                for part in points.chunks(batch) {
                    visit(part);
                }
            },
            &hints,
            &config,
        )
        .unwrap();
        assert_eq!(floor, oracle, "batches of {batch}");
        assert_eq!(passes.get(), 4);
    }
    assert_eq!(
        FloorMap::estimate_from_scan_points(&points, &hints, &config).unwrap(),
        oracle
    );
    // Every scan empty, or a non-finite point in any batch: refused.
    let empty: Vec<(Pose3, &[Point3<f32>])> = vec![(Pose3::identity(), &[]); 3];
    let err = FloorMap::estimate_from_scan_passes(
        |visit| empty.chunks(1).for_each(&mut *visit),
        &hints,
        &config,
    );
    assert!(matches!(err, Err(GridMapError::EmptyCloud)));
    let nan = [
        Point3::new(f32::NAN, 0.0, 0.0),
        Point3::new(0.0, f32::INFINITY, 0.0),
    ];
    let mut bad = points.clone();
    bad.push((Pose3::identity(), &nan));
    let err = FloorMap::estimate_from_scan_passes(
        |visit| bad.chunks(2).for_each(&mut *visit),
        &hints,
        &config,
    );
    assert!(matches!(
        err,
        Err(GridMapError::NonFinitePoints { count: 2 })
    ));
}

#[test]
fn band_from_the_map_cloud_takes_low_and_high_furniture_not_overhangs() {
    let world = room(FLOOR);
    let cloud = world.surface_cloud(-0.15, -0.15, 12.15, 6.15, 0.04);
    let hints = floor_hints_below(
        &poses()
            .iter()
            .map(|p| Pose3::translation(p.x, p.y, p.z))
            .collect::<Vec<_>>(),
        0.80,
    );
    let floor = FloorMap::estimate(&cloud, &hints, &FloorConfig::default()).unwrap();
    let band = ObstacleBandConfig::default();
    let grid = builder().build_floor_band(&cloud, &floor, &band).unwrap();
    assert_eq!(state_at(&grid, 2.25, 4.25), CellState::Occupied, "crate");
    assert_eq!(state_at(&grid, 5.6, 4.9), CellState::Occupied, "desk top");
    // The cross wall's faces at x = 8.0 and 8.15 m; its door under the lintel stays open.
    for x in [7.95, 8.05, 8.15, 8.25] {
        assert_eq!(state_at(&grid, x, 3.0), CellState::Free, "door at x = {x}");
    }
    assert_eq!(
        state_at(&grid, 8.17, 1.0),
        CellState::Occupied,
        "cross wall"
    );
    assert_eq!(state_at(&grid, 4.0, 2.0), CellState::Free, "floor");
    // The slice around the LiDAR height (0.6 to 1.0 m above the floor) misses the crate.
    let slice = builder().build(&cloud, FLOOR + 0.80).unwrap();
    assert_eq!(state_at(&slice, 2.25, 4.25), CellState::Free);
    // A band up to 0.5 m misses the desk top; one up to 2.2 m closes the door.
    let low = ObstacleBandConfig {
        up_to: 0.5,
        ..band.clone()
    };
    let grid = builder().build_floor_band(&cloud, &floor, &low).unwrap();
    assert_eq!(state_at(&grid, 5.6, 4.9), CellState::Free);
    let high = ObstacleBandConfig { up_to: 2.2, ..band };
    let grid = builder().build_floor_band(&cloud, &floor, &high).unwrap();
    assert_eq!(state_at(&grid, 8.07, 3.0), CellState::Occupied);
}

#[test]
fn band_from_scans_tells_free_from_unknown_and_the_ros_map_keeps_unknown() {
    let world = room(FLOOR);
    let scans: Vec<(Pose3, PointCloud)> = poses().iter().map(|&p| world.scan(p, 900)).collect();
    let refs: Vec<(Pose3, &PointCloud)> = scans.iter().map(|(p, c)| (*p, c)).collect();
    let poses: Vec<Pose3> = scans.iter().map(|(p, _)| *p).collect();
    let hints = floor_hints_below(&poses, 0.80);
    let floor = FloorMap::estimate_from_scans(&refs, &hints, &FloorConfig::default()).unwrap();
    assert!((floor.floor_at(4.0, 3.0) - FLOOR).abs() < 1e-3);
    let grid = builder()
        .build_floor_band_from_scans(&refs, &floor, &ObstacleBandConfig::default())
        .unwrap();
    assert_eq!(state_at(&grid, 2.25, 4.05), CellState::Occupied, "crate");
    assert_eq!(
        state_at(&grid, 5.6, 4.65),
        CellState::Occupied,
        "desk top's edge"
    );
    assert_eq!(state_at(&grid, 8.07, 3.0), CellState::Free, "door");
    assert_eq!(state_at(&grid, 4.0, 2.0), CellState::Free);
    assert_eq!(state_at(&grid, 10.0, 1.0), CellState::Free);
    // Beyond the outer walls nothing was observed.
    assert_eq!(state_at(&grid, -0.45, 3.0), CellState::Unknown);
    assert_eq!(state_at(&grid, 12.45, -0.45), CellState::Unknown);
    // Nearly every floor cell of the room is known.
    let (mut free, mut total) = (0, 0);
    for i in 0..118 {
        for j in 0..58 {
            let (x, y) = (0.15 + f64::from(i) * 0.1, 0.15 + f64::from(j) * 0.1);
            let near_block = world.blocks.iter().any(|b| {
                x > b.min.x - 0.15 && x < b.max.x + 0.15 && y > b.min.y - 0.15 && y < b.max.y + 0.15
            });
            if !near_block {
                total += 1;
                free += usize::from(state_at(&grid, x, y) == CellState::Free);
            }
        }
    }
    assert!(
        free * 100 >= total * 97,
        "{free} of {total} room cells free"
    );
    let planning = grid.to_planning_grid(UnknownCells::Blocked);
    let outside = grid.occupied().cell_at(Vector2::new(-0.45, 3.0)).unwrap();
    assert!(planning.is_blocked(outside));
    assert!(
        !grid
            .to_planning_grid(UnknownCells::Free)
            .is_blocked(outside)
    );
    // The ROS map writes unknown cells as unknown (205) and reads them back.
    let dir = std::env::temp_dir().join(format!("gridmap-band-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let yaml = dir.join("map.yaml");
    let pgm = write_ros_map(&grid, &yaml).unwrap();
    let bytes = std::fs::read(&pgm).unwrap();
    let (_, _, unknown) = grid.counts();
    assert!(unknown > 100);
    let pixels = &bytes[bytes.len() - grid.width() as usize * grid.height() as usize..];
    assert_eq!(
        pixels.iter().map(|&v| usize::from(v == 205)).sum::<usize>(),
        unknown
    );
    // The ROS map keeps the states (not where in each occupied cell its points lie).
    let back = read_ros_map(&yaml).unwrap();
    assert_eq!(back.occupied(), grid.occupied());
    assert_eq!(back.known_free(), grid.known_free());
    assert_eq!(back.stairs(), grid.stairs());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_floor_settings_and_input_are_errors() {
    let cloud = PointCloud::from_points(vec![Point3::new(0.0, 0.0, -0.8)]);
    let hint = [Point3::new(0.0, 0.0, -0.8)];
    let invalid = |r: Result<FloorMap, GridMapError>, name: &str| match r {
        Err(GridMapError::InvalidConfig(InvalidSetting { setting, .. })) => {
            assert_eq!(setting, name);
        }
        other => panic!("{name}: {other:?}"),
    };
    for v in [f64::NAN, 0.0, -1.0, f64::INFINITY] {
        for (name, config) in [
            (
                "FloorConfig::tile",
                FloorConfig {
                    tile: v,
                    ..FloorConfig::default()
                },
            ),
            (
                "FloorConfig::search",
                FloorConfig {
                    search: v,
                    ..FloorConfig::default()
                },
            ),
            (
                "FloorConfig::bin",
                FloorConfig {
                    bin: v,
                    ..FloorConfig::default()
                },
            ),
            (
                "FloorConfig::span",
                FloorConfig {
                    span: v,
                    ..FloorConfig::default()
                },
            ),
        ] {
            invalid(FloorMap::estimate(&cloud, &hint, &config), name);
        }
    }
    let fine = FloorConfig {
        search: 1.0e300,
        bin: 1.0e-300,
        ..FloorConfig::default()
    };
    invalid(FloorMap::estimate(&cloud, &hint, &fine), "FloorConfig::bin");
    let zero = FloorConfig {
        min_points: 0,
        ..FloorConfig::default()
    };
    invalid(
        FloorMap::estimate(&cloud, &hint, &zero),
        "FloorConfig::min_points",
    );
    invalid(
        FloorMap::estimate(
            &cloud,
            &[Point3::new(0.0, f64::NAN, 0.0)],
            &FloorConfig::default(),
        ),
        "FloorMap::estimate hints",
    );
    invalid(FloorMap::flat(f64::NAN), "FloorMap::flat z");
    assert!(matches!(
        FloorMap::estimate(&cloud, &[], &FloorConfig::default()),
        Err(GridMapError::NoFloorHint)
    ));
    assert!(matches!(
        FloorMap::estimate(&PointCloud::new(), &hint, &FloorConfig::default()),
        Err(GridMapError::EmptyCloud)
    ));
    let nan = PointCloud::from_points(vec![Point3::new(f32::NAN, 0.0, 0.0)]);
    assert!(matches!(
        FloorMap::estimate(&nan, &hint, &FloorConfig::default()),
        Err(GridMapError::NonFinitePoints { count: 1 })
    ));
    let far = PointCloud::from_points(vec![
        Point3::new(0.0, 0.0, -0.8),
        Point3::new(3.0e7, 3.0e7, -0.8),
    ]);
    assert!(matches!(
        FloorMap::estimate(&far, &hint, &FloorConfig::default()),
        Err(GridMapError::TooManyCells { .. })
    ));
}

#[test]
fn bad_band_settings_and_input_are_errors() {
    let cloud = PointCloud::from_points(vec![Point3::new(0.0, 0.0, -0.8)]);
    let nan = PointCloud::from_points(vec![Point3::new(f32::NAN, 0.0, 0.0)]);
    let floor = FloorMap::flat(-0.8).unwrap();
    for (band, name) in [
        (
            ObstacleBandConfig {
                above_floor: f64::NAN,
                ..ObstacleBandConfig::default()
            },
            "ObstacleBandConfig::above_floor",
        ),
        (
            ObstacleBandConfig {
                above_floor: -0.1,
                ..ObstacleBandConfig::default()
            },
            "ObstacleBandConfig::above_floor",
        ),
        (
            ObstacleBandConfig {
                up_to: 0.05,
                ..ObstacleBandConfig::default()
            },
            "ObstacleBandConfig::up_to",
        ),
        (
            ObstacleBandConfig {
                up_to: f64::NAN,
                ..ObstacleBandConfig::default()
            },
            "ObstacleBandConfig::up_to",
        ),
    ] {
        match builder().build_floor_band(&cloud, &floor, &band) {
            Err(GridMapError::InvalidConfig(InvalidSetting { setting, .. })) => {
                assert_eq!(setting, name);
            }
            other => panic!("{name}: {other:?}"),
        }
    }
    let band = ObstacleBandConfig::default();
    assert!(matches!(
        builder().build_floor_band(&cloud, &floor, &band),
        Err(GridMapError::EmptyBand { .. })
    ));
    assert!(matches!(
        builder().build_floor_band(&PointCloud::new(), &floor, &band),
        Err(GridMapError::EmptyCloud)
    ));
    let pose = Pose3::translation(0.0, 0.0, 0.0);
    assert!(matches!(
        builder().build_floor_band_from_scans(&[(pose, &PointCloud::new())], &floor, &band),
        Err(GridMapError::EmptyCloud)
    ));
    assert!(matches!(
        builder().build_floor_band_from_scans(&[(pose, &nan)], &floor, &band),
        Err(GridMapError::NonFinitePoints { count: 1 })
    ));
    assert!(matches!(
        builder().build_floor_band_from_scans(&[(pose, &cloud)], &floor, &band),
        Err(GridMapError::EmptyBand { .. })
    ));
    let stray = PointCloud::from_points(vec![
        Point3::new(1.0, 0.0, -0.5),
        Point3::new(1.0e6, 1.0e6, -0.5),
    ]);
    assert!(matches!(
        builder().build_floor_band_from_scans(&[(pose, &stray)], &floor, &band),
        Err(GridMapError::TooManyCells { .. })
    ));
}
