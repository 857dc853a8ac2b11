//! The cells walked against exact segment-square clipping, the planning layer with walked cells
//! against a brute-force distance test (built and refreshed), and a door that the full inflation
//! closes left open along the path the robot walked through it.
#![allow(clippy::unwrap_used, clippy::panic)]

use gridmap::{
    CellRect, CellState, ClearanceCostConfig, GridMapError, OccupancyGrid, PlanningGrid,
    PlanningGridConfig, UnknownCells, walked_cells,
};
use nalgebra::Vector2;
use proptest::prelude::*;
use slam_core::{BitGrid, Cell, GridGeometry, InvalidSetting};

use crate::planning_grid::{flip_cells_in, random_occupancy};
use crate::rng::rng;

const RES: f64 = 0.1;

fn geometry() -> GridGeometry {
    GridGeometry::try_new(Vector2::new(-1.0, 2.0), RES).unwrap()
}

/// Whether the segment `a`-`b` meets the closed square `[x0, x0 + s] x [y0, y0 + s]`
/// (Liang-Barsky clipping).
fn segment_meets_square(a: Vector2<f64>, b: Vector2<f64>, x0: f64, y0: f64, s: f64) -> bool {
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-d.x, a.x - x0),
        (d.x, x0 + s - a.x),
        (-d.y, a.y - y0),
        (d.y, y0 + s - a.y),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return false;
            }
        } else {
            let t = q / p;
            if p < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    t0 <= t1
}

fn random_mask(w: u32, h: u32, share: u64, seed: u64) -> BitGrid {
    let mut mask = BitGrid::new(w, h).unwrap().with_geometry(geometry());
    let mut next = rng(seed);
    for y in 0..h {
        for x in 0..w {
            if next() % 100 < share {
                mask.set(Cell::new(x, y), true).unwrap();
            }
        }
    }
    mask
}

/// Blocked cells from their definition: an obstacle cell (occupied, or unknown when unknown
/// cells block) within the inflation of the cell's centre, the inflation less the relief on the
/// cells walked.
fn brute_force_blocked(
    occupancy: &OccupancyGrid,
    walked: &BitGrid,
    config: &PlanningGridConfig,
) -> BitGrid {
    let (w, h) = (occupancy.width(), occupancy.height());
    let obstacle = |c: Cell| match occupancy.state(c) {
        CellState::Occupied | CellState::Stairs => true,
        CellState::Unknown => config.unknown == UnknownCells::Blocked,
        CellState::Free => false,
    };
    let obstacles: Vec<(f64, f64)> = (0..h)
        .flat_map(|y| (0..w).map(move |x| Cell::new(x, y)))
        .filter(|&c| obstacle(c))
        .map(|c| (f64::from(c.x), f64::from(c.y)))
        .collect();
    let mut blocked = BitGrid::new(w, h)
        .unwrap()
        .with_geometry(*occupancy.geometry());
    for y in 0..h {
        for x in 0..w {
            let c = Cell::new(x, y);
            let radius = if walked.is_blocked(c) {
                (config.inflation - config.walked_relief).max(0.0)
            } else {
                config.inflation
            } / RES;
            let near = obstacles.iter().any(|&(ox, oy)| {
                let (dx, dy) = (ox - f64::from(x), oy - f64::from(y));
                dx * dx + dy * dy <= radius * radius + 1e-9
            });
            blocked.set(c, near).unwrap();
        }
    }
    blocked
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn walked_cells_are_the_cells_the_path_crosses(
        w in 1u32..60, h in 1u32..60, seed in any::<u64>(), n in 1usize..12,
        max_step in 0.05f64..4.0,
    ) {
        let occupancy = OccupancyGrid::new(w, h, geometry(), CellState::Free).unwrap();
        let mut next = rng(seed);
        let mut unit = move || (next() >> 11) as f64 / (1u64 << 53) as f64;
        // Positions over the grid and half a metre around it.
        let (ox, oy) = (-1.5, 1.5);
        let (sx, sy) = (f64::from(w) * RES + 1.0, f64::from(h) * RES + 1.0);
        let path: Vec<Vector2<f64>> =
            (0..n).map(|_| Vector2::new(ox + unit() * sx, oy + unit() * sy)).collect();
        let walked = walked_cells(&occupancy, &path, max_step).unwrap();
        for y in 0..h {
            for x in 0..w {
                let (x0, y0) = (-1.0 + f64::from(x) * RES, 2.0 + f64::from(y) * RES);
                let crossed = path.windows(2).any(|p| {
                    (p[1] - p[0]).norm() <= max_step && segment_meets_square(p[0], p[1], x0, y0, RES)
                }) || (n == 1 && segment_meets_square(path[0], path[0], x0, y0, RES));
                prop_assert_eq!(walked.is_blocked(Cell::new(x, y)), crossed, "cell ({}, {})", x, y);
            }
        }
    }

    #[test]
    fn a_layer_with_walked_cells_blocks_by_its_definition_built_or_refreshed(
        w in 1u32..50, h in 1u32..50, density in 0u32..12, unknown in 0u32..6,
        seed in any::<u64>(), share in 0u64..100, inflation in 0.0f64..0.5,
        relief in 0.0f64..0.6, unknown_blocks in any::<bool>(),
        rect in (0u32..50, 0u32..50, 1u32..20, 1u32..20), flips in 1usize..30,
    ) {
        let mut occupancy = random_occupancy(w, h, density, unknown, seed);
        let walked = random_mask(w, h, share, seed.rotate_left(9));
        let config = PlanningGridConfig {
            unknown: if unknown_blocks { UnknownCells::Blocked } else { UnknownCells::Free },
            inflation,
            walked_relief: relief,
            point_margin: 0.05,
            cost: ClearanceCostConfig::default(),
        };
        let mut layer = PlanningGrid::new(&occupancy, config.clone())
            .unwrap()
            .with_walked(&occupancy, walked.clone())
            .unwrap();
        prop_assert_eq!(layer.blocked(), &brute_force_blocked(&occupancy, &walked, &config));
        prop_assert_eq!(layer.walked(), Some(&walked));
        // Obstacles come and go inside a rectangle: a refresh there keeps the walked relief.
        let changed = flip_cells_in(&mut occupancy, rect, flips, seed.rotate_left(23));
        layer.refresh(&occupancy, changed).unwrap();
        prop_assert_eq!(layer.blocked(), &brute_force_blocked(&occupancy, &walked, &config));
    }
}

/// The room's door is 0.9 m wide (its frame cells' centres 0.9 m apart). An inflation of
/// 0.40 m closes it; with the robot's path through it walked, the inflation less a relief of
/// 0.15 m (0.25 m) opens the cells on the path and nothing beside them. A box set down on the
/// path closes it again.
#[test]
fn a_door_walked_through_stays_open_along_the_path() {
    let mut occupancy = crate::planning_grid::room_occupancy();
    let config = PlanningGridConfig {
        inflation: 0.40,
        walked_relief: 0.15,
        ..PlanningGridConfig::default()
    };
    // Across the cross wall (its faces at x = 8.0 and 8.15 m) at the door's middle, y = 3.0.
    let path = [Vector2::new(6.0, 3.03), Vector2::new(10.0, 3.03)];
    let walked = walked_cells(&occupancy, &path, 5.0).unwrap();
    let without = PlanningGrid::new(&occupancy, config.clone()).unwrap();
    let mut layer = without
        .clone()
        .with_walked(&occupancy, walked.clone())
        .unwrap();
    let grid = layer.blocked().clone();
    let across = |grid: &BitGrid, y: f64| {
        (0..=30)
            .map(|i| Vector2::new(7.0 + 0.1 * f64::from(i), y))
            .filter(|p| grid.is_blocked(grid.cell_at(*p).unwrap()))
            .count()
    };
    assert!(
        across(without.blocked(), 3.03) > 0,
        "0.40 m closes the door"
    );
    assert_eq!(across(&grid, 3.03), 0, "the path walked is open");
    for y in [2.93, 3.13] {
        assert!(across(&grid, y) > 0, "beside the path, y = {y}: closed");
    }
    // A box on the path, in the door: blocked, the door closed along the path again.
    let box_cell = grid.cell_at(Vector2::new(9.0, 3.03)).unwrap();
    occupancy.set(box_cell, CellState::Occupied).unwrap();
    layer.refresh(&occupancy, CellRect::cell(box_cell)).unwrap();
    assert!(layer.blocked().is_blocked(box_cell));
    assert!(across(layer.blocked(), 3.03) > 0);
}

#[test]
fn bad_walked_settings_and_grids_are_errors() {
    let occupancy = random_occupancy(10, 10, 10, 0, 7);
    for relief in [f64::NAN, -0.01, f64::INFINITY] {
        let config = PlanningGridConfig {
            walked_relief: relief,
            ..PlanningGridConfig::default()
        };
        match PlanningGrid::new(&occupancy, config) {
            Err(GridMapError::InvalidConfig(InvalidSetting { setting, .. })) => {
                assert_eq!(setting, "PlanningGridConfig::walked_relief");
            }
            other => panic!("{relief}: {other:?}"),
        }
    }
    for step in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        match walked_cells(&occupancy, &[Vector2::zeros()], step) {
            Err(GridMapError::InvalidConfig(InvalidSetting { setting, .. })) => {
                assert_eq!(setting, "walked_cells::max_step");
            }
            other => panic!("{step}: {other:?}"),
        }
    }
    let layer = PlanningGrid::new(&occupancy, PlanningGridConfig::default()).unwrap();
    let wrong_size = BitGrid::new(11, 10).unwrap().with_geometry(geometry());
    let wrong_place = BitGrid::new(10, 10).unwrap();
    for mask in [wrong_size, wrong_place] {
        assert!(matches!(
            layer.clone().with_walked(&occupancy, mask),
            Err(GridMapError::GeometryMismatch)
        ));
    }
    // Non-finite positions are skipped with their segments, not an error.
    let path = [
        Vector2::new(-0.95, 2.05),
        Vector2::new(f64::NAN, 2.05),
        Vector2::new(-0.55, 2.05),
    ];
    let walked = walked_cells(&occupancy, &path, 1.0).unwrap();
    assert!((0..10).all(|x| (0..10).all(|y| !walked.is_blocked(Cell::new(x, y)))));
}
