//! JPS+ preprocessing (Harabor & Grastien 2014; Rabin's GDC 2015 formulation): for every free
//! cell and each of the 8 directions, the number of steps to the next jump point (positive) or to
//! the last free cell before a wall (zero or negative), so a query jumps in O(1).

use slam_core::{BitGrid, Cell};

use crate::jump_search::Jumper;
use crate::movement::{DIRECTIONS, can_step, free};

/// Jump distances, 8 per cell (`i16`: 16 bytes per cell).
pub(crate) struct JumpTables {
    width: u32,
    /// `dist[cell * 8 + direction]`.
    dist: Vec<i16>,
}

/// Largest grid side the `i16` tables can describe.
pub(crate) const MAX_TABLE_SIDE: u32 = i16::MAX as u32;

/// Most cells a grid may have for JPS+ tables: 2^28 (16,384 x 16,384), 4 GiB of tables.
pub const MAX_JUMP_TABLE_CELLS: u64 = 1 << 28;

impl JumpTables {
    /// Build the tables; the caller checks both sides are at most [`MAX_TABLE_SIDE`] and the cells
    /// at most [`MAX_JUMP_TABLE_CELLS`].
    pub(crate) fn new(grid: &BitGrid) -> Self {
        let (w, h) = (grid.width(), grid.height());
        let mut t = Self {
            width: w,
            dist: vec![0; w as usize * h as usize * 8],
        };
        // Straight directions: walk each line against the direction so the next cell is known.
        for d in 0..4u8 {
            let (dx, dy) = DIRECTIONS[d as usize];
            let (dx, dy) = (i64::from(dx), i64::from(dy));
            let (xs, ys) = (against(w, dx), against(h, dy));
            for &y in &ys {
                for &x in &xs {
                    if !free(grid, x, y) {
                        continue;
                    }
                    let (nx, ny) = (x + dx, y + dy);
                    let v = if !free(grid, nx, ny) {
                        0
                    } else if straight_forced(grid, nx, ny, dx, dy) {
                        1
                    } else {
                        let n = t.get(nx as u32, ny as u32, d);
                        if n > 0 { n + 1 } else { n - 1 }
                    };
                    t.set(x as u32, y as u32, d, v);
                }
            }
        }
        // Diagonals: a cell is a jump point when a straight component from it has one.
        for d in 4..8u8 {
            let (dx, dy) = DIRECTIONS[d as usize];
            let (dx, dy) = (i64::from(dx), i64::from(dy));
            let (hd, vd) = (u8::from(dx < 0), if dy > 0 { 2 } else { 3 });
            let (xs, ys) = (against(w, dx), against(h, dy));
            for &y in &ys {
                for &x in &xs {
                    if !free(grid, x, y) {
                        continue;
                    }
                    let v = if can_step(grid, x, y, dx, dy) {
                        let (nx, ny) = ((x + dx) as u32, (y + dy) as u32);
                        if t.get(nx, ny, hd) > 0 || t.get(nx, ny, vd) > 0 {
                            1
                        } else {
                            let n = t.get(nx, ny, d);
                            if n > 0 { n + 1 } else { n - 1 }
                        }
                    } else {
                        0
                    };
                    t.set(x as u32, y as u32, d, v);
                }
            }
        }
        t
    }

    #[inline]
    fn get(&self, x: u32, y: u32, d: u8) -> i16 {
        self.dist[(y as usize * self.width as usize + x as usize) * 8 + d as usize]
    }

    #[inline]
    fn set(&mut self, x: u32, y: u32, d: u8, v: i16) {
        self.dist[(y as usize * self.width as usize + x as usize) * 8 + d as usize] = v;
    }

    /// Bytes used.
    pub(crate) fn bytes(&self) -> usize {
        self.dist.len() * std::mem::size_of::<i16>()
    }
}

/// The coordinates `0..len` in the order that reaches each one after its neighbour a step of
/// sign `step` away (descending for a positive step): walking against the direction, the next
/// cell's distance is known when a cell is reached.
fn against(len: u32, step: i64) -> Vec<i64> {
    if step > 0 {
        (0..i64::from(len)).rev().collect()
    } else {
        (0..i64::from(len)).collect()
    }
}

/// Whether a straight move by `(dx, dy)` arriving at `(x, y)` has a forced side there.
fn straight_forced(grid: &BitGrid, x: i64, y: i64, dx: i64, dy: i64) -> bool {
    if dx != 0 {
        (free(grid, x, y + 1) && !free(grid, x - dx, y + 1))
            || (free(grid, x, y - 1) && !free(grid, x - dx, y - 1))
    } else {
        (free(grid, x + 1, y) && !free(grid, x + 1, y - dy))
            || (free(grid, x - 1, y) && !free(grid, x - 1, y - dy))
    }
}

impl Jumper for JumpTables {
    #[inline]
    fn jump(&self, c: Cell, d: u8, goal: Cell) -> Option<Cell> {
        let v = i32::from(self.get(c.x, c.y, d));
        let reach = v.unsigned_abs();
        let (dx, dy) = DIRECTIONS[d as usize];
        let gx = i64::from(goal.x) - i64::from(c.x);
        let gy = i64::from(goal.y) - i64::from(c.y);
        let at = |k: u32| {
            Cell::new(
                (i64::from(c.x) + i64::from(dx) * i64::from(k)) as u32,
                (i64::from(c.y) + i64::from(dy) * i64::from(k)) as u32,
            )
        };
        if dx == 0 || dy == 0 {
            // The goal on this ray, no further than the jump point or the wall: go straight to it.
            let k = if dx != 0 && gy == 0 && gx.signum() == i64::from(dx) {
                gx.unsigned_abs()
            } else if dy != 0 && gx == 0 && gy.signum() == i64::from(dy) {
                gy.unsigned_abs()
            } else {
                u64::MAX
            };
            if k <= u64::from(reach) {
                return Some(goal);
            }
        } else if gx.signum() == i64::from(dx) && gy.signum() == i64::from(dy) {
            // The goal in this quadrant: stop where the diagonal lines up with its row or column.
            let m = gx.unsigned_abs().min(gy.unsigned_abs());
            if m <= u64::from(reach) {
                return Some(at(m as u32));
            }
        }
        (v > 0).then(|| at(reach))
    }
}
