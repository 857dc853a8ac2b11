//! The bit-packed 2D occupancy grid shared by `gridmap` (which fills it) and `pathfind` (which
//! searches it).
//!
//! One bit per cell, `1` = blocked. Each row is `stride_words` `u64` words; cell `x` of a row is bit
//! `x % 64` of word `x / 64` (least significant bit first), so scanning east is `trailing_zeros` and
//! scanning west is `leading_zeros`. The padding bits past `width` in the last word of every row are
//! kept **blocked**, so a word scan stops at the grid's east edge without a bounds test.

use nalgebra::Vector2;

use crate::error::GridError;

/// A cell index: column `x` (east) and row `y` (north in metric space, see [`GridGeometry`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Cell {
    /// Column, `0..width`.
    pub x: u32,
    /// Row, `0..height`.
    pub y: u32,
}

impl Cell {
    /// A cell at column `x`, row `y`.
    #[must_use]
    pub const fn new(x: u32, y: u32) -> Self {
        Self { x, y }
    }
}

/// Where the grid lies in the world: the metric position of the corner of cell (0, 0) and the side
/// length of a cell. Row `y` grows along the world's +y axis (as in ROS `map_server` images read
/// bottom-up).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct GridGeometry {
    /// World x, y (metres) of the outer corner of cell (0, 0).
    pub origin: Vector2<f64>,
    /// Cell side in metres; usually 0.05 to 0.15 m.
    pub resolution: f64,
}

impl Default for GridGeometry {
    fn default() -> Self {
        Self {
            origin: Vector2::zeros(),
            resolution: 1.0,
        }
    }
}

impl GridGeometry {
    /// A geometry with the given origin (metres) and resolution (metres per cell).
    ///
    /// # Errors
    /// [`GridError::InvalidResolution`] unless `resolution` is finite and positive, and
    /// [`GridError::NonFiniteOrigin`] for a non-finite origin.
    pub fn try_new(origin: Vector2<f64>, resolution: f64) -> Result<Self, GridError> {
        if !(resolution.is_finite() && resolution > 0.0) {
            return Err(GridError::InvalidResolution { resolution });
        }
        if !(origin.x.is_finite() && origin.y.is_finite()) {
            return Err(GridError::NonFiniteOrigin);
        }
        Ok(Self { origin, resolution })
    }

    /// World position (metres) of the centre of `cell`.
    #[must_use]
    pub fn cell_center(&self, cell: Cell) -> Vector2<f64> {
        self.origin
            + Vector2::new(
                (f64::from(cell.x) + 0.5) * self.resolution,
                (f64::from(cell.y) + 0.5) * self.resolution,
            )
    }

    /// The (possibly negative or out-of-grid) integer cell coordinates containing world point `p`.
    #[must_use]
    pub fn cell_coords(&self, p: Vector2<f64>) -> (i64, i64) {
        let q = (p - self.origin) / self.resolution;
        (q.x.floor() as i64, q.y.floor() as i64)
    }
}

/// A bit-packed occupancy grid: any width and height, `1` bit per cell, rows padded to whole
/// `u64` words.
///
/// ```
/// use slam_core::{BitGrid, Cell};
/// let mut grid = BitGrid::new(100, 3)?;
/// grid.set(Cell::new(70, 1), true)?;
/// assert!(grid.is_blocked(Cell::new(70, 1)));
/// assert!(grid.is_blocked(Cell::new(100, 1)), "outside the grid counts as blocked");
/// // Row words expose the bits for word-at-a-time scans; padding bits are blocked.
/// assert_eq!(grid.row_words(1)[1], (1u64 << 6) | !((1u64 << 36) - 1));
/// # Ok::<(), slam_core::GridError>(())
/// ```
#[derive(PartialEq, Eq, Debug)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "serde_form::RawBitGrid", into = "serde_form::RawBitGrid")
)]
pub struct BitGrid {
    width: u32,
    height: u32,
    stride: usize,
    words: Vec<u64>,
    geometry: GeometryBits,
}

impl Clone for BitGrid {
    fn clone(&self) -> Self {
        Self {
            width: self.width,
            height: self.height,
            stride: self.stride,
            words: self.words.clone(),
            geometry: self.geometry,
        }
    }

    /// A copy of `source` in this grid's words, reallocated only when `source` has more: a
    /// planner that copies its grid at every query allocates nothing while the size holds.
    fn clone_from(&mut self, source: &Self) {
        self.width = source.width;
        self.height = source.height;
        self.stride = source.stride;
        self.words.clone_from(&source.words);
        self.geometry = source.geometry;
    }
}

/// `GridGeometry` stored so that `BitGrid` can stay `Eq` (compares the raw bits of the floats).
#[derive(Clone, Copy, Debug, Default)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(transparent)
)]
struct GeometryBits(GridGeometry);

impl PartialEq for GeometryBits {
    fn eq(&self, other: &Self) -> bool {
        self.0.origin.x.to_bits() == other.0.origin.x.to_bits()
            && self.0.origin.y.to_bits() == other.0.origin.y.to_bits()
            && self.0.resolution.to_bits() == other.0.resolution.to_bits()
    }
}
impl Eq for GeometryBits {}

/// Largest number of cells a grid may hold: 2^32 (512 MiB of bits), so that a cell's row-major
/// index fits the `u32` the planners store per cell (about 20 bytes per cell, 80 GiB at this limit).
pub const MAX_GRID_CELLS: u64 = 1 << 32;

impl BitGrid {
    /// An all-free grid of `width` x `height` cells with unit resolution at the origin.
    ///
    /// # Errors
    /// [`GridError::EmptyGrid`] when a side is zero, [`GridError::TooLarge`] past
    /// [`MAX_GRID_CELLS`].
    pub fn new(width: u32, height: u32) -> Result<Self, GridError> {
        if width == 0 || height == 0 {
            return Err(GridError::EmptyGrid { width, height });
        }
        let cells = u64::from(width) * u64::from(height);
        if cells > MAX_GRID_CELLS {
            return Err(GridError::TooLarge {
                width,
                height,
                max_cells: MAX_GRID_CELLS,
            });
        }
        let stride = (width as usize).div_ceil(64);
        let mut words = vec![0u64; stride * height as usize];
        let pad = Self::padding_mask(width);
        if pad != 0 {
            for row in words.chunks_exact_mut(stride) {
                row[stride - 1] = pad;
            }
        }
        Ok(Self {
            width,
            height,
            stride,
            words,
            geometry: GeometryBits::default(),
        })
    }

    /// A grid whose cell (x, y) is blocked when `blocked(x, y)` is true.
    ///
    /// # Errors
    /// As [`BitGrid::new`].
    pub fn from_fn(
        width: u32,
        height: u32,
        mut blocked: impl FnMut(u32, u32) -> bool,
    ) -> Result<Self, GridError> {
        let mut grid = Self::new(width, height)?;
        for y in 0..height {
            let row = grid.row_words_mut(y);
            for x in 0..width {
                if blocked(x, y) {
                    row[(x / 64) as usize] |= 1u64 << (x % 64);
                }
            }
        }
        Ok(grid)
    }

    /// Blocked bits of the last word of a row that lie past `width` (zero when `width % 64 == 0`).
    fn padding_mask(width: u32) -> u64 {
        match width % 64 {
            0 => 0,
            used => !((1u64 << used) - 1),
        }
    }

    /// Attach a metric placement to the grid.
    #[must_use]
    pub fn with_geometry(mut self, geometry: GridGeometry) -> Self {
        self.geometry = GeometryBits(geometry);
        self
    }

    /// Columns.
    #[must_use]
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Rows.
    #[must_use]
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Number of cells (`width * height`).
    #[must_use]
    pub fn len(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// Always false: a grid has at least one cell.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The grid's metric placement.
    #[must_use]
    pub fn geometry(&self) -> &GridGeometry {
        &self.geometry.0
    }

    /// `u64` words per row (`ceil(width / 64)`).
    #[must_use]
    pub fn stride_words(&self) -> usize {
        self.stride
    }

    /// Whether `cell` lies on the grid.
    #[must_use]
    pub fn contains(&self, cell: Cell) -> bool {
        cell.x < self.width && cell.y < self.height
    }

    /// Whether `(x, y)` (signed) lies on the grid.
    #[must_use]
    pub fn contains_signed(&self, x: i64, y: i64) -> bool {
        x >= 0 && y >= 0 && x < i64::from(self.width) && y < i64::from(self.height)
    }

    /// Whether `cell` is blocked; cells off the grid count as blocked.
    #[inline]
    #[must_use]
    pub fn is_blocked(&self, cell: Cell) -> bool {
        if !self.contains(cell) {
            return true;
        }
        let w = self.words[cell.y as usize * self.stride + (cell.x / 64) as usize];
        (w >> (cell.x % 64)) & 1 == 1
    }

    /// Whether signed coordinates `(x, y)` are a free cell on the grid.
    #[inline]
    #[must_use]
    pub fn is_free_signed(&self, x: i64, y: i64) -> bool {
        self.contains_signed(x, y) && !self.is_blocked(Cell::new(x as u32, y as u32))
    }

    /// The state of `cell`, or `None` off the grid.
    #[must_use]
    pub fn get(&self, cell: Cell) -> Option<bool> {
        self.contains(cell).then(|| self.is_blocked(cell))
    }

    /// Mark `cell` blocked (`true`) or free (`false`).
    ///
    /// # Errors
    /// [`GridError::OutOfBounds`] when `cell` is off the grid.
    pub fn set(&mut self, cell: Cell, blocked: bool) -> Result<(), GridError> {
        if !self.contains(cell) {
            return Err(GridError::OutOfBounds {
                x: i64::from(cell.x),
                y: i64::from(cell.y),
                width: self.width,
                height: self.height,
            });
        }
        let w = &mut self.words[cell.y as usize * self.stride + (cell.x / 64) as usize];
        let bit = 1u64 << (cell.x % 64);
        if blocked {
            *w |= bit;
        } else {
            *w &= !bit;
        }
        Ok(())
    }

    /// The words of row `y` (`stride_words()` of them). Bits past `width` are set (blocked).
    ///
    /// # Panics
    /// If `y >= height`.
    #[inline]
    #[must_use]
    pub fn row_words(&self, y: u32) -> &[u64] {
        let start = y as usize * self.stride;
        &self.words[start..start + self.stride]
    }

    /// Mutable words of row `y`. Writers must keep the padding bits set; [`BitGrid::restore_padding`]
    /// does it after bulk writes.
    ///
    /// # Panics
    /// If `y >= height`.
    #[inline]
    pub fn row_words_mut(&mut self, y: u32) -> &mut [u64] {
        let start = y as usize * self.stride;
        &mut self.words[start..start + self.stride]
    }

    /// All words, row after row.
    #[must_use]
    pub fn words(&self) -> &[u64] {
        &self.words
    }

    /// Set the padding bits of every row again (after writes through [`BitGrid::row_words_mut`]).
    pub fn restore_padding(&mut self) {
        let pad = Self::padding_mask(self.width);
        if pad != 0 {
            let stride = self.stride;
            for row in self.words.chunks_exact_mut(stride) {
                row[stride - 1] |= pad;
            }
        }
    }

    /// 64 cells of row `y` starting at column `x` (bit `i` = cell `x + i`), as one word. Cells past
    /// the east edge read as blocked. This is the primitive of the bitwise jump-point scans.
    ///
    /// # Panics
    /// If `y >= height` or `x >= width`.
    #[inline]
    #[must_use]
    pub fn word_at(&self, x: u32, y: u32) -> u64 {
        let row = self.row_words(y);
        let i = (x / 64) as usize;
        let shift = x % 64;
        let lo = row[i] >> shift;
        if shift == 0 {
            return lo;
        }
        let hi = row.get(i + 1).copied().unwrap_or(u64::MAX);
        lo | (hi << (64 - shift))
    }

    /// 64 cells of row `y` ending at column `x` going west (bit 63 = cell `x`, bit 63 - i = cell
    /// `x - i`). Cells past the west edge read as blocked.
    ///
    /// # Panics
    /// If `y >= height` or `x >= width`.
    #[inline]
    #[must_use]
    pub fn word_ending_at(&self, x: u32, y: u32) -> u64 {
        let row = self.row_words(y);
        let i = (x / 64) as usize;
        let bit = x % 64;
        // Shift so that cell x lands on bit 63.
        let shift = 63 - bit;
        let hi = row[i] << shift;
        if shift == 0 {
            return hi;
        }
        let lo = if i == 0 { u64::MAX } else { row[i - 1] };
        hi | (lo >> (64 - shift))
    }

    /// The transposed grid (cell (x, y) becomes (y, x)), so that column scans become row scans.
    #[must_use]
    pub fn transposed(&self) -> Self {
        let mut t = Self {
            width: self.height,
            height: self.width,
            stride: (self.height as usize).div_ceil(64),
            words: Vec::new(),
            geometry: GeometryBits(GridGeometry {
                origin: Vector2::new(self.geometry.0.origin.y, self.geometry.0.origin.x),
                resolution: self.geometry.0.resolution,
            }),
        };
        t.words = vec![0u64; t.stride * t.height as usize];
        for y in 0..self.height {
            let row = self.row_words(y);
            for (wi, &w) in row.iter().enumerate() {
                let mut bits = w;
                while bits != 0 {
                    let b = bits.trailing_zeros();
                    bits &= bits - 1;
                    let x = wi as u32 * 64 + b;
                    if x < self.width {
                        t.words[x as usize * t.stride + (y / 64) as usize] |= 1u64 << (y % 64);
                    }
                }
            }
        }
        t.restore_padding();
        t
    }

    /// Number of blocked cells.
    #[must_use]
    pub fn count_blocked(&self) -> usize {
        let pad = u64::from(Self::padding_mask(self.width).count_ones());
        let total: u64 = self.words.iter().map(|w| u64::from(w.count_ones())).sum();
        (total - pad * u64::from(self.height)) as usize
    }

    /// Every blocked cell, row by row.
    pub fn blocked_cells(&self) -> impl Iterator<Item = Cell> + '_ {
        (0..self.height).flat_map(move |y| {
            self.row_words(y)
                .iter()
                .enumerate()
                .flat_map(move |(wi, &w)| {
                    let mut bits = w;
                    std::iter::from_fn(move || {
                        while bits != 0 {
                            let b = bits.trailing_zeros();
                            bits &= bits - 1;
                            let x = wi as u32 * 64 + b;
                            if x < self.width {
                                return Some(Cell::new(x, y));
                            }
                        }
                        None
                    })
                })
        })
    }

    /// The cell containing world point `p` (metres), if it is on the grid.
    #[must_use]
    pub fn cell_at(&self, p: Vector2<f64>) -> Option<Cell> {
        let (x, y) = self.geometry.0.cell_coords(p);
        self.contains_signed(x, y)
            .then(|| Cell::new(x as u32, y as u32))
    }

    /// World position (metres) of the centre of `cell`.
    #[must_use]
    pub fn cell_center(&self, cell: Cell) -> Vector2<f64> {
        self.geometry.0.cell_center(cell)
    }
}

/// The serialised form of a grid, checked on the way back in so a bad file cannot break the
/// grid's invariants (row stride, padding bits).
#[cfg(feature = "serde")]
mod serde_form {
    use super::{BitGrid, GeometryBits, GridGeometry};
    use crate::error::GridError;

    #[derive(serde::Serialize, serde::Deserialize)]
    pub(super) struct RawBitGrid {
        width: u32,
        height: u32,
        geometry: GridGeometry,
        words: Vec<u64>,
    }

    impl From<BitGrid> for RawBitGrid {
        fn from(g: BitGrid) -> Self {
            Self {
                width: g.width,
                height: g.height,
                geometry: g.geometry.0,
                words: g.words,
            }
        }
    }

    impl TryFrom<RawBitGrid> for BitGrid {
        type Error = GridError;
        fn try_from(raw: RawBitGrid) -> Result<Self, GridError> {
            let mut grid = BitGrid::new(raw.width, raw.height)?;
            if raw.words.len() != grid.words.len() {
                return Err(GridError::WordCount {
                    expected: grid.words.len(),
                    got: raw.words.len(),
                });
            }
            let geometry = GridGeometry::try_new(raw.geometry.origin, raw.geometry.resolution)?;
            grid.words = raw.words;
            grid.geometry = GeometryBits(geometry);
            grid.restore_padding();
            Ok(grid)
        }
    }
}

#[cfg(test)]
#[path = "grid_tests.rs"]
mod tests;
