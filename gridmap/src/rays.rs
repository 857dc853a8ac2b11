//! Ray geometry shared by the map builders and the live layer: where a beam lies below
//! the top of the obstacle band, and which cells its ground track crosses.

use nalgebra::{Point3, Vector2};

/// The part of the beam from `origin` to `end` that lies at or below height `top`, as its two
/// ends; `None` when the whole beam is above `top`.
#[inline]
pub(crate) fn below_top(
    origin: Point3<f64>,
    end: Point3<f64>,
    top: f64,
) -> Option<(Point3<f64>, Point3<f64>)> {
    match (origin.z <= top, end.z <= top) {
        (true, true) => Some((origin, end)),
        (true, false) => {
            let t = (top - origin.z) / (end.z - origin.z);
            Some((origin, origin + (end - origin) * t))
        }
        (false, true) => {
            let t = (origin.z - top) / (origin.z - end.z);
            Some((origin + (end - origin) * t, end))
        }
        (false, false) => None,
    }
}

/// The part of the segment from `a` to `b` inside the box `[0, size.x] x [0, size.y]`
/// (Liang-Barsky), and whether `b` was cut off; `None` when the segment misses the box.
#[inline]
pub(crate) fn clip_to_box(
    a: Vector2<f64>,
    b: Vector2<f64>,
    size: Vector2<f64>,
) -> Option<(Vector2<f64>, Vector2<f64>, bool)> {
    clip_to_bounds(a, b, Vector2::zeros(), size)
}

/// The part of the segment from `a` to `b` inside the box `lo`..`hi` (Liang-Barsky), and
/// whether `b` was cut off; `None` when it misses the box. A segment inside the box is returned as it
/// is, so that its cells do not depend on the box.
#[inline]
pub(crate) fn clip_to_bounds(
    a: Vector2<f64>,
    b: Vector2<f64>,
    lo: Vector2<f64>,
    hi: Vector2<f64>,
) -> Option<(Vector2<f64>, Vector2<f64>, bool)> {
    let inside = |v: Vector2<f64>| v.x >= lo.x && v.y >= lo.y && v.x < hi.x && v.y < hi.y;
    if inside(a) && inside(b) {
        return Some((a, b, false));
    }
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-d.x, a.x - lo.x),
        (d.x, hi.x - a.x),
        (-d.y, a.y - lo.y),
        (d.y, hi.y - a.y),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    if t0 > t1 {
        return None;
    }
    // Keep the clipped ends a hair inside the box so that their cells are on the grid.
    let keep_in = |v: Vector2<f64>| {
        Vector2::new(
            v.x.clamp(lo.x, (hi.x - 1e-9).max(lo.x)),
            v.y.clamp(lo.y, (hi.y - 1e-9).max(lo.y)),
        )
    };
    Some((keep_in(a + d * t0), keep_in(a + d * t1), t1 < 1.0))
}

/// `x.floor()` as an integer, without the library call `f64::floor` compiles to on baseline
/// x86-64 (saturating at the ends of `i64`, as `as` does).
#[inline]
pub(crate) fn floor_i64(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x {
        t.saturating_sub(1)
    } else {
        t
    }
}

/// Visit every cell the segment from `a` to `b` crosses (both in cell units: metres from the
/// grid's origin divided by the resolution), in order (Amanatides & Woo, "A Fast Voxel Traversal
/// Algorithm for Ray Tracing", 1987); the cell containing `b` only when `include_end`. Cells may
/// lie off the grid: `visit` gets signed coordinates.
#[inline]
pub(crate) fn traverse(
    a: Vector2<f64>,
    b: Vector2<f64>,
    include_end: bool,
    mut visit: impl FnMut(i64, i64),
) {
    let (mut x, mut y) = (floor_i64(a.x), floor_i64(a.y));
    let (ex, ey) = (floor_i64(b.x), floor_i64(b.y));
    let d = b - a;
    let step_x: i64 = if d.x > 0.0 { 1 } else { -1 };
    let step_y: i64 = if d.y > 0.0 { 1 } else { -1 };
    let next_boundary = |p: f64, s: i64| {
        let f = floor_i64(p) as f64;
        if s > 0 { f + 1.0 } else { f }
    };
    let (mut t_max_x, t_dx) = if d.x == 0.0 {
        (f64::INFINITY, f64::INFINITY)
    } else {
        ((next_boundary(a.x, step_x) - a.x) / d.x, 1.0 / d.x.abs())
    };
    let (mut t_max_y, t_dy) = if d.y == 0.0 {
        (f64::INFINITY, f64::INFINITY)
    } else {
        ((next_boundary(a.y, step_y) - a.y) / d.y, 1.0 / d.y.abs())
    };
    // Each step moves one cell closer to the end cell along x or y.
    let steps = (ex - x).abs() + (ey - y).abs();
    for _ in 0..steps {
        if x == ex && y == ey {
            break;
        }
        visit(x, y);
        if t_max_x < t_max_y {
            x += step_x;
            t_max_x += t_dx;
        } else {
            y += step_y;
            t_max_y += t_dy;
        }
    }
    if include_end || (x, y) != (ex, ey) {
        visit(x, y);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn traversal_is_connected_and_ends_in_the_end_cell() {
        let mut s = 99u64;
        let mut rnd = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s % 10_000) as f64 / 100.0 - 50.0
        };
        for _ in 0..2000 {
            let (a, b) = (Vector2::new(rnd(), rnd()), Vector2::new(rnd(), rnd()));
            let mut cells = Vec::new();
            traverse(a, b, true, |x, y| cells.push((x, y)));
            assert_eq!(cells[0], (a.x.floor() as i64, a.y.floor() as i64));
            assert_eq!(
                *cells.last().unwrap_or(&(0, 0)),
                (b.x.floor() as i64, b.y.floor() as i64)
            );
            for w in cells.windows(2) {
                assert_eq!((w[0].0 - w[1].0).abs() + (w[0].1 - w[1].1).abs(), 1);
            }
            // Every visited cell is touched by the segment (its distance to the cell's box is ~0).
            for &(x, y) in &cells {
                let hit = (0..=1000).any(|k| {
                    let p = a + (b - a) * (f64::from(k) / 1000.0);
                    (p.x - x as f64) > -0.06
                        && (p.x - x as f64) < 1.06
                        && (p.y - y as f64) > -0.06
                        && (p.y - y as f64) < 1.06
                });
                assert!(hit, "({x}, {y}) from {a:?} to {b:?}");
            }
            let mut without = Vec::new();
            traverse(a, b, false, |x, y| without.push((x, y)));
            assert_eq!(without.len() + 1, cells.len());
        }
    }

    #[test]
    fn fast_floor_is_floor() {
        for x in [
            -2.5,
            -2.0,
            -0.0,
            0.0,
            0.3,
            1.0,
            7.999_999,
            -1e-300,
            1e15 + 0.5,
            -1e15 - 0.5,
        ] {
            assert_eq!(floor_i64(x), x.floor() as i64, "{x}");
        }
        assert_eq!(floor_i64(f64::MAX), i64::MAX);
        assert_eq!(floor_i64(f64::MIN), i64::MIN);
    }

    #[test]
    fn clipping_to_the_box() {
        let size = Vector2::new(10.0, 5.0);
        let (a, b, cut) =
            clip_to_box(Vector2::new(5.0, 2.0), Vector2::new(25.0, 2.0), size).unwrap_or_default();
        assert_eq!(a, Vector2::new(5.0, 2.0));
        assert!((b.x - 10.0).abs() < 1e-6 && cut);
        let (_, b, cut) =
            clip_to_box(Vector2::new(5.0, 2.0), Vector2::new(6.0, 3.0), size).unwrap_or_default();
        assert_eq!((b, cut), (Vector2::new(6.0, 3.0), false));
        assert!(clip_to_box(Vector2::new(-5.0, -2.0), Vector2::new(-1.0, 20.0), size).is_none());
        let (a, b, _) =
            clip_to_box(Vector2::new(-5.0, 2.5), Vector2::new(15.0, 2.5), size).unwrap_or_default();
        assert!(a.x.abs() < 1e-9 && (b.x - 10.0).abs() < 1e-6);
    }

    #[test]
    fn clipping_below_the_top() {
        let o = Point3::new(0.0, 0.0, 0.8);
        let (a, b) = below_top(o, Point3::new(4.0, 0.0, 2.8), 1.3).unwrap_or((o, o));
        assert_eq!(a, o);
        assert!((b - Point3::new(1.0, 0.0, 1.3)).norm() < 1e-12);
        assert!(below_top(Point3::new(0.0, 0.0, 2.0), Point3::new(1.0, 0.0, 3.0), 1.0).is_none());
        let (a, _) = below_top(Point3::new(0.0, 0.0, 2.0), Point3::new(2.0, 0.0, 0.0), 1.0)
            .unwrap_or((o, o));
        assert!((a - Point3::new(1.0, 0.0, 1.0)).norm() < 1e-12);
    }
}
