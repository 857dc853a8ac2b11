//! Stairs on a floor's grid: a flight found from a walk over it among walls, a ceiling and the
//! floors at its ends (the oracle: the flight's own geometry, built here), the stairs state
//! through the grid, the planning layer and the ROS map, and bad input refused by name.

#![allow(clippy::unwrap_used, clippy::panic)]

use gridmap::{
    CellState, Climb, GridMapError, OccupancyGrid, StairsConfig, UnknownCells, ros_map_pgm,
    stairs_cells,
};
use nalgebra::{Point3, Vector2};
use slam_core::{BitGrid, Cell, GridGeometry};

/// Rise, tread and steps of the flight: 0.2 m x 0.3 m, 14 steps then the upper floor at 3 m.
const RISE: f64 = 0.2;
const TREAD: f64 = 0.3;
const STEPS: usize = 14;

/// A flight along +x from x = 2 m (its foot) to x = 6.2 m (its top), 1.2 m wide (y 1 to 2.2),
/// sampled every 2 cm where a sensor on it would see: every step's tread and riser (the back
/// third of each tread hidden, as a climbing sensor leaves it), a wall along y = 2.2 m, the
/// lower floor before the foot and in a lane beside the flight (y 0 to 0.9 m), the slab's
/// underside over the lane near the top (2.8 m, seen from below), and the upper floor past the
/// top; each with the position of the sensor that saw it.
fn flight_points() -> Vec<(Point3<f64>, Point3<f64>)> {
    // Every surface seen from 1 m above it, but the ceiling, seen from the lane below.
    let up = nalgebra::Vector3::new(0.0, 0.0, 1.0);
    surfaces()
        .into_iter()
        .map(|p| {
            (
                p,
                if (p.z - 2.8).abs() < 1e-9 && p.y < 0.9 {
                    p - 2.0 * up
                } else {
                    p + up
                },
            )
        })
        .collect()
}

/// The surfaces of [`flight_points`].
fn surfaces() -> Vec<Point3<f64>> {
    let mut points = Vec::new();
    let grid = |x0: f64, x1: f64, y0: f64, y1: f64| {
        let (nx, ny) = (((x1 - x0) / 0.02) as usize, ((y1 - y0) / 0.02) as usize);
        (0..nx).flat_map(move |i| {
            (0..ny).map(move |j| (x0 + 0.02 * i as f64 + 0.01, y0 + 0.02 * j as f64 + 0.01))
        })
    };
    for k in 1..=STEPS {
        let x0 = 2.0 + (k - 1) as f64 * TREAD;
        let z = k as f64 * RISE;
        // The front two thirds of the tread.
        points.extend(grid(x0, x0 + 0.2, 1.0, 2.2).map(|(x, y)| Point3::new(x, y, z)));
        // Its riser.
        for j in 0..60 {
            for h in 0..10 {
                points.push(Point3::new(
                    x0,
                    1.01 + 0.02 * f64::from(j),
                    z - RISE + 0.02 * f64::from(h) + 0.01,
                ));
            }
        }
    }
    // The lower floor before the foot and the lane beside the flight.
    points.extend(grid(0.0, 2.0, 0.0, 2.2).map(|(x, y)| Point3::new(x, y, 0.0)));
    points.extend(grid(2.0, 7.0, 0.0, 0.9).map(|(x, y)| Point3::new(x, y, 0.0)));
    // The slab's underside over the lane near the top, and the upper floor past the top.
    points.extend(grid(4.5, 6.2, 0.0, 0.9).map(|(x, y)| Point3::new(x, y, 2.8)));
    points.extend(grid(6.2, 7.5, 0.0, 2.2).map(|(x, y)| Point3::new(x, y, 3.0)));
    // The wall beside the flight, from the lower floor to 4 m.
    for i in 0..300 {
        for h in 0..200 {
            points.push(Point3::new(
                1.0 + 0.02 * f64::from(i),
                2.21,
                0.02 * f64::from(h),
            ));
        }
    }
    points
}

/// The walk up the flight's middle, its ground a ramp through the step tops, from 1 m before
/// the foot to 1 m past the top.
fn walk() -> Vec<Point3<f64>> {
    let run = STEPS as f64 * TREAD;
    (0..=70)
        .map(|i| {
            let x = 1.0 + f64::from(i) * 0.1;
            let z = ((x - 2.0 + 0.5 * TREAD) / run * (STEPS + 1) as f64 * RISE).clamp(0.0, 3.0);
            Point3::new(x, 1.6, z)
        })
        .collect()
}

fn grid() -> OccupancyGrid {
    let g = GridGeometry::try_new(Vector2::new(-0.5, -0.5), 0.1).unwrap();
    OccupancyGrid::new(90, 40, g, CellState::Free).unwrap()
}

#[test]
fn a_flight_among_a_wall_a_ceiling_and_two_floors_is_found_cell_for_cell() {
    let mut grid = grid();
    let track = walk();
    let climb = Climb {
        track: &track,
        lower: 0.0,
        upper: 3.0,
    };
    let stairs = stairs_cells(&grid, flight_points(), &climb, &StairsConfig::default()).unwrap();
    grid.mark_stairs(&stairs).unwrap();
    let run = STEPS as f64 * TREAD;
    for y in 0..grid.height() {
        for x in 0..grid.width() {
            let cell = Cell::new(x, y);
            let c = grid.geometry().cell_center(cell);
            // Cell centres at least half a cell inside the flight are stairs; none outside it
            // by more than a cell.
            let inside = c.x > 2.05 && c.x < 2.0 + run - 0.05 && c.y > 1.05 && c.y < 2.15;
            let near = c.x > 1.9 && c.x < 2.0 + run + 0.1 && c.y > 0.9 && c.y < 2.3;
            let state = grid.state(cell);
            if inside {
                assert_eq!(state, CellState::Stairs, "{c}");
            } else if !near {
                assert_ne!(state, CellState::Stairs, "{c}");
            }
        }
    }
    // The ceiling over the lane and the floors are no stairs.
    let at = |x: f64, y: f64| grid.state(stairs.cell_at(Vector2::new(x, y)).unwrap());
    assert_eq!(at(5.5, 0.5), CellState::Free, "under the ceiling");
    assert_eq!(at(1.5, 1.6), CellState::Free, "before the foot");
    assert_eq!(at(6.8, 1.6), CellState::Free, "past the top");
}

#[test]
fn stairs_cells_are_blocked_for_planning_counted_apart_and_written_occupied() {
    let mut grid = grid();
    let g = *grid.geometry();
    let mut marks = BitGrid::new(grid.width(), grid.height())
        .unwrap()
        .with_geometry(g);
    for x in 10..20 {
        marks.set(Cell::new(x, 5), true).unwrap();
    }
    grid.set(Cell::new(10, 5), CellState::Occupied).unwrap();
    grid.set(Cell::new(30, 30), CellState::Unknown).unwrap();
    let before = grid.clone();
    grid.mark_stairs(&marks).unwrap();
    assert_eq!(
        grid.state(Cell::new(10, 5)),
        CellState::Stairs,
        "was occupied"
    );
    assert_eq!(grid.state(Cell::new(15, 5)), CellState::Stairs, "was free");
    assert_eq!(grid.state(Cell::new(20, 5)), CellState::Free);
    assert_eq!(grid.stairs().count_blocked(), 10);
    let (free, occupied, unknown) = grid.counts();
    assert_eq!((occupied, unknown), (0, 1));
    assert_eq!(free, 90 * 40 - 10 - 1);
    for unknown in [UnknownCells::Free, UnknownCells::Blocked] {
        let planning = grid.to_planning_grid(unknown);
        assert!(planning.is_blocked(Cell::new(15, 5)));
        assert!(!planning.is_blocked(Cell::new(20, 5)));
        assert_eq!(
            planning.is_blocked(Cell::new(30, 30)),
            unknown == UnknownCells::Blocked
        );
    }
    let changed = grid.changed_from(&before).unwrap();
    assert_eq!(
        (changed.x0, changed.y0, changed.x1, changed.y1),
        (10, 5, 20, 6)
    );
    // Setting a cell clears its stairs mark.
    grid.set(Cell::new(11, 5), CellState::Free).unwrap();
    assert_eq!(grid.state(Cell::new(11, 5)), CellState::Free);
    // The PGM: stairs as occupied (0), its first row the grid's top row.
    let pgm = ros_map_pgm(&grid, std::path::Path::new("stairs.pgm")).unwrap();
    let row = grid.height() - 1 - 5;
    let at = pgm.len() - (grid.width() * grid.height()) as usize + (row * grid.width()) as usize;
    assert_eq!(pgm[at + 15], 0);
    assert_eq!(pgm[at + 20], 254);
    // A mark of another size is refused.
    let small = BitGrid::new(5, 5).unwrap().with_geometry(g);
    assert!(matches!(
        grid.mark_stairs(&small),
        Err(GridMapError::GeometryMismatch)
    ));
}

#[test]
#[allow(clippy::too_many_lines)] // one list of bad inputs
fn a_climb_or_settings_that_cannot_be_used_are_refused_by_name() {
    let grid = grid();
    let track = walk();
    let named = |r: Result<BitGrid, GridMapError>, name: &str| match r {
        Err(GridMapError::InvalidConfig(e)) => assert_eq!(e.setting, name),
        other => panic!("{name}: {other:?}"),
    };
    let ok = Climb {
        track: &track,
        lower: 0.0,
        upper: 3.0,
    };
    let config = StairsConfig::default();
    named(
        stairs_cells(
            &grid,
            [],
            &Climb {
                track: &track[..1],
                ..ok
            },
            &config,
        ),
        "Climb::track",
    );
    named(
        stairs_cells(&grid, [], &Climb { upper: 0.1, ..ok }, &config),
        "Climb::upper",
    );
    named(
        stairs_cells(
            &grid,
            [],
            &Climb {
                lower: f64::NAN,
                ..ok
            },
            &config,
        ),
        "Climb::lower",
    );
    let mut broken = track.clone();
    broken[3].z = f64::INFINITY;
    assert!(matches!(
        stairs_cells(
            &grid,
            [],
            &Climb {
                track: &broken,
                ..ok
            },
            &config
        ),
        Err(GridMapError::NonFinitePosition { index: 3 })
    ));
    for (bad, name) in [
        (
            StairsConfig {
                reach: 0.0,
                ..config
            },
            "StairsConfig::reach",
        ),
        (
            StairsConfig {
                tread_tolerance: f64::NAN,
                ..config
            },
            "StairsConfig::tread_tolerance",
        ),
        (
            StairsConfig {
                clear_from: 0.1,
                ..config
            },
            "StairsConfig::clear_from",
        ),
        (
            StairsConfig {
                headroom: 0.3,
                ..config
            },
            "StairsConfig::headroom",
        ),
        (
            StairsConfig {
                min_points: 0,
                ..config
            },
            "StairsConfig::min_points",
        ),
        (
            StairsConfig {
                min_step: -1.0,
                ..config
            },
            "StairsConfig::min_step",
        ),
    ] {
        named(stairs_cells(&grid, [], &ok, &bad), name);
    }
    // A walk far off the grid finds nothing.
    let away: Vec<Point3<f64>> = track
        .iter()
        .map(|p| p + nalgebra::Vector3::new(100.0, 0.0, 0.0))
        .collect();
    let none = stairs_cells(
        &grid,
        flight_points(),
        &Climb { track: &away, ..ok },
        &config,
    )
    .unwrap();
    assert_eq!(none.count_blocked(), 0);
}
