//! The grid a planner searches: hard inflation by the robot's half width plus a margin, and a
//! clearance cost per cell from the distance field (the thesis' future work, f = g + h + o), kept
//! up to date over a changed region at a cost bounded by the region's size.

use slam_core::{BitGrid, Cell};

use crate::distance::{DistanceField, squared_distance_cells};
use crate::error::{GridMapError, check, check_not_negative};
use crate::extent::CellExtent;
use crate::occupancy::{OccupancyGrid, UnknownCells};

/// The clearance cost: entering a cell `d` metres from the nearest obstacle costs the step's
/// length times `1 + weight * penalty(d)`, with
/// `penalty(d) = clamp((zero_beyond - d) / (zero_beyond - full_within), 0, 1)^2`:
/// 1 at `full_within` and closer, falling to 0 at `zero_beyond` and beyond. Multipliers are at
/// least 1, so a planner's octile heuristic stays admissible (pathfind's `CellCostAStar`).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct ClearanceCostConfig {
    /// Weight of the penalty (dimensionless), 2.0: a cell at `full_within` costs 3 times its
    /// length; 0 turns the cost off (every multiplier 1: shortest paths).
    pub weight: f64,
    /// Distance (metres) at and below which the penalty is full, 0.30 m (the hard inflation: the
    /// closest a free cell can be).
    pub full_within: f64,
    /// Distance (metres) at and beyond which the penalty is 0, 1.0 m: in corridors up to about
    /// 2 m wide, paths keep to the middle.
    pub zero_beyond: f64,
}

impl Default for ClearanceCostConfig {
    fn default() -> Self {
        Self {
            weight: 2.0,
            full_within: 0.30,
            zero_beyond: 1.0,
        }
    }
}

impl ClearanceCostConfig {
    /// Check the settings.
    ///
    /// # Errors
    /// [`GridMapError::InvalidConfig`] unless `0 <= weight <= 1000`,
    /// `0 <= full_within < zero_beyond <= 1000` (metres), all finite.
    pub fn validate(&self) -> Result<(), GridMapError> {
        check(
            self.weight.is_finite() && (0.0..=1000.0).contains(&self.weight),
            "ClearanceCostConfig::weight",
            self.weight,
            "finite, from 0 to 1000",
        )?;
        check_not_negative(&[("ClearanceCostConfig::full_within", self.full_within)])?;
        check(
            self.zero_beyond.is_finite()
                && self.zero_beyond > self.full_within
                && self.zero_beyond <= 1000.0,
            "ClearanceCostConfig::zero_beyond",
            self.zero_beyond,
            "finite, above ClearanceCostConfig::full_within and at most 1000 m",
        )?;
        Ok(())
    }

    /// The cost multiplier of a cell `d` metres from the nearest obstacle (at least 1).
    #[inline]
    #[must_use]
    pub fn multiplier(&self, d: f64) -> f32 {
        let p = ((self.zero_beyond - d) / (self.zero_beyond - self.full_within)).clamp(0.0, 1.0);
        (1.0 + self.weight * p * p) as f32
    }
}

/// The cost multipliers of every cell (row-major) from a distance field, for pathfind's
/// `CellCostAStar::new(&grid, &costs)`: [`ClearanceCostConfig::multiplier`] of each distance.
///
/// # Errors
/// [`GridMapError::InvalidConfig`] for invalid settings.
pub fn clearance_step_costs(
    field: &DistanceField,
    config: &ClearanceCostConfig,
) -> Result<Vec<f32>, GridMapError> {
    config.validate()?;
    Ok(field
        .as_slice()
        .iter()
        .map(|&d| config.multiplier(f64::from(d)))
        .collect())
}

/// Settings of [`PlanningGrid`]. Lengths in metres.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct PlanningGridConfig {
    /// How unknown cells count: [`UnknownCells::Blocked`] (default: the robot stays in observed
    /// space; unknown cells are obstacles for the inflation and the clearance too) or
    /// [`UnknownCells::Free`].
    pub unknown: UnknownCells,
    /// Hard inflation, 0.30 m: Spot's half width (0.25 m) plus 0.05 m. Cells whose centre lies
    /// within it of an obstacle are blocked: of the box of an occupied cell's points where the
    /// grid records them ([`OccupancyGrid::extent`]), of the cell's centre otherwise (unknown
    /// cells, cells set by hand).
    pub inflation: f64,
    /// How much less the cells the robot has walked ([`PlanningGrid::with_walked`]) are
    /// inflated, 0.05 m: the default's margin over Spot's half width. The robot fitted there,
    /// so the margin, which covers where the grid puts an obstacle's surface (anywhere in its
    /// cell), need not be added again: a door the robot walked through stays open when scans
    /// from its other side add a cell to a jamb. Obstacle cells block whatever the relief.
    pub walked_relief: f64,
    /// How much nearer than its recorded points an obstacle may stand, 0.05 m: clearances
    /// measured from an occupied cell's points ([`OccupancyGrid::extent`]) are this much less.
    /// A scan samples a surface every few centimetres (a box's corner lies between the last
    /// point on one face and the first past it), the points are a scan old, and the robot keeps
    /// to its path within a few centimetres; measured from the cells' centres, half a cell of
    /// slop hid all three. Cells with no points recorded read as their centres, without it.
    /// With the default inflation a passage needs 0.70 m between its obstacles' points.
    pub point_margin: f64,
    /// The clearance cost on the cells left free.
    pub cost: ClearanceCostConfig,
}

impl Default for PlanningGridConfig {
    fn default() -> Self {
        Self {
            unknown: UnknownCells::Blocked,
            inflation: 0.30,
            walked_relief: 0.05,
            point_margin: 0.05,
            cost: ClearanceCostConfig::default(),
        }
    }
}

impl PlanningGridConfig {
    /// Check the settings.
    ///
    /// # Errors
    /// [`GridMapError::InvalidConfig`] for an inflation that is not finite, not negative and at
    /// most 1000 m, a walked relief or point margin that is not finite and non-negative, a
    /// point margin above 1 m, or an invalid cost.
    pub fn validate(&self) -> Result<(), GridMapError> {
        check(
            self.inflation.is_finite() && (0.0..=1000.0).contains(&self.inflation),
            "PlanningGridConfig::inflation",
            self.inflation,
            "finite, from 0 to 1000 m",
        )?;
        check_not_negative(&[
            ("PlanningGridConfig::walked_relief", self.walked_relief),
            ("PlanningGridConfig::point_margin", self.point_margin),
        ])?;
        check(
            self.point_margin <= 1.0,
            "PlanningGridConfig::point_margin",
            self.point_margin,
            "at most 1 m",
        )?;
        self.cost.validate()
    }

    /// The farthest distance (metres) that matters: beyond it a cell is neither blocked nor
    /// penalised.
    fn reach(&self) -> f64 {
        // An obstacle's points count the margin nearer.
        let inflation = self.inflation + self.point_margin;
        if self.cost.weight > 0.0 {
            inflation.max(self.cost.zero_beyond)
        } else {
            inflation
        }
    }
}

/// The obstacles of `occupancy` inside `rect` (non-empty, on the grid) as a grid of its own:
/// occupied cells, and unknown cells when they count as blocked. Word by word.
fn obstacles(
    occupancy: &OccupancyGrid,
    rect: CellRect,
    unknown: UnknownCells,
) -> Result<BitGrid, GridMapError> {
    let (w, h) = (rect.x1 - rect.x0, rect.y1 - rect.y0);
    let mut sub = BitGrid::new(w, h)?;
    let (occupied, free) = (occupancy.occupied(), occupancy.known_free());
    let stairs = occupancy.stairs();
    for y in 0..h {
        let row = sub.row_words_mut(y);
        for (k, word) in row.iter_mut().enumerate() {
            let x = rect.x0 + 64 * k as u32;
            // Cells past the source's east edge read as blocked; the padding is restored below.
            // Stairs are no floor to walk on here.
            let occ = occupied.word_at(x, rect.y0 + y) | stairs.word_at(x, rect.y0 + y);
            *word = if unknown == UnknownCells::Blocked {
                occ | !free.word_at(x, rect.y0 + y)
            } else {
                occ
            };
        }
    }
    // Bits past the rectangle's east edge: clear them, then set the padding.
    let tail = w % 64;
    if tail != 0 {
        let last = sub.stride_words() - 1;
        for y in 0..h {
            sub.row_words_mut(y)[last] &= (1u64 << tail) - 1;
        }
    }
    sub.restore_padding();
    Ok(sub)
}

/// A cell's half diagonal in cells, rounded up: how far an obstacle point can lie from its
/// cell's centre.
const HALF_DIAGONAL: f64 = 0.707_2;

/// Squared distance, in cells, from the centre of cell `(x, y)` of `occupancy` to the nearest
/// obstacle within `radius` cells (columns and rows) of it: the box of the points in each
/// occupied cell ([`OccupancyGrid::extent`]) less `margin` cells, the centre of each other
/// obstacle of `sub` (the obstacles over `source`: unknown cells when they count). Infinite
/// when there is none.
fn squared_distance_to_points(
    occupancy: &OccupancyGrid,
    sub: &BitGrid,
    source: CellRect,
    (x, y): (u32, u32),
    (radius, margin): (i64, f64),
) -> f64 {
    let mut best = f64::INFINITY;
    let (sx, sy) = (i64::from(x - source.x0), i64::from(y - source.y0));
    let (w, h) = (i64::from(sub.width()), i64::from(sub.height()));
    for dy in -radius..=radius {
        let oy = sy + dy;
        if oy < 0 || oy >= h {
            continue;
        }
        let near_y = (dy.abs() as f64 - 0.5).max(0.0);
        for dx in -radius..=radius {
            let ox = sx + dx;
            let near_x = (dx.abs() as f64 - 0.5).max(0.0);
            // The nearest a point of that cell can be, less the margin.
            let nearest = ((near_x * near_x + near_y * near_y).sqrt() - margin).max(0.0);
            if ox < 0 || ox >= w || nearest * nearest >= best {
                continue;
            }
            if !sub.is_blocked(Cell::new(ox as u32, oy as u32)) {
                continue;
            }
            let cell = Cell::new(source.x0 + ox as u32, source.y0 + oy as u32);
            let d2 = match occupancy.extent(cell) {
                Some(points) if !points.is_centre() => {
                    let d =
                        (points.squared_distance_from_centre((dx, dy)).sqrt() - margin).max(0.0);
                    d * d
                }
                _ => CellExtent::CENTRE.squared_distance_from_centre((dx, dy)),
            };
            best = best.min(d2);
        }
    }
    best
}

/// Every cell of `occupancy`.
fn all_cells(occupancy: &OccupancyGrid) -> CellRect {
    CellRect {
        x0: 0,
        y0: 0,
        x1: occupancy.width(),
        y1: occupancy.height(),
    }
}

/// A rectangle of cells, `x0..x1` by `y0..y1` (ends excluded).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct CellRect {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl CellRect {
    /// The rectangle holding one cell.
    #[must_use]
    pub fn cell(c: Cell) -> Self {
        Self {
            x0: c.x,
            y0: c.y,
            x1: c.x + 1,
            y1: c.y + 1,
        }
    }

    /// Whether it holds no cell.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.x0 >= self.x1 || self.y0 >= self.y1
    }

    /// Number of cells.
    #[must_use]
    pub fn len(&self) -> usize {
        if self.is_empty() {
            0
        } else {
            (self.x1 - self.x0) as usize * (self.y1 - self.y0) as usize
        }
    }

    /// The smallest rectangle holding both.
    #[must_use]
    pub fn union(&self, other: &Self) -> Self {
        if self.is_empty() {
            return *other;
        }
        if other.is_empty() {
            return *self;
        }
        Self {
            x0: self.x0.min(other.x0),
            y0: self.y0.min(other.y0),
            x1: self.x1.max(other.x1),
            y1: self.y1.max(other.y1),
        }
    }

    /// Grown by `cells` on every side, cut to a `width` x `height` grid.
    #[must_use]
    pub fn grown(&self, cells: u32, width: u32, height: u32) -> Self {
        Self {
            x0: self.x0.saturating_sub(cells).min(width),
            y0: self.y0.saturating_sub(cells).min(height),
            x1: self.x1.saturating_add(cells).min(width),
            y1: self.y1.saturating_add(cells).min(height),
        }
    }
}

/// The planning layer over an occupancy grid: the blocked cells (obstacles, and unknown cells
/// unless configured free, hard-inflated by [`PlanningGridConfig::inflation`]), each cell's
/// clearance (metres to the nearest obstacle, capped at the reach: the larger of the inflation
/// plus the point margin and the cost's `zero_beyond`) and its step-cost multiplier.
///
/// Build it once per map ([`PlanningGrid::new`], linear in cells), then after each change of the
/// occupancy (a live layer's update) [`PlanningGrid::refresh`] the changed rectangle: the work
/// covers the rectangle grown by twice the reach, not the map. Plan with pathfind's
/// `CellCostAStar::new(planning.blocked(), planning.step_costs())`, or with any shortest-path
/// planner on [`PlanningGrid::blocked`] when the cost is off.
#[derive(Debug, PartialEq)]
pub struct PlanningGrid {
    config: PlanningGridConfig,
    blocked: BitGrid,
    clearance: Vec<f32>,
    costs: Vec<f32>,
    roomy: RoomyCache,
    /// Cells the robot walked ([`PlanningGrid::with_walked`]): inflated by the walked inflation.
    walked: Option<BitGrid>,
}

impl Clone for PlanningGrid {
    fn clone(&self) -> Self {
        Self {
            config: self.config.clone(),
            blocked: self.blocked.clone(),
            clearance: self.clearance.clone(),
            costs: self.costs.clone(),
            roomy: self.roomy.clone(),
            walked: self.walked.clone(),
        }
    }

    /// A copy of `source` in this grid's memory (its clearance and costs, 8 bytes a cell),
    /// reallocated only when `source` is larger: a navigator made for each walk of an
    /// exploration copies its planning grid into the last one's.
    fn clone_from(&mut self, source: &Self) {
        self.config.clone_from(&source.config);
        self.blocked.clone_from(&source.blocked);
        self.clearance.clone_from(&source.clearance);
        self.costs.clone_from(&source.costs);
        self.roomy.clone_from(&source.roomy);
        self.walked.clone_from(&source.walked);
    }
}

/// The last roomy mask asked for ([`PlanningGrid::roomy`]) with its clearance, kept up to date
/// by [`PlanningGrid::refresh`]. A cache: grids equal but for it compare equal.
#[derive(Clone, Debug, Default)]
struct RoomyCache(std::sync::OnceLock<(f32, BitGrid)>);

impl PartialEq for RoomyCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl PlanningGrid {
    /// The planning layer of `occupancy`.
    ///
    /// # Errors
    /// [`GridMapError::InvalidConfig`] for invalid settings.
    pub fn new(
        occupancy: &OccupancyGrid,
        config: PlanningGridConfig,
    ) -> Result<Self, GridMapError> {
        config.validate()?;
        let (w, h) = (occupancy.width(), occupancy.height());
        let mut grid = Self {
            blocked: occupancy.occupied().clone(),
            clearance: vec![0.0; w as usize * h as usize],
            costs: vec![1.0; w as usize * h as usize],
            config,
            roomy: RoomyCache::default(),
            walked: None,
        };
        grid.recompute(occupancy, all_cells(occupancy))?;
        Ok(grid)
    }

    /// This layer with `walked` (cells the robot's path crossed, e.g. [`crate::walked_cells`],
    /// over `occupancy`, the grid it was built from) inflated by the inflation less
    /// [`PlanningGridConfig::walked_relief`] (not below 0), here and in every
    /// [`Self::refresh`]. Obstacle cells stay blocked, and so does a walked cell that a new
    /// obstacle comes within the walked inflation of.
    ///
    /// # Errors
    /// [`GridMapError::GeometryMismatch`] when `walked` or `occupancy` is not the size and
    /// placement of this layer.
    pub fn with_walked(
        mut self,
        occupancy: &OccupancyGrid,
        walked: BitGrid,
    ) -> Result<Self, GridMapError> {
        let same = |g: &BitGrid| {
            (g.width(), g.height()) == (self.blocked.width(), self.blocked.height())
                && g.geometry() == self.blocked.geometry()
        };
        if !same(&walked) {
            return Err(GridMapError::GeometryMismatch);
        }
        self.walked = Some(walked);
        self.recompute(occupancy, all_cells(occupancy))?;
        Ok(self)
    }

    /// The cells walked ([`Self::with_walked`]), when given.
    #[must_use]
    pub fn walked(&self) -> Option<&BitGrid> {
        self.walked.as_ref()
    }

    /// Bring the layer up to date after the occupancy changed inside `changed` (cells outside it
    /// must be as they were). Recomputes the distance transform over `changed` grown by twice
    /// the reach and writes the cells within one reach of it, the only ones whose capped
    /// clearance can change. Returns the rectangle written (empty when `changed` is).
    ///
    /// # Errors
    /// [`GridMapError::GeometryMismatch`] when `occupancy` is not the grid the layer was built
    /// for (size or placement).
    pub fn refresh(
        &mut self,
        occupancy: &OccupancyGrid,
        changed: CellRect,
    ) -> Result<CellRect, GridMapError> {
        if changed.is_empty() {
            return Ok(changed);
        }
        let (w, h) = (occupancy.width(), occupancy.height());
        let written = changed.grown(self.reach_cells(), w, h);
        self.recompute(occupancy, written)?;
        Ok(written)
    }

    /// Cells of the reach, rounded up, plus one for the rounding of the centres.
    fn reach_cells(&self) -> u32 {
        let cells = (self.config.reach() / self.blocked.geometry().resolution).ceil() + 1.0;
        cells.min(f64::from(u32::MAX / 4)) as u32
    }

    /// Recompute the cells of `written` from the obstacles within one reach of it.
    fn recompute(
        &mut self,
        occupancy: &OccupancyGrid,
        written: CellRect,
    ) -> Result<(), GridMapError> {
        let (w, h) = (occupancy.width(), occupancy.height());
        if (w, h) != (self.blocked.width(), self.blocked.height())
            || occupancy.geometry() != self.blocked.geometry()
        {
            return Err(GridMapError::GeometryMismatch);
        }
        if written.is_empty() {
            return Ok(());
        }
        let source = written.grown(self.reach_cells(), w, h);
        let sub = obstacles(occupancy, source, self.config.unknown)?;
        let d2 = squared_distance_cells(&sub);
        let res = occupancy.geometry().resolution;
        let reach = self.config.reach();
        let r_cells = self.config.inflation / res;
        let limit = r_cells * r_cells + 1e-9;
        let walked_cells = (self.config.inflation - self.config.walked_relief).max(0.0) / res;
        let walked_limit = walked_cells * walked_cells + 1e-9;
        // Cells whose distance to the obstacles' points could fall on either side of a limit
        // (a point lies within half a cell's diagonal of its cell's centre, the margin nearer)
        // are measured from the points; the others keep the distance between centres.
        let margin = self.config.point_margin / res;
        let (near, far) = (
            walked_cells.min(r_cells) - HALF_DIAGONAL,
            r_cells + margin + HALF_DIAGONAL,
        );
        let search = (far.ceil() as i64, margin);
        let sub_w = sub.width() as usize;
        for y in written.y0..written.y1 {
            for x in written.x0..written.x1 {
                let k = (y - source.y0) as usize * sub_w + (x - source.x0) as usize;
                let i = y as usize * w as usize + x as usize;
                let centres = d2[k];
                let d = centres.sqrt();
                let d2 = if centres > 0.0 && d > near && d <= far {
                    squared_distance_to_points(occupancy, &sub, source, (x, y), search)
                        .min((d + HALF_DIAGONAL) * (d + HALF_DIAGONAL))
                } else {
                    centres
                };
                let metres = (d2.sqrt() * res).min(reach);
                self.clearance[i] = metres as f32;
                self.costs[i] = self.config.cost.multiplier(metres);
                // The same test as `inflate`, so that the blocked cells are `inflate`'s where
                // no points are recorded (but for the cells walked).
                let walked = self
                    .walked
                    .as_ref()
                    .is_some_and(|m| m.is_blocked(Cell::new(x, y)));
                let blocked = d2 <= if walked { walked_limit } else { limit };
                self.blocked.set(Cell::new(x, y), blocked)?;
                if let Some((min_clearance, roomy)) = self.roomy.0.get_mut() {
                    roomy.set(Cell::new(x, y), blocked || (metres as f32) < *min_clearance)?;
                }
            }
        }
        Ok(())
    }

    /// The settings.
    #[must_use]
    pub fn config(&self) -> &PlanningGridConfig {
        &self.config
    }

    /// Blocked cells: obstacles (and unknown cells, unless configured free) inflated by the
    /// inflation radius (less the walked relief on the cells walked), with the occupancy grid's
    /// size and placement.
    #[must_use]
    pub fn blocked(&self) -> &BitGrid {
        &self.blocked
    }

    /// The step-cost multiplier of every cell (row-major, at least 1; all 1 with the cost off).
    #[must_use]
    pub fn step_costs(&self) -> &[f32] {
        &self.costs
    }

    /// Metres from every cell centre to the nearest obstacle (row-major): to its points less
    /// the point margin where a cell lies within a cell's diagonal of the inflation, to the
    /// obstacle cells' centres elsewhere; capped at the reach (the larger of the inflation plus
    /// the point margin and the cost's `zero_beyond`; the former alone with the cost off).
    #[must_use]
    pub fn clearance(&self) -> &[f32] {
        &self.clearance
    }

    /// The blocked cells and every cell closer than `min_clearance` metres to an obstacle: the
    /// grid on which straight segments between a path's waypoints keep room to spare. The mask
    /// of the last clearance asked for is kept and kept up to date by [`Self::refresh`], so a
    /// navigator that asks every plan builds it once per map; another clearance is computed
    /// afresh. A clearance beyond the reach blocks every cell (clearances are capped there); one
    /// that is not above zero (or NaN) adds no cell to the blocked ones.
    ///
    /// ```
    /// use gridmap::{OccupancyGridBuilder, OccupancyGridConfig, PlanningGrid, PlanningGridConfig};
    /// use nalgebra::{Point3, Vector2};
    /// use slam_core::PointCloud;
    ///
    /// // A room of 4 m by 4 m, its walls sampled every 5 cm at the LiDAR's height.
    /// let mut walls = Vec::new();
    /// for i in 0..=80 {
    ///     let a = i as f32 * 0.05;
    ///     walls.extend([[a, 0.0], [a, 4.0], [0.0, a], [4.0, a]].map(|[x, y]| Point3::new(x, y, 0.5)));
    /// }
    /// let occupancy = OccupancyGridBuilder::new(OccupancyGridConfig::default())?
    ///     .build(&PointCloud::from_points(walls), 0.5)?;
    /// let planning = PlanningGrid::new(&occupancy, PlanningGridConfig::default())?;
    /// let roomy = planning.roomy(0.6);
    /// let cell = |x, y| planning.blocked().cell_at(Vector2::new(x, y)).unwrap();
    /// // 0.45 m from a wall: free to stand on, not roomy; the middle is both.
    /// assert!(!planning.blocked().is_blocked(cell(2.0, 0.45)) && roomy.is_blocked(cell(2.0, 0.45)));
    /// assert!(!roomy.is_blocked(cell(2.0, 2.0)));
    /// # Ok::<(), gridmap::GridMapError>(())
    /// ```
    #[must_use]
    pub fn roomy(&self, min_clearance: f64) -> std::borrow::Cow<'_, BitGrid> {
        let limit = min_clearance as f32;
        let mask = || {
            let mut roomy = self.blocked.clone();
            let w = self.blocked.width() as usize;
            for (k, &d) in self.clearance.iter().enumerate() {
                if d < limit {
                    // The cell exists: k indexes the grid's cells.
                    let _ = roomy.set(Cell::new((k % w) as u32, (k / w) as u32), true);
                }
            }
            roomy
        };
        let (kept, roomy) = self.roomy.0.get_or_init(|| (limit, mask()));
        if kept.to_bits() == limit.to_bits() {
            std::borrow::Cow::Borrowed(roomy)
        } else {
            std::borrow::Cow::Owned(mask())
        }
    }

    /// Whether the cost is on (a positive weight): plan with a cost-aware planner; otherwise
    /// every multiplier is 1 and the fastest shortest-path planner gives the same paths.
    #[must_use]
    pub fn cost_enabled(&self) -> bool {
        self.config.cost.weight > 0.0
    }

    /// Whether any of `cells` is blocked (or off the grid): the test for replanning when a live
    /// layer's update blocked part of the current path.
    #[must_use]
    pub fn blocks_any(&self, cells: &[Cell]) -> bool {
        cells.iter().any(|&c| self.blocked.is_blocked(c))
    }
}
