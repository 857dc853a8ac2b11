//! Exact Euclidean distance transform (Felzenszwalb & Huttenlocher, "Distance Transforms of
//! Sampled Functions", 2012): squared distances by two passes of the 1D lower-envelope algorithm,
//! linear in the number of cells.

use slam_core::{BitGrid, Cell};

use crate::error::{GridMapError, check};

/// Squared value standing for "no obstacle on this line": above any real squared distance on
/// grids up to 100,000 cells a side, small enough that `FAR + q^2` keeps its precision.
const FAR: f64 = 1e12;

/// 1D squared distance transform of `f` into `out` (`v`, `z` are scratch of length n and n + 1):
/// the lower envelope of the parabolas `(q - p)^2 + f(p)`.
fn transform_1d(f: &[f64], out: &mut [f64], v: &mut [usize], z: &mut [f64]) {
    let n = f.len();
    let parabola = |p: usize| f[p] + (p * p) as f64;
    let mut k = 0usize;
    v[0] = 0;
    z[0] = f64::NEG_INFINITY;
    z[1] = f64::INFINITY;
    for q in 1..n {
        let mut s;
        loop {
            let p = v[k];
            s = (parabola(q) - parabola(p)) / (2.0 * (q as f64 - p as f64));
            // z[0] is -inf, so this stops at k == 0 at the latest.
            if s <= z[k] {
                k -= 1;
            } else {
                break;
            }
        }
        k += 1;
        v[k] = q;
        z[k] = s;
        z[k + 1] = f64::INFINITY;
    }
    k = 0;
    for (q, o) in out.iter_mut().enumerate() {
        while z[k + 1] < q as f64 {
            k += 1;
        }
        let p = v[k];
        let d = q as f64 - p as f64;
        *o = d * d + f[p];
    }
}

/// Squared distance, in cells, from each cell centre to the nearest blocked cell centre
/// (1e12 or more when the grid has no blocked cell). Row-major.
#[must_use]
pub fn squared_distance_cells(grid: &BitGrid) -> Vec<f64> {
    let (w, h) = (grid.width() as usize, grid.height() as usize);
    let mut d = vec![0.0; w * h];
    let n = w.max(h);
    let (mut f, mut out) = (vec![0.0; n], vec![0.0; n]);
    let (mut v, mut z) = (vec![0usize; n], vec![0.0; n + 1]);
    // Columns first (along y), then rows.
    for x in 0..w {
        for (y, v) in f[..h].iter_mut().enumerate() {
            *v = if grid.is_blocked(Cell::new(x as u32, y as u32)) {
                0.0
            } else {
                FAR
            };
        }
        transform_1d(&f[..h], &mut out[..h], &mut v, &mut z);
        for y in 0..h {
            d[y * w + x] = out[y];
        }
    }
    for y in 0..h {
        f[..w].copy_from_slice(&d[y * w..(y + 1) * w]);
        transform_1d(&f[..w], &mut out[..w], &mut v, &mut z);
        d[y * w..(y + 1) * w].copy_from_slice(&out[..w]);
    }
    d
}

/// Metres from each cell centre to the nearest obstacle cell centre, for cost-aware planning and
/// safety margins.
#[derive(Clone, Debug, PartialEq)]
pub struct DistanceField {
    width: u32,
    height: u32,
    resolution: f64,
    metres: Vec<f32>,
}

impl DistanceField {
    /// The distance field of `grid` (blocked cells are obstacles; distance 0 on them).
    #[must_use]
    pub fn new(grid: &BitGrid) -> Self {
        let r = grid.geometry().resolution;
        let metres = squared_distance_cells(grid)
            .into_iter()
            .map(|d2| {
                if d2 >= FAR {
                    f32::INFINITY
                } else {
                    (d2.sqrt() * r) as f32
                }
            })
            .collect();
        Self {
            width: grid.width(),
            height: grid.height(),
            resolution: r,
            metres,
        }
    }

    /// Metres to the nearest obstacle (`INFINITY` when there is none; `None` off the grid).
    #[must_use]
    pub fn distance(&self, cell: Cell) -> Option<f32> {
        (cell.x < self.width && cell.y < self.height)
            .then(|| self.metres[cell.y as usize * self.width as usize + cell.x as usize])
    }

    /// All distances, row-major.
    #[must_use]
    pub fn as_slice(&self) -> &[f32] {
        &self.metres
    }

    /// Cell side, metres.
    #[must_use]
    pub fn resolution(&self) -> f64 {
        self.resolution
    }
}

/// Inflate obstacles by `radius` metres as an exact Euclidean disc: a cell is blocked when its
/// centre lies within `radius` of a blocked cell's centre. Computed from the distance transform,
/// so the cost does not grow with the radius.
///
/// # Errors
/// [`GridMapError::InvalidConfig`] unless `radius` is finite and at least zero (a negative
/// radius is not read as its absolute value, and NaN does not skip the inflation).
pub fn inflate(grid: &BitGrid, radius: f64) -> Result<BitGrid, GridMapError> {
    check(
        radius.is_finite() && radius >= 0.0,
        "inflate radius",
        radius,
        "finite and at least 0 m",
    )?;
    let r_cells = radius / grid.geometry().resolution;
    let limit = r_cells * r_cells;
    let d2 = squared_distance_cells(grid);
    let w = grid.width() as usize;
    let mut out = grid.clone();
    for y in 0..grid.height() {
        let row = out.row_words_mut(y);
        for (x, &d) in d2[y as usize * w..(y as usize + 1) * w].iter().enumerate() {
            // A tiny slack so that cells exactly at the radius count despite rounding of r / res.
            if d <= limit + 1e-9 {
                row[x / 64] |= 1u64 << (x % 64);
            }
        }
    }
    Ok(out)
}
