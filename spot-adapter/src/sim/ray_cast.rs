//! Ray casting against the building: a uniform plan-view grid of cells listing the boxes that
//! overlap them, walked cell by cell along the ray (Amanatides and Woo, "A fast voxel traversal
//! algorithm for ray tracing", Eurographics 1987), with the floor and ceiling as planes.

use nalgebra::{Point3, Vector3};

use crate::sim::solid_box::SolidBox;

/// What a ray hit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HitTarget {
    /// The box with this index in [`Building::boxes`](crate::sim::Building::boxes).
    Box(usize),
    /// The floor (z = 0).
    Floor,
    /// The ceiling.
    Ceiling,
}

/// The nearest intersection of a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// Distance along the (unit) direction, metres.
    pub range: f64,
    /// What was hit.
    pub target: HitTarget,
}

/// Plan-view grid of box indices in compressed rows: cell `k` lists
/// `items[offsets[k]..offsets[k + 1]]`.
#[derive(Clone, Debug)]
pub(crate) struct BoxGrid {
    origin: [f64; 2],
    cell: f64,
    nx: usize,
    ny: usize,
    offsets: Vec<u32>,
    items: Vec<u32>,
    /// Boxes copied in a flat layout for the hot loop: min xyz, max xyz.
    flat: Vec<[f64; 6]>,
}

impl BoxGrid {
    /// Index `boxes` with square cells of side `cell` metres.
    pub(crate) fn new(boxes: &[SolidBox], cell: f64) -> Self {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for b in boxes {
            for k in 0..2 {
                lo[k] = lo[k].min(b.min[k]);
                hi[k] = hi[k].max(b.max[k]);
            }
        }
        if boxes.is_empty() {
            (lo, hi) = ([0.0; 2], [cell; 2]);
        }
        let origin = [lo[0] - cell, lo[1] - cell];
        let nx = ((hi[0] - origin[0]) / cell).ceil() as usize + 1;
        let ny = ((hi[1] - origin[1]) / cell).ceil() as usize + 1;
        let range = |b: &SolidBox| {
            let c = |v: f64, k: usize, n: usize| {
                (((v - origin[k]) / cell).floor().max(0.0) as usize).min(n - 1)
            };
            (
                c(b.min.x, 0, nx),
                c(b.max.x, 0, nx),
                c(b.min.y, 1, ny),
                c(b.max.y, 1, ny),
            )
        };
        let mut counts = vec![0u32; nx * ny + 1];
        for b in boxes {
            let (x0, x1, y0, y1) = range(b);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    counts[y * nx + x + 1] += 1;
                }
            }
        }
        for k in 1..counts.len() {
            counts[k] += counts[k - 1];
        }
        let mut fill = counts.clone();
        let mut items = vec![0u32; counts[nx * ny] as usize];
        for (i, b) in boxes.iter().enumerate() {
            let (x0, x1, y0, y1) = range(b);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let slot = &mut fill[y * nx + x];
                    items[*slot as usize] = i as u32;
                    *slot += 1;
                }
            }
        }
        let flat = boxes
            .iter()
            .map(|b| [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z])
            .collect();
        Self {
            origin,
            cell,
            nx,
            ny,
            offsets: counts,
            items,
            flat,
        }
    }

    /// Nearest box hit with range in `[0, limit)`: (range, box index).
    pub(crate) fn cast(
        &self,
        o: &Point3<f64>,
        d: &Vector3<f64>,
        limit: f64,
    ) -> Option<(f64, usize)> {
        let inv = Vector3::new(1.0 / d.x, 1.0 / d.y, 1.0 / d.z);
        // Clip the ray to the grid's plan-view rectangle.
        let (mut t0, mut t1) = (0.0f64, limit);
        for k in 0..2 {
            let lo = self.origin[k];
            let hi = lo + self.cell * if k == 0 { self.nx } else { self.ny } as f64;
            if d[k] == 0.0 {
                if o[k] < lo || o[k] > hi {
                    return None;
                }
            } else {
                let (a, b) = ((lo - o[k]) * inv[k], (hi - o[k]) * inv[k]);
                t0 = t0.max(a.min(b));
                t1 = t1.min(a.max(b));
            }
        }
        if t0 > t1 {
            return None;
        }
        let start = o + d * t0;
        let cell_of = |v: f64, k: usize, n: usize| {
            (((v - self.origin[k]) / self.cell).floor().max(0.0) as usize).min(n - 1)
        };
        let (mut ix, mut iy) = (cell_of(start.x, 0, self.nx), cell_of(start.y, 1, self.ny));
        let axis = |i: usize, k: usize| {
            if d[k] > 0.0 {
                (
                    (self.origin[k] + (i + 1) as f64 * self.cell - o[k]) * inv[k],
                    self.cell * inv[k],
                )
            } else if d[k] < 0.0 {
                (
                    (self.origin[k] + i as f64 * self.cell - o[k]) * inv[k],
                    -self.cell * inv[k],
                )
            } else {
                (f64::INFINITY, f64::INFINITY)
            }
        };
        let (mut next_x, dx) = axis(ix, 0);
        let (mut next_y, dy) = axis(iy, 1);
        let mut best = limit;
        let mut hit = None;
        loop {
            let k = iy * self.nx + ix;
            let span = self.offsets[k] as usize..self.offsets[k + 1] as usize;
            for &i in &self.items[span] {
                let b = &self.flat[i as usize];
                if let Some(t) = slab(b, o, d, &inv)
                    && t < best
                {
                    best = t;
                    hit = Some(i as usize);
                }
            }
            let exit = next_x.min(next_y);
            if best <= exit || exit >= t1 {
                break;
            }
            if next_x < next_y {
                if d.x > 0.0 {
                    ix += 1;
                    if ix >= self.nx {
                        break;
                    }
                } else {
                    if ix == 0 {
                        break;
                    }
                    ix -= 1;
                }
                next_x += dx;
            } else {
                if d.y > 0.0 {
                    iy += 1;
                    if iy >= self.ny {
                        break;
                    }
                } else {
                    if iy == 0 {
                        break;
                    }
                    iy -= 1;
                }
                next_y += dy;
            }
        }
        hit.map(|i| (best, i))
    }
}

/// Entry distance of a ray into a box (slab method), `None` when it misses or the box lies
/// behind the origin. An origin inside the box gives 0.
#[inline]
fn slab(b: &[f64; 6], o: &Point3<f64>, d: &Vector3<f64>, inv: &Vector3<f64>) -> Option<f64> {
    let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
    for k in 0..3 {
        if d[k] == 0.0 {
            if o[k] < b[k] || o[k] > b[k + 3] {
                return None;
            }
        } else {
            let a = (b[k] - o[k]) * inv[k];
            let c = (b[k + 3] - o[k]) * inv[k];
            t0 = t0.max(a.min(c));
            t1 = t1.min(a.max(c));
            if t0 > t1 {
                return None;
            }
        }
    }
    Some(t0)
}
