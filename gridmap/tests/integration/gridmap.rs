//! Occupancy grids against brute-force oracles.
#![allow(clippy::unwrap_used, clippy::panic)]

use std::collections::BTreeSet;

use gridmap::{
    CellState, DistanceField, GridMapError, LocalCell, LocalGrid, OccupancyGrid,
    OccupancyGridBuilder, OccupancyGridConfig, RosMapYaml, UnknownCells, fuse_local_grid, inflate,
    read_ros_map, ros_map_pgm, ros_map_yaml, squared_distance_cells, write_png, write_ros_map,
};
use nalgebra::{Point3, Vector2};
use proptest::prelude::*;
use slam_core::{BitGrid, Cell, GridGeometry, InvalidSetting, PointCloud, Pose2, Pose3};

use crate::rng::rng;

fn config(resolution: f64) -> OccupancyGridConfig {
    OccupancyGridConfig {
        resolution,
        margin: 0.0,
        ..OccupancyGridConfig::default()
    }
}

fn random_grid(w: u32, h: u32, density: u32, seed: u64) -> BitGrid {
    let mut r = rng(seed);
    BitGrid::from_fn(w, h, |_, _| (r() % 100) < u64::from(density)).unwrap()
}

/// A 6 m x 4 m room at 0.1 m cells: walls one cell thick, a pillar, floor and ceiling outside the
/// slice, and stray single points filtered by `min_points`.
#[test]
fn synthetic_room_gives_exactly_the_wall_cells() {
    let res = 0.1;
    let (w, h) = (60u32, 40u32);
    let mut expected = BTreeSet::new();
    for x in 0..w {
        expected.insert((x, 0));
        expected.insert((x, h - 1));
    }
    for y in 0..h {
        expected.insert((0, y));
        expected.insert((w - 1, y));
    }
    for (x, y) in [(30, 20), (31, 20), (30, 21), (31, 21)] {
        expected.insert((x, y));
    }
    let centre = |c: u32| (f64::from(c) + 0.5) * res;
    let mut pts = Vec::new();
    for &(x, y) in &expected {
        // Three points per cell at different heights inside the slice (LiDAR at 0.5 m).
        for z in [0.35, 0.5, 0.65] {
            pts.push(Point3::new(
                centre(x) as f32 + 0.02,
                centre(y) as f32 - 0.03,
                z,
            ));
        }
    }
    for x in 1..w - 1 {
        for y in 1..h - 1 {
            pts.push(Point3::new(centre(x) as f32, centre(y) as f32, 0.0)); // floor
            pts.push(Point3::new(centre(x) as f32, centre(y) as f32, 2.5)); // ceiling
        }
    }
    // Stray points (dust, a passing person's single return): one per cell.
    pts.push(Point3::new(1.55, 1.55, 0.5));
    pts.push(Point3::new(4.25, 2.85, 0.4));
    let cloud = PointCloud::from_points(pts);
    let builder = OccupancyGridBuilder::new(OccupancyGridConfig {
        min_points: 2,
        ..config(res)
    })
    .unwrap();
    let grid = builder.build(&cloud, 0.5).unwrap();
    assert_eq!((grid.width(), grid.height()), (w, h));
    assert!((grid.geometry().origin - Vector2::zeros()).norm() < 1e-12);
    let got: BTreeSet<(u32, u32)> = grid
        .occupied()
        .blocked_cells()
        .map(|c| (c.x, c.y))
        .collect();
    assert_eq!(got, expected);
    let (free, occupied, unknown) = grid.counts();
    assert_eq!((occupied, unknown), (expected.len(), 0));
    assert_eq!(free + occupied, (w * h) as usize);
    // With min_points = 1 the strays appear too.
    let all = OccupancyGridBuilder::new(config(res))
        .unwrap()
        .build(&cloud, 0.5)
        .unwrap();
    assert_eq!(all.occupied().count_blocked(), expected.len() + 2);
}

#[test]
fn ray_casting_tells_free_from_unknown() {
    // A sensor at (2, 2) sees a wall at x = 4 m from y = 1 to 3 m.
    let res = 0.1;
    let pts: Vec<Point3<f32>> = (0..=200)
        .map(|i| Point3::new(2.0, -1.0 + i as f32 * 0.01, 0.0))
        .collect();
    let cloud = PointCloud::from_points(pts);
    let pose = Pose3::translation(2.0, 2.0, 0.5);
    let grid = OccupancyGridBuilder::new(config(res))
        .unwrap()
        .build_from_scans(&[(pose, &cloud)], 0.5)
        .unwrap();
    let at = |x: f64, y: f64| grid.state(grid.occupied().cell_at(Vector2::new(x, y)).unwrap());
    assert_eq!(at(4.05, 2.0), CellState::Occupied);
    assert_eq!(at(3.0, 2.0), CellState::Free);
    assert_eq!(at(2.05, 2.05), CellState::Free);
    assert_eq!(
        at(3.5, 1.45),
        CellState::Free,
        "inside the triangle of rays"
    );
    // Behind the sensor nothing was observed.
    assert_eq!(grid.state(Cell::new(0, 0)), CellState::Unknown);
    let planning = grid.to_planning_grid(UnknownCells::Blocked);
    assert!(planning.is_blocked(Cell::new(0, 0)));
    let c = grid.occupied().cell_at(Vector2::new(3.0, 2.0)).unwrap();
    assert!(!planning.is_blocked(c));
    assert!(
        !grid
            .to_planning_grid(UnknownCells::Free)
            .is_blocked(Cell::new(0, 0))
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn distance_transform_matches_brute_force(w in 1u32..40, h in 1u32..40, density in 0u32..30, seed in any::<u64>()) {
        let grid = random_grid(w, h, density, seed);
        let d2 = squared_distance_cells(&grid);
        let obstacles: Vec<Cell> = grid.blocked_cells().collect();
        for y in 0..h {
            for x in 0..w {
                let brute = obstacles.iter().map(|o| {
                    let (dx, dy) = (f64::from(o.x) - f64::from(x), f64::from(o.y) - f64::from(y));
                    dx * dx + dy * dy
                }).fold(f64::INFINITY, f64::min);
                let got = d2[(y * w + x) as usize];
                if brute.is_finite() {
                    prop_assert!((got - brute).abs() < 1e-9, "({x}, {y}): {got} vs {brute}");
                } else {
                    prop_assert!(got >= 1e12);
                }
            }
        }
        let field = DistanceField::new(&grid.clone().with_geometry(GridGeometry::try_new(Vector2::zeros(), 0.05).unwrap()));
        if let Some(o) = obstacles.first() {
            prop_assert_eq!(field.distance(*o), Some(0.0));
        }
    }

    #[test]
    fn inflation_matches_brute_force_disc(w in 1u32..50, h in 1u32..50, density in 0u32..15, seed in any::<u64>(), radius in 0.0f64..0.6) {
        let res = 0.1;
        let grid = random_grid(w, h, density, seed).with_geometry(GridGeometry::try_new(Vector2::zeros(), res).unwrap());
        let inflated = inflate(&grid, radius).unwrap();
        let obstacles: Vec<Cell> = grid.blocked_cells().collect();
        let r = radius / res;
        for y in 0..h {
            for x in 0..w {
                let brute = obstacles.iter().any(|o| {
                    let (dx, dy) = (f64::from(o.x) - f64::from(x), f64::from(o.y) - f64::from(y));
                    dx * dx + dy * dy <= r * r + 1e-9
                });
                prop_assert_eq!(inflated.is_blocked(Cell::new(x, y)), brute, "({}, {}) r = {}", x, y, r);
            }
        }
    }
}

fn temp_dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("gridmap-test-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn ros_map_round_trip_preserves_every_cell() {
    let geometry = GridGeometry::try_new(Vector2::new(-12.35, 4.05), 0.05).unwrap();
    let mut grid = OccupancyGrid::new(77, 53, geometry, CellState::Unknown).unwrap();
    let mut r = rng(12345);
    for y in 0..53 {
        for x in 0..77 {
            let state =
                [CellState::Free, CellState::Occupied, CellState::Unknown][(r() % 3) as usize];
            grid.set(Cell::new(x, y), state).unwrap();
        }
    }
    let dir = temp_dir("ros");
    let yaml = dir.join("map.yaml");
    let pgm = write_ros_map(&grid, &yaml).unwrap();
    let bytes = std::fs::read(&pgm).unwrap();
    assert!(bytes.starts_with(b"P5"), "binary PGM");
    let back = read_ros_map(&yaml).unwrap();
    assert_eq!(back, grid);
    // The PGM's first row is the grid's top row.
    let top_left = bytes[bytes.len() - 77 * 53];
    let expect = match grid.state(Cell::new(0, 52)) {
        CellState::Occupied | CellState::Stairs => 0,
        CellState::Free => 254,
        CellState::Unknown => 205,
    };
    assert_eq!(top_left, expect);
    write_png(
        dir.join("map.png"),
        &grid,
        None,
        &[Cell::new(1, 1)],
        &[Cell::new(2, 2)],
    )
    .unwrap();
    std::fs::write(
        dir.join("bad.yaml"),
        "image: map.pgm\nresolution: 0.05\norigin: [0, 0, 0.5]\n",
    )
    .unwrap();
    assert!(matches!(
        read_ros_map(dir.join("bad.yaml")),
        Err(GridMapError::Yaml { line: 3, .. })
    ));
    std::fs::write(
        dir.join("bad2.yaml"),
        "image: map.pgm\nresolution: x\norigin: [0, 0, 0]\n",
    )
    .unwrap();
    assert!(matches!(
        read_ros_map(dir.join("bad2.yaml")),
        Err(GridMapError::Yaml { line: 2, .. })
    ));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn local_grid_fusion_under_rotation_and_offset() {
    let res = 0.1;
    let geometry = GridGeometry::try_new(Vector2::zeros(), res).unwrap();
    // Global: 100 x 100 cells, all free but a column of obstacles at x = 50.
    let mut global = OccupancyGrid::new(100, 100, geometry, CellState::Free).unwrap();
    for y in 0..100 {
        global.set(Cell::new(50, y), CellState::Occupied).unwrap();
    }
    // Local: 30 x 20 cells of 0.07 m, rotated 30 degrees, its corner at (4.2, 3.1); an obstacle
    // band in its first 5 rows, its other cells free except an unknown block.
    let (lw, lh, lres) = (30u32, 20u32, 0.07);
    let angle = 30f64.to_radians();
    let map_t_grid = Pose2::new(Vector2::new(4.2, 3.1), angle);
    let local_state = |i: u32, j: u32| {
        if j < 5 {
            LocalCell::Obstacle
        } else if i >= 25 && j >= 15 {
            LocalCell::Unknown
        } else {
            LocalCell::Free
        }
    };
    let cells = (0..lh)
        .flat_map(|j| (0..lw).map(move |i| local_state(i, j)))
        .collect();
    let local = LocalGrid {
        map_t_grid,
        resolution: lres,
        width: lw,
        height: lh,
        cells,
    };
    let before = global.clone();
    let report = fuse_local_grid(&mut global, &local).unwrap();
    // Oracle: project each global cell centre on the local axes with dot products.
    let (ax, ay) = (
        Vector2::new(angle.cos(), angle.sin()),
        Vector2::new(-angle.sin(), angle.cos()),
    );
    let (mut added, mut cleared) = (0, 0);
    for y in 0..100u32 {
        for x in 0..100u32 {
            let c = Cell::new(x, y);
            let v = geometry.cell_center(c) - Vector2::new(4.2, 3.1);
            let (u, w) = (v.dot(&ax) / lres, v.dot(&ay) / lres);
            let expect = if u >= 0.0 && w >= 0.0 && u < f64::from(lw) && w < f64::from(lh) {
                match local_state(u.floor() as u32, w.floor() as u32) {
                    LocalCell::Obstacle => CellState::Occupied,
                    LocalCell::Free => CellState::Free,
                    LocalCell::Unknown => before.state(c),
                }
            } else {
                before.state(c)
            };
            assert_eq!(global.state(c), expect, "cell {c:?}");
            if expect != before.state(c) {
                if expect == CellState::Occupied {
                    added += 1;
                } else {
                    cleared += 1;
                }
            }
        }
    }
    assert_eq!((report.added, report.cleared), (added, cleared));
    assert!(
        added > 50 && cleared > 0,
        "the test must exercise both: {added} {cleared}"
    );
    let bad = LocalGrid {
        cells: vec![],
        ..local
    };
    assert!(fuse_local_grid(&mut global, &bad).is_err());
}

#[test]
fn bad_input_gives_clear_errors() {
    let b = OccupancyGridBuilder::new(config(0.1)).unwrap();
    assert!(matches!(
        b.build(&PointCloud::new(), 0.5),
        Err(GridMapError::EmptyCloud)
    ));
    let nan = PointCloud::from_points(vec![
        Point3::new(f32::NAN, 0.0, 0.5),
        Point3::new(1.0, 1.0, 0.5),
    ]);
    assert!(matches!(
        b.build(&nan, 0.5),
        Err(GridMapError::NonFinitePoints { count: 1 })
    ));
    let floor = PointCloud::from_points(vec![Point3::new(1.0, 1.0, 0.0)]);
    assert!(matches!(
        b.build(&floor, 0.5),
        Err(GridMapError::EmptySlice { .. })
    ));
    for r in [0.0, -0.1, f64::NAN] {
        assert!(matches!(
            OccupancyGridBuilder::new(config(r)),
            Err(GridMapError::InvalidConfig(InvalidSetting {
                setting: "OccupancyGridConfig::resolution",
                ..
            }))
        ));
    }
    let far = PointCloud::from_points(vec![
        Point3::new(0.0, 0.0, 0.5),
        Point3::new(1.0e6, 1.0e6, 0.5),
    ]);
    let small = OccupancyGridBuilder::new(OccupancyGridConfig {
        max_cells: 1_000_000,
        ..config(0.1)
    })
    .unwrap();
    assert!(matches!(
        small.build(&far, 0.5),
        Err(GridMapError::TooManyCells { .. })
    ));
}

#[test]
fn inflate_refuses_negative_and_nan_radii() {
    let grid = BitGrid::from_fn(9, 9, |x, y| x == 4 && y == 4).unwrap();
    for radius in [-1.0, f64::NAN, f64::INFINITY] {
        assert!(
            matches!(inflate(&grid, radius), Err(GridMapError::InvalidConfig(_))),
            "{radius}"
        );
    }
    // Zero keeps the obstacles as they are.
    assert_eq!(inflate(&grid, 0.0).unwrap(), grid);
}

#[test]
fn ros_map_yaml_refuses_nan_thresholds_and_odd_negate() {
    let base = "image: map.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n";
    for (extra, line) in [
        ("occupied_thresh: nan\n", 4),
        ("free_thresh: NaN\n", 4),
        ("free_thresh: 1.5\n", 4),
        ("negate: nan\n", 4),
        ("negate: 2\n", 4),
    ] {
        let text = format!("{base}{extra}");
        assert!(
            matches!(
                RosMapYaml::parse(&text),
                Err(GridMapError::YamlText { line: l, .. }) if l == line
            ),
            "{extra}"
        );
    }
    let yaml = RosMapYaml::parse(&format!("{base}negate: 1\nfree_thresh: 0.25\n")).unwrap();
    assert!(yaml.negate);
    assert_eq!(yaml.free_thresh.to_bits(), 0.25f64.to_bits());
    assert_eq!(RosMapYaml::parse(&yaml.to_text()).unwrap(), yaml);
}

#[test]
fn ros_map_in_memory_matches_the_files() {
    let geometry = GridGeometry::try_new(Vector2::new(-1.5, 2.25), 0.05).unwrap();
    let mut grid = OccupancyGrid::new(5, 3, geometry, CellState::Free).unwrap();
    grid.set(Cell::new(4, 0), CellState::Occupied).unwrap();
    grid.set(Cell::new(0, 2), CellState::Unknown).unwrap();
    let yaml = ros_map_yaml(&grid, "m.pgm");
    let pgm = ros_map_pgm(&grid, std::path::Path::new("m.pgm")).unwrap();
    let back = RosMapYaml::parse(&yaml.to_text())
        .unwrap()
        .grid_from_image(&pgm)
        .unwrap();
    assert_eq!(back, grid);
    assert!(matches!(
        yaml.grid_from_image(b"P5 not an image"),
        Err(GridMapError::Image { .. })
    ));
}

#[cfg(unix)]
#[test]
fn ros_map_image_must_be_a_regular_file() {
    let dir = temp_dir("ros_dev");
    let yaml = dir.join("dev.yaml");
    std::fs::write(
        &yaml,
        "image: /dev/zero\nresolution: 0.05\norigin: [0, 0, 0]\n",
    )
    .unwrap();
    assert!(matches!(
        read_ros_map(&yaml),
        Err(GridMapError::Io { source, .. }) if source.kind() == std::io::ErrorKind::InvalidInput
    ));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Found by fuzzing (`fuzz/regressions/ros_map`): `image:' arena.pgm` read as " arena.pgm" (a
/// lone quote stripped) and was written back unquoted, so it read back as "arena.pgm".
#[test]
fn ros_map_image_names_read_back_as_written() {
    for (line, name) in [
        ("image:' arena.pgm", "' arena.pgm"),
        ("image: \" arena.pgm\"", " arena.pgm"),
        ("image: '\"a\"'", "\"a\""),
        ("image: \"\"", ""),
        ("image: maps/a:b.pgm", "maps/a:b.pgm"),
    ] {
        let yaml =
            RosMapYaml::parse(&format!("{line}\nresolution: 0.05\norigin: [0, 0, 0]\n")).unwrap();
        assert_eq!(yaml.image, name, "{line}");
        assert_eq!(RosMapYaml::parse(&yaml.to_text()).unwrap(), yaml, "{line}");
    }
}
