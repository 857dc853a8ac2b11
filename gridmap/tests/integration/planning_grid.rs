//! The planning layer against brute force: its blocked cells are `inflate`'s, its clearance the
//! distance field's (capped), a refresh over a changed rectangle equals a rebuild, and a 0.9 m
//! door stays open under the hard inflation that a 0.40 m inflation closes.
#![allow(clippy::unwrap_used, clippy::panic)]

use gridmap::{
    CellRect, CellState, ClearanceCostConfig, DistanceField, FloorConfig, FloorMap, GridMapError,
    ObstacleBandConfig, OccupancyGrid, OccupancyGridBuilder, OccupancyGridConfig, PlanningGrid,
    PlanningGridConfig, UnknownCells, clearance_step_costs, inflate,
};
use nalgebra::{Point3, Vector2};
use proptest::prelude::*;
use slam_core::{Cell, GridGeometry, InvalidSetting};

use crate::rng::rng;

/// A grid of `w` x `h` cells of 0.1 m at (-1, 2): `density` % occupied, `unknown` % unknown.
pub fn random_occupancy(w: u32, h: u32, density: u32, unknown: u32, seed: u64) -> OccupancyGrid {
    let geometry = GridGeometry::try_new(Vector2::new(-1.0, 2.0), 0.1).unwrap();
    let mut grid = OccupancyGrid::new(w, h, geometry, CellState::Free).unwrap();
    let mut next = rng(seed);
    for y in 0..h {
        for x in 0..w {
            let r = (next() % 1000) as u32;
            let state = if r < density * 10 {
                CellState::Occupied
            } else if r < (density + unknown) * 10 {
                CellState::Unknown
            } else {
                CellState::Free
            };
            grid.set(Cell::new(x, y), state).unwrap();
        }
    }
    grid
}

fn config(unknown: bool, inflation: f64, weight: f64) -> PlanningGridConfig {
    PlanningGridConfig {
        unknown: if unknown {
            UnknownCells::Blocked
        } else {
            UnknownCells::Free
        },
        inflation,
        walked_relief: 0.05,
        // Cells set by hand have no points: the margin would only move the clearances' cap.
        point_margin: 0.0,
        cost: ClearanceCostConfig {
            weight,
            ..ClearanceCostConfig::default()
        },
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn layer_matches_inflate_and_the_distance_field(
        w in 1u32..90, h in 1u32..90, density in 0u32..20, unknown in 0u32..10, seed in any::<u64>(),
        blocked in any::<bool>(), inflation in 0.0f64..0.6, weight in prop_oneof![Just(0.0), 0.0f64..5.0],
    ) {
        let occupancy = random_occupancy(w, h, density, unknown, seed);
        let cfg = config(blocked, inflation, weight);
        let layer = PlanningGrid::new(&occupancy, cfg.clone()).unwrap();
        let obstacles = occupancy.to_planning_grid(cfg.unknown);
        prop_assert_eq!(layer.blocked(), &inflate(&obstacles, inflation).unwrap());
        let field = DistanceField::new(&obstacles);
        let reach = if weight > 0.0 { inflation.max(1.0) } else { inflation };
        let costs = clearance_step_costs(&field, &cfg.cost).unwrap();
        for (i, (&d, &c)) in layer.clearance().iter().zip(layer.step_costs()).enumerate() {
            let want = field.as_slice()[i].min(reach as f32);
            prop_assert!((d - want).abs() < 1e-5, "cell {}: {} vs {}", i, d, want);
            prop_assert!(c >= 1.0);
            if field.as_slice()[i] <= reach as f32 {
                prop_assert!((c - costs[i]).abs() < 1e-5);
            }
            if weight == 0.0 {
                prop_assert!((c - 1.0).abs() < f32::EPSILON);
            }
        }
        prop_assert_eq!(layer.cost_enabled(), weight > 0.0);
    }

    #[test]
    fn refresh_of_a_changed_rectangle_equals_a_rebuild(
        w in 1u32..120, h in 1u32..120, density in 0u32..15, seed in any::<u64>(),
        rect in (0u32..120, 0u32..120, 1u32..40, 1u32..40), flips in 1usize..60,
        weight in prop_oneof![Just(0.0), 0.5f64..4.0],
    ) {
        let mut occupancy = random_occupancy(w, h, density, 5, seed);
        let cfg = config(seed % 2 == 0, 0.3, weight);
        let mut layer = PlanningGrid::new(&occupancy, cfg.clone()).unwrap();
        // The roomy mask asked for before the change is kept and refreshed with the layer.
        let min_clearance = 0.45;
        let _ = layer.roomy(min_clearance);
        let changed = flip_cells_in(&mut occupancy, rect, flips, seed.rotate_left(17));
        let written = layer.refresh(&occupancy, changed).unwrap();
        prop_assert!(written.len() >= changed.len());
        let rebuilt = PlanningGrid::new(&occupancy, cfg).unwrap();
        prop_assert_eq!(layer.blocked(), rebuilt.blocked());
        for (a, b) in layer.clearance().iter().zip(rebuilt.clearance()) {
            prop_assert!((a - b).abs() < 1e-6);
        }
        prop_assert_eq!(layer.step_costs(), rebuilt.step_costs());
        // Against the mask from its definition on the rebuilt layer: blocked, or nearer an
        // obstacle than the clearance.
        let mut want = rebuilt.blocked().clone();
        for (k, &d) in rebuilt.clearance().iter().enumerate() {
            if d < min_clearance as f32 {
                want.set(Cell::new(k as u32 % w, k as u32 / w), true).unwrap();
            }
        }
        prop_assert_eq!(&*layer.roomy(min_clearance), &want);
        prop_assert_eq!(&*rebuilt.roomy(min_clearance), &want);
        prop_assert_eq!(&*layer.roomy(0.7), &*rebuilt.roomy(0.7));
        // Careless clearances: none, negative, NaN add nothing; beyond the reach, everything.
        for nothing in [0.0, -1.0, f64::NAN] {
            prop_assert_eq!(&*layer.roomy(nothing), rebuilt.blocked());
        }
        let everything = layer.roomy(1e9);
        prop_assert!((0..h).all(|y| (0..w).all(|x| everything.is_blocked(Cell::new(x, y)))));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// `changed_from` is the bounding box of the cells whose state differs (the oracle: every
    /// cell compared), and refreshing over it matches a rebuild.
    #[test]
    fn the_changed_rectangle_bounds_every_changed_cell(
        w in 1u32..150, h in 1u32..60, density in 0u32..15, seed in any::<u64>(),
        rect in (0u32..150, 0u32..60, 1u32..70, 1u32..30), flips in 0usize..40,
    ) {
        let earlier = random_occupancy(w, h, density, 5, seed);
        let mut now = earlier.clone();
        flip_cells_in(&mut now, rect, flips, seed.rotate_left(9));
        let changed = now.changed_from(&earlier).unwrap();
        let differing: Vec<Cell> = (0..h)
            .flat_map(|y| (0..w).map(move |x| Cell::new(x, y)))
            .filter(|&c| now.state(c) != earlier.state(c))
            .collect();
        let mut want = CellRect { x0: 0, y0: 0, x1: 0, y1: 0 };
        for c in &differing {
            want = want.union(&CellRect::cell(*c));
        }
        prop_assert_eq!(changed.is_empty(), differing.is_empty());
        if !differing.is_empty() {
            prop_assert_eq!(changed, want);
        }
        let cfg = config(seed % 2 == 0, 0.3, 1.0);
        let mut layer = PlanningGrid::new(&earlier, cfg.clone()).unwrap();
        layer.refresh(&now, changed).unwrap();
        let rebuilt = PlanningGrid::new(&now, cfg).unwrap();
        prop_assert_eq!(layer.blocked(), rebuilt.blocked());
        prop_assert_eq!(layer.step_costs(), rebuilt.step_costs());
    }
}

#[test]
fn grids_of_another_size_or_place_have_no_changed_rectangle() {
    let a = random_occupancy(20, 10, 5, 5, 1);
    let b = random_occupancy(21, 10, 5, 5, 1);
    assert!(matches!(
        a.changed_from(&b),
        Err(GridMapError::GeometryMismatch)
    ));
}

/// `flips` random cells of the rectangle `rect` (x, y taken modulo the grid, then width and
/// height, clipped to the grid) set to random states; returns that rectangle.
pub fn flip_cells_in(
    occupancy: &mut OccupancyGrid,
    rect: (u32, u32, u32, u32),
    flips: usize,
    seed: u64,
) -> CellRect {
    let (w, h) = (occupancy.width(), occupancy.height());
    let (x0, y0) = (rect.0 % w, rect.1 % h);
    let changed = CellRect {
        x0,
        y0,
        x1: (x0 + rect.2).min(w),
        y1: (y0 + rect.3).min(h),
    };
    let mut r = rng(seed);
    for _ in 0..flips {
        let s = r();
        let x = changed.x0 + (s % u64::from(changed.x1 - changed.x0)) as u32;
        let y = changed.y0 + ((s >> 20) % u64::from(changed.y1 - changed.y0)) as u32;
        let state =
            [CellState::Free, CellState::Occupied, CellState::Unknown][(s >> 40) as usize % 3];
        occupancy.set(Cell::new(x, y), state).unwrap();
    }
    changed
}

/// The room's door is 0.9 m wide; on the map its frame cells' centres are 0.9 m apart (8 free
/// cells). The hard inflation of 0.30 m leaves two cells open, 0.40 m closes it.
/// The occupancy of `common::room` (its floor 0.8 m below the sensor), from its surfaces
/// sampled every 4 cm.
pub fn room_occupancy() -> OccupancyGrid {
    let world = crate::common::room(-0.8);
    let cloud = world.surface_cloud(-0.15, -0.15, 12.15, 6.15, 0.04);
    let floor = FloorMap::estimate(
        &cloud,
        &[Point3::new(1.0, 3.0, -0.8)],
        &FloorConfig::default(),
    )
    .unwrap();
    OccupancyGridBuilder::new(OccupancyGridConfig::default())
        .unwrap()
        .build_floor_band(&cloud, &floor, &ObstacleBandConfig::default())
        .unwrap()
}

#[test]
fn a_door_of_0_9_m_stays_open_under_the_hard_inflation() {
    let occupancy = room_occupancy();
    // Rows open across the whole cross wall (its faces at x = 8.0 and 8.15 m).
    let columns: Vec<u32> = [7.95, 8.05, 8.15, 8.25]
        .iter()
        .map(|&x| {
            occupancy
                .occupied()
                .cell_at(Vector2::new(x, 3.0))
                .unwrap()
                .x
        })
        .collect();
    let open_rows = |grid: &slam_core::BitGrid| -> Vec<f64> {
        (0..grid.height())
            .filter(|&y| columns.iter().all(|&x| !grid.is_blocked(Cell::new(x, y))))
            .map(|y| grid.cell_center(Cell::new(columns[0], y)).y)
            .filter(|y| (1.0..5.0).contains(y))
            .collect()
    };
    let door: Vec<f64> = open_rows(occupancy.occupied());
    assert_eq!(door.len(), 8, "the map shows the door 0.8 m wide: {door:?}");
    let layer = PlanningGrid::new(&occupancy, PlanningGridConfig::default()).unwrap();
    let open = open_rows(layer.blocked());
    assert_eq!(open.len(), 2, "{open:?}");
    assert!(open.iter().all(|y| (y - 3.0).abs() < 0.1));
    assert!(open_rows(&inflate(occupancy.occupied(), 0.40).unwrap()).is_empty());
    // In the door, 0.4-0.5 m from the frame's points, less the 0.05 m point margin:
    // multipliers 1 + 2 ((1 - d) / 0.7)^2.
    for y in open {
        let cell = layer.blocked().cell_at(Vector2::new(8.07, y)).unwrap();
        let i = (cell.y * layer.blocked().width() + cell.x) as usize;
        let d = f64::from(layer.clearance()[i]);
        assert!((0.34..0.51).contains(&d), "{d}");
        let want = 1.0 + 2.0 * ((1.0 - d) / 0.7).powi(2);
        assert!((f64::from(layer.step_costs()[i]) - want).abs() < 1e-5);
    }
    // In the room's middle, 3 m from the walls: no penalty.
    let mid = layer.blocked().cell_at(Vector2::new(4.0, 2.0)).unwrap();
    let i = (mid.y * layer.blocked().width() + mid.x) as usize;
    assert!((layer.step_costs()[i] - 1.0).abs() < f32::EPSILON);
}

#[test]
fn bad_settings_are_errors() {
    let occupancy = random_occupancy(10, 10, 10, 0, 7);
    let cases: Vec<(PlanningGridConfig, &str)> = vec![
        (config(true, f64::NAN, 1.0), "PlanningGridConfig::inflation"),
        (config(true, -0.1, 1.0), "PlanningGridConfig::inflation"),
        (config(true, 1e9, 1.0), "PlanningGridConfig::inflation"),
        (config(true, 0.3, f64::NAN), "ClearanceCostConfig::weight"),
        (config(true, 0.3, -1.0), "ClearanceCostConfig::weight"),
        (
            PlanningGridConfig {
                cost: ClearanceCostConfig {
                    full_within: f64::NAN,
                    ..ClearanceCostConfig::default()
                },
                ..PlanningGridConfig::default()
            },
            "ClearanceCostConfig::full_within",
        ),
        (
            PlanningGridConfig {
                cost: ClearanceCostConfig {
                    zero_beyond: 0.2,
                    ..ClearanceCostConfig::default()
                },
                ..PlanningGridConfig::default()
            },
            "ClearanceCostConfig::zero_beyond",
        ),
    ];
    let margin = |m: f64| {
        (
            PlanningGridConfig {
                point_margin: m,
                ..PlanningGridConfig::default()
            },
            "PlanningGridConfig::point_margin",
        )
    };
    let cases: Vec<_> = cases
        .into_iter()
        .chain([f64::NAN, -0.01, f64::INFINITY, 2.0].map(margin))
        .collect();
    for (cfg, name) in cases {
        match PlanningGrid::new(&occupancy, cfg) {
            Err(GridMapError::InvalidConfig(InvalidSetting { setting, .. })) => {
                assert_eq!(setting, name);
            }
            other => panic!("{name}: {other:?}"),
        }
    }
    let mut layer = PlanningGrid::new(&occupancy, PlanningGridConfig::default()).unwrap();
    let other = random_occupancy(11, 10, 10, 0, 7);
    let all = CellRect {
        x0: 0,
        y0: 0,
        x1: 10,
        y1: 10,
    };
    assert!(matches!(
        layer.refresh(&other, all),
        Err(GridMapError::GeometryMismatch)
    ));
    assert!(layer.refresh(&occupancy, all).is_ok());
}
