//! Where in an occupied cell its obstacle points lie: the box round them, kept per cell so that
//! a planner's clearance is measured from the points rather than from the cells' centres.
//!
//! With clearance measured between cell centres, a surface anywhere in its cell reads as the
//! cell's centre: up to half a cell off, and a surface near a cell's edge reads a whole cell
//! nearer or farther depending on which of the two cells its points happen to fall in. A gap a
//! few centimetres wider than the robot then opens and shuts from scan to scan. The box of the
//! points in each cell removes that: a cell's distance is the distance to its points' box.

use nalgebra::Vector2;
use slam_core::GridGeometry;

/// Steps of a cell side in [`CellExtent`]: sixteen, about 6 mm at 0.1 m cells.
const STEPS: f64 = 16.0;

/// The box round the obstacle points that fell in one cell, each side in sixteenths of the
/// cell from its lower (west or south) edge, rounded outward so the box holds every point: a
/// distance to it is never more than the distance to the nearest point, and at most a
/// sixteenth of a cell's diagonal less. A cell with no points recorded (set occupied by hand,
/// unknown, stairs) reads as its centre, as clearances between cell centres had it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CellExtent(u16);

impl Default for CellExtent {
    fn default() -> Self {
        Self::CENTRE
    }
}

impl CellExtent {
    /// No points recorded: the cell reads as its centre. (Any box whose low side exceeds its
    /// high side means this.)
    pub const CENTRE: Self = Self(0x0F0F);

    /// The box round the point at `fraction` of its cell (each coordinate in `[0, 1)`, values
    /// outside clamped).
    #[must_use]
    pub fn at(fraction: Vector2<f64>) -> Self {
        let step = |f: f64| (f * STEPS).floor().clamp(0.0, STEPS - 1.0) as u16;
        let (x, y) = (step(fraction.x), step(fraction.y));
        Self::pack([x, x, y, y])
    }

    /// The cell of `p` on `geometry` (signed: it may lie off a grid) and the box of `p` in it.
    #[must_use]
    pub fn of_point(geometry: &GridGeometry, p: Vector2<f64>) -> ((i64, i64), Self) {
        let q = (p - geometry.origin) / geometry.resolution;
        let cell = (q.x.floor(), q.y.floor());
        (
            (cell.0 as i64, cell.1 as i64),
            Self::at(Vector2::new(q.x - cell.0, q.y - cell.1)),
        )
    }

    /// Whether no points are recorded (the cell reads as its centre).
    #[must_use]
    pub fn is_centre(self) -> bool {
        let [x0, x1, y0, y1] = self.unpack();
        x0 > x1 || y0 > y1
    }

    /// The box holding both (a box with no points recorded adds nothing).
    #[must_use]
    pub fn union(self, other: Self) -> Self {
        match (self.is_centre(), other.is_centre()) {
            (true, _) => other,
            (_, true) => self,
            _ => {
                let (a, b) = (self.unpack(), other.unpack());
                Self::pack([
                    a[0].min(b[0]),
                    a[1].max(b[1]),
                    a[2].min(b[2]),
                    a[3].max(b[3]),
                ])
            }
        }
    }

    /// The box in fractions of its cell: (low x, high x, low y, high y), the centre as a point
    /// at 0.5 when no points are recorded.
    #[must_use]
    pub fn bounds(self) -> [f64; 4] {
        if self.is_centre() {
            return [0.5; 4];
        }
        let [x0, x1, y0, y1] = self.unpack().map(f64::from);
        [
            x0 / STEPS,
            (x1 + 1.0) / STEPS,
            y0 / STEPS,
            (y1 + 1.0) / STEPS,
        ]
    }

    /// Squared distance, in cells, from the centre of a cell to this box in the cell `offset`
    /// (columns, rows) from it.
    #[inline]
    #[must_use]
    pub fn squared_distance_from_centre(self, offset: (i64, i64)) -> f64 {
        let [x0, x1, y0, y1] = self.bounds();
        let gap = |lo: f64, hi: f64, d: i64| {
            // The box's side in the query cell's frame, its centre at 0.
            let (lo, hi) = (d as f64 + lo - 0.5, d as f64 + hi - 0.5);
            if lo > 0.0 {
                lo
            } else if hi < 0.0 {
                -hi
            } else {
                0.0
            }
        };
        let (dx, dy) = (gap(x0, x1, offset.0), gap(y0, y1, offset.1));
        dx * dx + dy * dy
    }

    fn unpack(self) -> [u16; 4] {
        [0, 4, 8, 12].map(|s| (self.0 >> s) & 0xF)
    }

    fn pack(v: [u16; 4]) -> Self {
        Self(v[0] | v[1] << 4 | v[2] << 8 | v[3] << 12)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_point_box_holds_the_point_and_unions_grow() {
        let a = CellExtent::at(Vector2::new(0.9, 0.2));
        let [x0, x1, y0, y1] = a.bounds();
        assert!(x0 <= 0.9 && 0.9 <= x1 && x1 - x0 <= 1.0 / 16.0 + 1e-12);
        assert!(y0 <= 0.2 && 0.2 <= y1);
        let b = a.union(CellExtent::at(Vector2::new(0.1, 0.95)));
        let want = [1.0 / 16.0, 15.0 / 16.0, 3.0 / 16.0, 1.0];
        assert!(
            b.bounds()
                .iter()
                .zip(want)
                .all(|(a, w)| (a - w).abs() < 1e-12)
        );
        assert_eq!(CellExtent::CENTRE.union(a), a);
        assert_eq!(a.union(CellExtent::CENTRE), a);
        assert!(CellExtent::CENTRE.is_centre() && !a.is_centre());
    }

    #[test]
    fn distances_are_to_the_box() {
        // A point at the west edge of the cell two columns east: 1.5 cells from the centre.
        let west = CellExtent::at(Vector2::new(0.0, 0.5));
        assert!((west.squared_distance_from_centre((2, 0)).sqrt() - 1.5).abs() < 1e-12);
        // The centre reads as before: whole cells between centres.
        assert!((CellExtent::CENTRE.squared_distance_from_centre((3, 4)) - 25.0).abs() < 1e-12);
        // Inside the query cell's own box: 0.
        let all = west.union(CellExtent::at(Vector2::new(0.99, 0.99)));
        assert!(all.squared_distance_from_centre((0, 0)).abs() < 1e-12);
    }

    #[test]
    fn points_find_their_cells() {
        let g = GridGeometry::try_new(Vector2::new(-1.0, 2.0), 0.1).unwrap();
        let (cell, e) = CellExtent::of_point(&g, Vector2::new(-0.96, 2.25));
        assert_eq!(cell, (0, 2));
        let [x0, x1, ..] = e.bounds();
        assert!(x0 <= 0.4 + 1e-9 && 0.4 - 1e-9 <= x1);
    }
}
