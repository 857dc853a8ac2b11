//! The live layer: a dropped box goes in, a removed crate comes out, a moving box leaves no
//! trail, unseen changes decay back to the static map, and only the window is touched.
#![allow(clippy::unwrap_used, clippy::panic)]

use crate::common::{World, block, room};
use gridmap::{
    CellRect, CellState, FloorMap, GridMapError, LiveLayer, LiveLayerConfig, LocalCell,
    ObstacleBandConfig, OccupancyGrid, OccupancyGridBuilder, OccupancyGridConfig, PlanningGrid,
    PlanningGridConfig,
};
use nalgebra::{Point3, Vector2};
use slam_core::{Cell, InvalidSetting, PointCloud, Pose3};

const FLOOR: f64 = -0.80;

fn sensor(x: f64, y: f64) -> Point3<f64> {
    Point3::new(x, y, FLOOR + 0.80)
}

/// The room's static map from scans along its middle.
fn static_map(world: &World) -> OccupancyGrid {
    let scans: Vec<(Pose3, PointCloud)> = [1.0, 3.0, 4.5, 6.5, 9.0, 11.0]
        .into_iter()
        .map(|x| world.scan(sensor(x, 3.0), 900))
        .collect();
    let refs: Vec<(Pose3, &PointCloud)> = scans.iter().map(|(p, c)| (*p, c)).collect();
    OccupancyGridBuilder::new(OccupancyGridConfig::default())
        .unwrap()
        .build_floor_band_from_scans(
            &refs,
            &FloorMap::flat(FLOOR).unwrap(),
            &ObstacleBandConfig::default(),
        )
        .unwrap()
}

/// Beams clear every cell they cross below the band's top: these tests look at what a scan from
/// close by shows of a removed crate, which the default (clear only below 0.3 m) leaves to
/// scans from farther away.
fn every_beam_clears() -> LiveLayerConfig {
    LiveLayerConfig {
        clear_below: ObstacleBandConfig::default().up_to,
        ..LiveLayerConfig::default()
    }
}

fn cell(grid: &OccupancyGrid, x: f64, y: f64) -> Cell {
    grid.occupied().cell_at(Vector2::new(x, y)).unwrap()
}

fn inside(r: &CellRect, c: Cell) -> bool {
    (r.x0..r.x1).contains(&c.x) && (r.y0..r.y1).contains(&c.y)
}

#[test]
fn dropped_box_in_removed_crate_out_then_both_decay() {
    let world = room(FLOOR);
    let map = static_map(&world);
    let floor = FloorMap::flat(FLOOR).unwrap();
    let mut layer = LiveLayer::new(map.clone(), every_beam_clears()).unwrap();
    // After mapping: the crate (index 7) is gone and a 0.6 m box stands at (4.2..4.8, 1.2..1.8).
    let mut now = world.clone();
    now.blocks.remove(7);
    now.blocks
        .push(block(4.2, 1.2, FLOOR, 4.8, 1.8, FLOOR + 0.6));
    let (pose, scan) = now.scan(sensor(3.0, 3.0), 1800);
    assert!(scan.len() > 28_000);
    let report = layer.update(&scan, &pose, &floor, 0.0).unwrap();
    let window = report.window.unwrap();
    // 8 m at 0.1 m: 80 x 80 cells from 40 cells before the sensor's, cut at the map's edges.
    let at = cell(&map, 3.0, 3.0);
    let expect = CellRect {
        x0: at.x.saturating_sub(40),
        y0: at.y.saturating_sub(40),
        x1: (at.x + 40).min(map.width()),
        y1: (at.y + 40).min(map.height()),
    };
    assert_eq!(window, expect);
    let combined = layer.combined();
    let box_face = cell(combined, 4.25, 1.45);
    assert_eq!(map.state(box_face), CellState::Free);
    assert_eq!(
        combined.state(box_face),
        CellState::Occupied,
        "the box is in"
    );
    let crate_cell = cell(combined, 2.25, 4.05);
    assert_eq!(map.state(crate_cell), CellState::Occupied);
    assert_eq!(
        combined.state(crate_cell),
        CellState::Free,
        "the crate is out"
    );
    assert!(report.added > 0 && report.cleared > 0, "{report:?}");
    // Every change lies in the window; outside it the combined grid is the static map.
    let changed = report.changed.unwrap();
    assert!(changed.x0 >= window.x0 && changed.x1 <= window.x1);
    // Cells whose state differs, and those whose points moved within them too (the scan's
    // points in a wall cell are not the map's).
    let (mut differing, mut moved) = (0, 0);
    for y in 0..map.height() {
        for x in 0..map.width() {
            let c = Cell::new(x, y);
            if combined.state(c) != map.state(c) {
                differing += 1;
                assert!(inside(&window, c), "{c:?} changed outside the window");
            }
            if combined.state(c) != map.state(c) || combined.extent(c) != map.extent(c) {
                moved += 1;
                assert!(inside(&window, c), "{c:?} changed outside the window");
            }
        }
    }
    assert_eq!(differing, report.added + report.cleared);
    // The local grid says the same as the window of the combined grid where it saw something.
    let local = layer.last_local_grid();
    assert_eq!((local.width, local.height), (80, 80));
    let g = combined.geometry();
    for j in 0..local.height {
        for i in 0..local.width {
            let centre = local.map_t_grid
                * nalgebra::Point2::new(
                    (f64::from(i) + 0.5) * local.resolution,
                    (f64::from(j) + 0.5) * local.resolution,
                );
            let Some(c) = combined.occupied().cell_at(centre.coords) else {
                continue;
            };
            let want = match local.cells[(j * local.width + i) as usize] {
                LocalCell::Obstacle => CellState::Occupied,
                LocalCell::Free => CellState::Free,
                LocalCell::Unknown => map.state(c),
            };
            assert_eq!(combined.state(c), want, "{c:?} {:?}", g.cell_center(c));
        }
    }
    // Seen from the far end of the room (the box and the crate's place out of its window), the
    // changes hold until 5 s after they were last seen, then return to the static map.
    let (far, far_scan) = now.scan(sensor(11.0, 3.0), 900);
    let r = layer.update(&far_scan, &far, &floor, 4.9).unwrap();
    assert_eq!(r.decayed, 0);
    assert_eq!(layer.combined().state(box_face), CellState::Occupied);
    let r = layer.update(&far_scan, &far, &floor, 5.0).unwrap();
    assert_eq!(r.decayed, moved);
    let reverted = r.reverted.unwrap();
    assert!(
        reverted.x0 >= window.x0 && reverted.x1 <= window.x1,
        "{reverted:?}"
    );
    assert_eq!(
        r.changed.unwrap(),
        reverted.union(&r.observed.unwrap_or(reverted))
    );
    assert_back_to_the_map(layer.combined(), &map, r.window.unwrap());
}

/// `combined` is `map` again but where the scan whose window was `window` holds the points of
/// the walls it sees rather than the map's.
fn assert_back_to_the_map(combined: &OccupancyGrid, map: &OccupancyGrid, window: CellRect) {
    assert_eq!(combined.occupied(), map.occupied());
    assert_eq!(combined.known_free(), map.known_free());
    for y in 0..map.height() {
        for x in 0..map.width() {
            let c = Cell::new(x, y);
            assert!(
                combined.extent(c) == map.extent(c) || inside(&window, c),
                "{c:?}"
            );
        }
    }
}

#[test]
fn a_moving_box_leaves_no_trail_and_seen_cells_stay() {
    let world = room(FLOOR);
    let map = static_map(&world);
    let floor = FloorMap::flat(FLOOR).unwrap();
    let mut layer = LiveLayer::new(map.clone(), every_beam_clears()).unwrap();
    let person = |x: f64| {
        let mut w = world.clone();
        w.blocks
            .push(block(x, 1.35, FLOOR, x + 0.4, 1.75, FLOOR + 1.7));
        w
    };
    // The cell of the middle of its face towards the sensor.
    let at = |x: f64| cell(&map, x + 0.2, 1.75);
    for (k, x) in [3.0, 3.6, 4.2, 4.8].into_iter().enumerate() {
        let (pose, scan) = person(x).scan(sensor(4.0, 3.5), 900);
        layer.update(&scan, &pose, &floor, 0.2 * k as f64).unwrap();
        assert_eq!(layer.combined().state(at(x)), CellState::Occupied);
        if k > 0 {
            // Its previous place was seen free again: back to the map's free cell at once.
            assert_eq!(layer.combined().state(at(x - 0.6)), CellState::Free);
        }
    }
    // Still seen 10 s later: the box stays (refreshed every update).
    let (pose, scan) = person(4.8).scan(sensor(4.0, 3.5), 900);
    layer.update(&scan, &pose, &floor, 10.0).unwrap();
    assert_eq!(layer.combined().state(at(4.8)), CellState::Occupied);
    // The planning layer follows the changed rectangles and equals a rebuild.
    let config = PlanningGridConfig::default();
    let mut planning = PlanningGrid::new(layer.combined(), config.clone()).unwrap();
    let (pose, scan) = person(3.0).scan(sensor(4.0, 3.5), 900);
    let r = layer.update(&scan, &pose, &floor, 10.2).unwrap();
    planning
        .refresh(layer.combined(), r.changed.unwrap())
        .unwrap();
    assert_eq!(
        planning,
        PlanningGrid::new(layer.combined(), config).unwrap()
    );
    assert!(planning.blocks_any(&[at(3.0)]));
    assert!(!planning.blocks_any(&[at(4.8)]));
}

#[test]
fn marks_decay_and_the_map_edge_is_safe() {
    let world = room(FLOOR);
    let map = static_map(&world);
    let floor = FloorMap::flat(FLOOR).unwrap();
    let mut layer = LiveLayer::new(map.clone(), LiveLayerConfig::default()).unwrap();
    let c = cell(&map, 4.0, 2.0);
    let r = layer.mark(c, CellState::Occupied, 1.0).unwrap();
    assert_eq!((r.added, r.changed), (1, Some(CellRect::cell(c))));
    assert_eq!(layer.combined().state(c), CellState::Occupied);
    // Off the map: ignored.
    let r = layer
        .mark(Cell::new(100_000, 3), CellState::Occupied, 1.0)
        .unwrap();
    assert_eq!(r.changed, None);
    // A scan far off the map touches nothing.
    let (_, scan) = world.scan(sensor(3.0, 3.0), 300);
    let far = Pose3::translation(1.0e6, -1.0e6, 0.0);
    let r = layer.update(&scan, &far, &floor, 2.0).unwrap();
    assert_eq!((r.window, r.changed), (None, None));
    let huge = Pose3::translation(1.0e300, 1.0e300, 0.0);
    assert!(layer.update(&scan, &huge, &floor, 2.0).is_ok());
    let r = layer.update(&PointCloud::new(), &far, &floor, 6.0).unwrap();
    assert_eq!(r.decayed, 1);
    assert_eq!(layer.combined(), &map);
}

#[test]
fn bad_settings_are_errors() {
    let map = OccupancyGrid::new(
        50,
        50,
        slam_core::GridGeometry::try_new(Vector2::zeros(), 0.1).unwrap(),
        CellState::Free,
    )
    .unwrap();
    let cases: Vec<(LiveLayerConfig, &str)> = vec![
        (
            LiveLayerConfig {
                window: f64::NAN,
                ..LiveLayerConfig::default()
            },
            "LiveLayerConfig::window",
        ),
        (
            LiveLayerConfig {
                window: 0.0,
                ..LiveLayerConfig::default()
            },
            "LiveLayerConfig::window",
        ),
        (
            LiveLayerConfig {
                window: 2000.0,
                ..LiveLayerConfig::default()
            },
            "LiveLayerConfig::window",
        ),
        (
            LiveLayerConfig {
                min_points: 0,
                ..LiveLayerConfig::default()
            },
            "LiveLayerConfig::min_points",
        ),
        (
            LiveLayerConfig {
                decay: f64::NAN,
                ..LiveLayerConfig::default()
            },
            "LiveLayerConfig::decay",
        ),
        (
            LiveLayerConfig {
                min_range: -1.0,
                ..LiveLayerConfig::default()
            },
            "LiveLayerConfig::min_range",
        ),
        (
            LiveLayerConfig {
                band: ObstacleBandConfig {
                    up_to: f64::INFINITY,
                    ..ObstacleBandConfig::default()
                },
                ..LiveLayerConfig::default()
            },
            "ObstacleBandConfig::up_to",
        ),
    ];
    for (cfg, name) in cases {
        match LiveLayer::new(map.clone(), cfg) {
            Err(GridMapError::InvalidConfig(InvalidSetting { setting, .. })) => {
                assert_eq!(setting, name);
            }
            other => panic!("{name}: {:?}", other.err()),
        }
    }
    // 250 m at 0.1 m: more than 2,000 cells a side.
    let wide = LiveLayerConfig {
        window: 250.0,
        ..LiveLayerConfig::default()
    };
    assert!(matches!(
        LiveLayer::new(map.clone(), wide).err(),
        Some(GridMapError::InvalidConfig(InvalidSetting {
            setting: "LiveLayerConfig::window",
            ..
        }))
    ));
}

#[test]
fn bad_input_is_an_error() {
    let map = OccupancyGrid::new(
        50,
        50,
        slam_core::GridGeometry::try_new(Vector2::zeros(), 0.1).unwrap(),
        CellState::Free,
    )
    .unwrap();
    let mut layer = LiveLayer::new(map, LiveLayerConfig::default()).unwrap();
    let floor = FloorMap::flat(0.0).unwrap();
    let scan = PointCloud::from_points(vec![Point3::new(1.0, 0.0, 0.3)]);
    let pose = Pose3::translation(2.0, 2.0, 0.8);
    assert!(matches!(
        layer.update(&scan, &pose, &floor, f64::NAN),
        Err(GridMapError::InvalidConfig(InvalidSetting {
            setting: "LiveLayer stamp",
            ..
        }))
    ));
    layer.update(&scan, &pose, &floor, 1.0).unwrap();
    assert!(matches!(
        layer.update(&scan, &pose, &floor, 0.5),
        Err(GridMapError::StampOutOfOrder { .. })
    ));
    let nan_pose = Pose3::translation(f64::NAN, 2.0, 0.8);
    assert!(matches!(
        layer.update(&scan, &nan_pose, &floor, 2.0),
        Err(GridMapError::InvalidConfig(InvalidSetting {
            setting: "LiveLayer map_t_sensor",
            ..
        }))
    ));
    let nan = PointCloud::from_points(vec![Point3::new(f32::NAN, 0.0, 0.3)]);
    assert!(matches!(
        layer.update(&nan, &pose, &floor, 2.0),
        Err(GridMapError::NonFinitePoints { count: 1 })
    ));
}

/// A box the LiDAR saw from afar is not cleared by the beams that pass over it once the robot is
/// so close that it no longer sees it (the VLP-16's lowest beam meets a 0.6 m top 0.75 m away):
/// by default a beam clears only the cells it crosses below 0.3 m.
#[test]
fn beams_passing_over_a_low_box_do_not_clear_it() {
    let world = room(FLOOR);
    let map = static_map(&world);
    let floor = FloorMap::flat(FLOOR).unwrap();
    let mut now = world.clone();
    now.blocks
        .push(block(6.0, 2.7, FLOOR, 6.6, 3.3, FLOOR + 0.6));
    // The face the robot walks toward: from 3 m its lowest beams hit it, from 0.5 m they pass
    // over it.
    let box_cell = cell(&map, 6.05, 3.0);
    let mut states = Vec::new();
    for config in [LiveLayerConfig::default(), every_beam_clears()] {
        let mut layer = LiveLayer::new(map.clone(), config).unwrap();
        // Seen from 3 m, then from 0.5 m where no beam hits it any more.
        let (pose, scan) = now.scan(sensor(3.3, 3.0), 1800);
        layer.update(&scan, &pose, &floor, 0.0).unwrap();
        assert_eq!(layer.combined().state(box_cell), CellState::Occupied);
        let (pose, scan) = now.scan(sensor(5.5, 3.0), 1800);
        layer.update(&scan, &pose, &floor, 0.2).unwrap();
        states.push(layer.combined().state(box_cell));
    }
    assert_eq!(states[0], CellState::Occupied, "the default keeps it");
    assert_eq!(
        states[1],
        CellState::Free,
        "clearing with every beam loses it"
    );
}

#[test]
fn a_renewed_layer_answers_as_a_new_one() {
    let world = room(FLOOR);
    let map = static_map(&world);
    let floor = FloorMap::flat(FLOOR).unwrap();
    let mut now = world.clone();
    now.blocks.remove(7);
    now.blocks
        .push(block(4.2, 1.2, FLOOR, 4.8, 1.8, FLOOR + 0.6));
    // A layer used on a smaller map with other settings, then renewed over the room's.
    let small = OccupancyGrid::new(20, 30, *map.geometry(), CellState::Free).unwrap();
    let mut renewed = LiveLayer::new(small, LiveLayerConfig::default()).unwrap();
    let (pose, scan) = now.scan(sensor(1.0, 1.0), 900);
    renewed.update(&scan, &pose, &floor, 0.0).unwrap();
    renewed.renew(&map, every_beam_clears()).unwrap();
    let mut fresh = LiveLayer::new(map.clone(), every_beam_clears()).unwrap();
    assert_eq!(renewed.combined(), fresh.combined());
    for (i, x) in [3.0, 4.0, 6.0].into_iter().enumerate() {
        let (pose, scan) = now.scan(sensor(x, 3.0), 900);
        let stamp = 2.0 * i as f64;
        let a = renewed.update(&scan, &pose, &floor, stamp).unwrap();
        let b = fresh.update(&scan, &pose, &floor, stamp).unwrap();
        assert_eq!(a.window, b.window);
        assert_eq!(renewed.combined(), fresh.combined());
    }
    // Invalid settings leave it as it was.
    let bad = LiveLayerConfig {
        window: -1.0,
        ..LiveLayerConfig::default()
    };
    assert!(renewed.renew(&map, bad).is_err());
    assert_eq!(renewed.combined(), fresh.combined());
}
