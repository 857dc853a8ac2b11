//! A gap beside a dropped box, a few centimetres wider (or narrower) than the robot needs at
//! its hard inflation and point margin: the planning layer reads it open (or shut) wherever the grid's cells fall
//! against the box's edge and the wall, and whether the box is seen close by (its face) or from
//! afar (its top, sparser), because clearance is measured from the obstacles' points, not from
//! their cells' centres.
#![allow(clippy::unwrap_used, clippy::panic)]

use gridmap::{CellState, OccupancyGrid, PlanningGrid, PlanningGridConfig};
use nalgebra::Vector2;
use slam_core::{BitGrid, Cell, GridGeometry};

/// Where the box is seen from.
#[derive(Clone, Copy, Debug)]
enum View {
    /// Its west face, a point every 2 cm.
    Near,
    /// Its top, a point every 7 cm from the west edge in.
    Far,
}

/// The wall's face (x metres, facing east), the box's west face and its side (0.6 m).
const WALL: f64 = 2.0;
const BOX: f64 = 0.6;
const BOX_Y: (f64, f64) = (2.0, 2.6);

/// A known-free grid of 0.1 m cells, its origin `shift` metres west of a whole metre, holding a
/// wall along x = `WALL` and a 0.6 m box whose west face lies `gap` metres east of it, seen
/// from `view`: each point marks its cell occupied with the box round that cell's points.
fn scene(shift: f64, gap: f64, view: View) -> OccupancyGrid {
    let geometry = GridGeometry::try_new(Vector2::new(-shift, 0.0), 0.1).unwrap();
    let mut grid = OccupancyGrid::new(60, 50, geometry, CellState::Free).unwrap();
    let mut add = |p: Vector2<f64>| {
        let ((x, y), extent) = gridmap::CellExtent::of_point(&geometry, p);
        let cell = Cell::new(u32::try_from(x).unwrap(), u32::try_from(y).unwrap());
        let before = grid.extent(cell).unwrap_or(extent);
        grid.set_occupied_within(cell, before.union(extent))
            .unwrap();
    };
    for i in 0..=200 {
        add(Vector2::new(WALL, 0.02 * f64::from(i)));
    }
    let west = WALL + gap;
    match view {
        View::Near => {
            for i in 0..=30 {
                add(Vector2::new(west, BOX_Y.0 + 0.02 * f64::from(i)));
            }
        }
        View::Far => {
            for i in 0..=8 {
                for j in 0..=8 {
                    let (dx, dy) = (0.07 * f64::from(i), 0.07 * f64::from(j) + 0.01);
                    add(Vector2::new(west + dx.min(BOX), BOX_Y.0 + dy.min(BOX)));
                }
            }
        }
    }
    grid
}

/// Whether a lane of cells runs free past the box between it and the wall (`gap` metres apart):
/// a column whose cells are free in every row from 0.4 m south of the box to 0.4 m north of it.
fn lane_past_the_box(blocked: &BitGrid, gap: f64) -> bool {
    let rows: Vec<u32> = (0..blocked.height())
        .filter(|&y| {
            let c = blocked.cell_center(Cell::new(0, y)).y;
            (BOX_Y.0 - 0.4..=BOX_Y.1 + 0.4).contains(&c)
        })
        .collect();
    (0..blocked.width())
        .filter(|&x| {
            let c = blocked.cell_center(Cell::new(x, 0)).x;
            c > WALL && c < WALL + gap
        })
        .any(|x| rows.iter().all(|&y| !blocked.is_blocked(Cell::new(x, y))))
}

#[test]
fn a_gap_a_few_cm_wider_than_the_robot_reads_open_wherever_the_cells_fall() {
    // 0.30 m each side and the 0.05 m point margin: 0.70 m needed. 0.82 m leaves 12 cm, more
    // than a cell, so a column of centres always falls in it; 0.66 m leaves none.
    for view in [View::Near, View::Far] {
        for k in 0..20 {
            let shift = 0.005 * f64::from(k);
            for (gap, open) in [(0.82, true), (0.66, false)] {
                let planning =
                    PlanningGrid::new(&scene(shift, gap, view), PlanningGridConfig::default())
                        .unwrap();
                assert_eq!(
                    lane_past_the_box(planning.blocked(), gap),
                    open,
                    "gap {gap} m, cells shifted {shift:.3} m, seen {view:?}"
                );
            }
        }
    }
}

#[test]
fn cells_with_no_points_recorded_read_as_their_centres() {
    // The same scene with every occupied cell set by hand: the clearance between centres, which
    // shuts the wider gap or opens the narrower one for some placements of the cells.
    let mut wrong = 0;
    for k in 0..20 {
        let shift = 0.005 * f64::from(k);
        for (gap, open) in [(0.72, true), (0.56, false)] {
            let mut grid = scene(shift, gap, View::Near);
            for y in 0..grid.height() {
                for x in 0..grid.width() {
                    let c = Cell::new(x, y);
                    if grid.state(c) == CellState::Occupied {
                        grid.set(c, CellState::Occupied).unwrap();
                        assert!(grid.extent(c).unwrap().is_centre());
                    }
                }
            }
            let planning = PlanningGrid::new(&grid, PlanningGridConfig::default()).unwrap();
            wrong += usize::from(lane_past_the_box(planning.blocked(), gap) != open);
        }
    }
    assert!(wrong > 0, "the centres read every placement right");
}
