//! A live layer over a static map: each scan's obstacle band becomes a robot-centred local grid
//! (a square window at the map's resolution, as Spot's own local grids), with free cells from its
//! beams, fused over the static map; cells not seen for a while decay back to the map's state.
//! The work per update is bounded by the scan and the window, not the map.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use nalgebra::{Point3, Vector2};
use slam_core::{BitGrid, Cell, InvalidSetting, PointCloud, Pose2, Pose3};

use crate::band::{Height, ObstacleBandConfig, band_at, classify};
use crate::error::{GridMapError, check, check_finite_points, check_not_negative};
use crate::extent::CellExtent;
use crate::floor::FloorMap;
use crate::fusion::{LocalCell, LocalGrid};
use crate::occupancy::{CellState, OccupancyGrid};
use crate::planning::CellRect;
use crate::rays::{below_top, clip_to_box, traverse};

/// Settings of [`LiveLayer`]. Lengths in metres, times in seconds.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct LiveLayerConfig {
    /// Side of the square local window centred on the sensor, 8.0 m (80 x 80 cells at 0.10 m):
    /// points and beams beyond it are cut at its edge.
    pub window: f64,
    /// The obstacle band above the floor.
    pub band: ObstacleBandConfig,
    /// A window cell is an obstacle when at least this many of the scan's band points fall in
    /// it, 1.
    pub min_points: u32,
    /// A cell whose live state differs from the static map's returns to the map's state once it
    /// has not been observed for this long, 5.0 s.
    pub decay: f64,
    /// Points closer to the sensor than this (horizontally) are ignored, 0.0 m; raise it to drop
    /// returns from the robot itself.
    pub min_range: f64,
    /// A beam clears only the cells it crosses at most this high above the floor, 0.3 m: a
    /// beam passing at height h over a cell shows only that nothing taller than h stands there,
    /// so beams passing over a low obstacle (a crate the LiDAR no longer sees from close by)
    /// must not clear it.
    pub clear_below: f64,
}

impl Default for LiveLayerConfig {
    fn default() -> Self {
        Self {
            window: 8.0,
            band: ObstacleBandConfig::default(),
            min_points: 1,
            decay: 5.0,
            min_range: 0.0,
            clear_below: 0.3,
        }
    }
}

impl LiveLayerConfig {
    /// Check the settings.
    ///
    /// # Errors
    /// [`GridMapError::InvalidConfig`] for a window that is not finite and positive or exceeds
    /// 1000 m, an invalid band, `min_points == 0` or above 65,535, or a decay or minimum range
    /// that is not finite and non-negative.
    pub fn validate(&self) -> Result<(), GridMapError> {
        check_not_negative(&[("LiveLayerConfig::clear_below", self.clear_below)])?;
        check(
            self.window.is_finite() && self.window > 0.0 && self.window <= 1000.0,
            "LiveLayerConfig::window",
            self.window,
            "finite, positive and at most 1000 m",
        )?;
        self.band.validate()?;
        check(
            (1..=u32::from(u16::MAX)).contains(&self.min_points),
            "LiveLayerConfig::min_points",
            f64::from(self.min_points),
            "from 1 to 65535",
        )?;
        check_not_negative(&[
            ("LiveLayerConfig::decay", self.decay),
            ("LiveLayerConfig::min_range", self.min_range),
        ])
    }
}

/// What one [`LiveLayer::update`] changed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct LiveUpdate {
    /// Cells that became occupied.
    pub added: usize,
    /// Cells that became free.
    pub cleared: usize,
    /// Cells that returned to the static map's state because they were not observed for
    /// [`LiveLayerConfig::decay`] seconds.
    pub decayed: usize,
    /// The rectangle holding every cell whose state changed (`None` when none did): pass it to
    /// [`PlanningGrid::refresh`](crate::PlanningGrid::refresh).
    pub changed: Option<CellRect>,
    /// The rectangle of the cells the scan (or mark) changed: inside the window.
    pub observed: Option<CellRect>,
    /// The rectangle of the cells that decayed back to the static map: where the window was
    /// [`LiveLayerConfig::decay`] seconds ago. Refreshing `observed` and `reverted` separately
    /// does less work than their union `changed` when they lie apart.
    pub reverted: Option<CellRect>,
    /// The window's cells on the map this update.
    pub window: Option<CellRect>,
}

/// A pending return to the static map: `cell` is due at `due` seconds.
#[derive(Clone, Copy, Debug)]
struct Due {
    due: f64,
    cell: u32,
}

impl PartialEq for Due {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Due {}
impl PartialOrd for Due {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Due {
    // The earliest first out of the max-heap.
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .due
            .total_cmp(&self.due)
            .then(other.cell.cmp(&self.cell))
    }
}

/// Window cell states of the scratch local grid.
const UNSEEN: u8 = 0;
const SEEN_FREE: u8 = 1;
const SEEN_OCCUPIED: u8 = 2;

/// A live layer over a static occupancy map.
///
/// Each [`LiveLayer::update`] turns one scan into a local grid around the sensor (an `n x n`
/// window of the map's cells, `n = round(window / resolution)`, aligned with the map's cells):
/// band points ([`ObstacleBandConfig`] above the [`FloorMap`]) make obstacles, beams free the
/// cells their ground track crosses below the band's top (as
/// [`OccupancyGridBuilder::build_floor_band_from_scans`](crate::OccupancyGridBuilder::build_floor_band_from_scans)
/// does, one beam per end cell), occupied wins. The window is fused into the combined grid:
/// an obstacle seen goes in, a cell seen free comes out (whatever the static map says), and a cell
/// whose live state differs from the static map's returns to it once unobserved for
/// [`LiveLayerConfig::decay`] seconds.
///
/// Cost per update: the scan's points, the beams (at most one per window cell and kind, each at
/// most the window's diagonal long), the window's cells and the decayed cells (each cell that
/// ever changed is queued once, at most once at a time): bounded by the scan and the window, never
/// the map.
#[derive(Clone, Debug)]
pub struct LiveLayer {
    config: LiveLayerConfig,
    static_map: OccupancyGrid,
    combined: OccupancyGrid,
    /// When each cell was last observed with a live state differing from the map's, seconds.
    last_seen: Vec<f64>,
    /// Cells queued for a decay check (1 = queued).
    queued: BitGrid,
    due: BinaryHeap<Due>,
    previous_stamp: f64,
    /// Window side, cells.
    n: u32,
    /// Scratch window of the last update: states, band point counts, end-cell stamps.
    state: Vec<u8>,
    counts: Vec<u16>,
    /// The box of the band points in each window cell.
    extents: Vec<CellExtent>,
    hit_stamp: Vec<u32>,
    free_stamp: Vec<u32>,
    stamp: u32,
    beams: Vec<(Vector2<f64>, Vector2<f64>, bool)>,
    /// The last window's lower-left cell (signed: it may hang off the map).
    corner: (i64, i64),
}

/// The side of `config`'s window in cells of `static_map` (validating `config`).
fn window_cells(config: &LiveLayerConfig, static_map: &OccupancyGrid) -> Result<u32, GridMapError> {
    config.validate()?;
    let n = (config.window / static_map.geometry().resolution)
        .round()
        .max(1.0);
    check(
        n <= 2_000.0,
        "LiveLayerConfig::window",
        config.window,
        "at most 2,000 cells a side at the map's resolution",
    )?;
    Ok(n as u32)
}

impl LiveLayer {
    /// A live layer over `static_map` (the combined grid starts equal to it).
    ///
    /// # Errors
    /// [`GridMapError::InvalidConfig`] for invalid settings or a window above 2,000 cells a
    /// side at the map's resolution (the scratch window takes 11 bytes per cell).
    pub fn new(static_map: OccupancyGrid, config: LiveLayerConfig) -> Result<Self, GridMapError> {
        let n = window_cells(&config, &static_map)?;
        let cells = n as usize * n as usize;
        let queued = BitGrid::new(static_map.width(), static_map.height())?;
        Ok(Self {
            combined: static_map.clone(),
            last_seen: vec![
                f64::NEG_INFINITY;
                static_map.width() as usize * static_map.height() as usize
            ],
            static_map,
            config,
            queued,
            due: BinaryHeap::new(),
            previous_stamp: f64::NEG_INFINITY,
            n,
            state: vec![UNSEEN; cells],
            counts: vec![0; cells],
            extents: vec![CellExtent::CENTRE; cells],
            hit_stamp: vec![0; cells],
            free_stamp: vec![0; cells],
            stamp: 0,
            beams: Vec::new(),
            corner: (0, 0),
        })
    }

    /// This layer made anew over `static_map` with `config`: the same as
    /// [`LiveLayer::new`]`(static_map.clone(), config)`, in this layer's memory (its grids and
    /// the per-cell observation times, 8 bytes a cell), reallocated only where `static_map` is
    /// larger. Left as it was on an error.
    ///
    /// # Errors
    /// As [`LiveLayer::new`].
    pub fn renew(
        &mut self,
        static_map: &OccupancyGrid,
        config: LiveLayerConfig,
    ) -> Result<(), GridMapError> {
        let n = window_cells(&config, static_map)?;
        let cells = n as usize * n as usize;
        let queued = BitGrid::new(static_map.width(), static_map.height())?;
        self.static_map.clone_from(static_map);
        self.combined.clone_from(static_map);
        self.last_seen.clear();
        self.last_seen.resize(
            static_map.width() as usize * static_map.height() as usize,
            f64::NEG_INFINITY,
        );
        self.config = config;
        self.queued = queued;
        self.due.clear();
        self.previous_stamp = f64::NEG_INFINITY;
        self.n = n;
        self.state.clear();
        self.state.resize(cells, UNSEEN);
        for stamps in [&mut self.hit_stamp, &mut self.free_stamp] {
            stamps.clear();
            stamps.resize(cells, 0);
        }
        self.counts.clear();
        self.counts.resize(cells, 0);
        self.extents.clear();
        self.extents.resize(cells, CellExtent::CENTRE);
        self.stamp = 0;
        self.beams.clear();
        self.corner = (0, 0);
        Ok(())
    }

    /// The static map with the live changes.
    #[must_use]
    pub fn combined(&self) -> &OccupancyGrid {
        &self.combined
    }

    /// The static map.
    #[must_use]
    pub fn static_map(&self) -> &OccupancyGrid {
        &self.static_map
    }

    /// The settings.
    #[must_use]
    pub fn config(&self) -> &LiveLayerConfig {
        &self.config
    }

    /// Fuse one scan (`scan` in the sensor frame, `map_t_sensor` its pose, `stamp` its time in
    /// seconds) into the layer, then return the cells not observed for the decay time to the
    /// static map's state.
    ///
    /// # Errors
    /// [`GridMapError::InvalidConfig`] for a non-finite pose or stamp,
    /// [`GridMapError::StampOutOfOrder`] for a stamp before the previous update's,
    /// [`GridMapError::NonFinitePoints`] for a scan with non-finite points (nothing is changed
    /// then).
    pub fn update(
        &mut self,
        scan: &PointCloud,
        map_t_sensor: &Pose3,
        floor: &FloorMap,
        stamp: f64,
    ) -> Result<LiveUpdate, GridMapError> {
        self.check_stamp(stamp)?;
        self.local_window(scan, map_t_sensor, floor)?;
        self.previous_stamp = stamp;
        let mut report = LiveUpdate::default();
        let (cx, cy) = self.corner;
        let (w, h) = (
            i64::from(self.combined.width()),
            i64::from(self.combined.height()),
        );
        let (x0, y0) = (cx.max(0), cy.max(0));
        let (x1, y1) = (
            cx.saturating_add(i64::from(self.n)).min(w),
            cy.saturating_add(i64::from(self.n)).min(h),
        );
        if x0 < x1 && y0 < y1 {
            report.window = Some(CellRect {
                x0: x0 as u32,
                y0: y0 as u32,
                x1: x1 as u32,
                y1: y1 as u32,
            });
            for y in y0..y1 {
                let row = (y - cy) as usize * self.n as usize;
                for x in x0..x1 {
                    let k = row + (x - cx) as usize;
                    let seen = match self.state[k] {
                        SEEN_FREE => CellState::Free,
                        SEEN_OCCUPIED => CellState::Occupied,
                        _ => continue,
                    };
                    let cell = Cell::new(x as u32, y as u32);
                    self.observe(cell, seen, self.extents[k], stamp, &mut report)?;
                }
            }
        }
        self.decay(stamp, &mut report)?;
        Ok(report)
    }

    /// Set `cell` to `state` as observed at `stamp` (seconds), as an update would: for marking
    /// what blocks the robot (a stuck recovery) or clearing a cell by other evidence. Decays as
    /// any live change. Cells off the map are ignored.
    ///
    /// # Errors
    /// [`GridMapError::InvalidConfig`] for a non-finite stamp, [`GridMapError::StampOutOfOrder`]
    /// for a stamp before the previous update's.
    pub fn mark(
        &mut self,
        cell: Cell,
        state: CellState,
        stamp: f64,
    ) -> Result<LiveUpdate, GridMapError> {
        self.check_stamp(stamp)?;
        self.previous_stamp = stamp;
        let mut report = LiveUpdate::default();
        if cell.x < self.combined.width() && cell.y < self.combined.height() {
            self.observe(cell, state, CellExtent::CENTRE, stamp, &mut report)?;
        }
        Ok(report)
    }

    /// The local grid of the last update: the window's cells as obstacle, free or unknown,
    /// placed in the map (its corner on the map's cell boundaries), for [`fuse_local_grid`] or
    /// pictures.
    ///
    /// [`fuse_local_grid`]: crate::fuse_local_grid
    #[must_use]
    pub fn last_local_grid(&self) -> LocalGrid {
        let g = self.combined.geometry();
        let corner =
            g.origin + Vector2::new(self.corner.0 as f64, self.corner.1 as f64) * g.resolution;
        LocalGrid {
            map_t_grid: Pose2::new(corner, 0.0),
            resolution: g.resolution,
            width: self.n,
            height: self.n,
            cells: self
                .state
                .iter()
                .map(|&s| match s {
                    SEEN_FREE => LocalCell::Free,
                    SEEN_OCCUPIED => LocalCell::Obstacle,
                    _ => LocalCell::Unknown,
                })
                .collect(),
        }
    }

    fn check_stamp(&self, stamp: f64) -> Result<(), GridMapError> {
        check(stamp.is_finite(), "LiveLayer stamp", stamp, "finite")?;
        if stamp < self.previous_stamp {
            return Err(GridMapError::StampOutOfOrder {
                previous: self.previous_stamp,
                stamp,
            });
        }
        Ok(())
    }

    /// Record that `cell` was seen in state `seen` (its obstacle points within `extent` when
    /// occupied) at `stamp`.
    fn observe(
        &mut self,
        cell: Cell,
        seen: CellState,
        extent: CellExtent,
        stamp: f64,
        report: &mut LiveUpdate,
    ) -> Result<(), GridMapError> {
        if self.static_map.state(cell) == CellState::Stairs {
            // A flight stays stairs: its steps read as obstacles and its stairwell as free.
            return Ok(());
        }
        let now = self.combined.state(cell);
        let points = (seen == CellState::Occupied).then_some(extent);
        if now != seen || self.combined.extent(cell) != points {
            if seen == CellState::Occupied {
                self.combined.set_occupied_within(cell, extent)?;
            } else {
                self.combined.set(cell, seen)?;
            }
            if now != seen {
                match seen {
                    CellState::Occupied => report.added += 1,
                    CellState::Free => report.cleared += 1,
                    CellState::Unknown | CellState::Stairs => {}
                }
            }
            grow(&mut report.changed, cell);
            grow(&mut report.observed, cell);
        }
        if seen != self.static_map.state(cell) || self.static_map.extent(cell) != points {
            let i = cell.y as usize * self.combined.width() as usize + cell.x as usize;
            self.last_seen[i] = stamp;
            if !self.queued.is_blocked(cell) {
                self.queued.set(cell, true)?;
                self.due.push(Due {
                    due: stamp + self.config.decay,
                    cell: i as u32,
                });
            }
        }
        Ok(())
    }

    /// Return the cells due by `now` to the static map's state.
    fn decay(&mut self, now: f64, report: &mut LiveUpdate) -> Result<(), GridMapError> {
        let width = self.combined.width();
        while let Some(&Due { due, cell: i }) = self.due.peek() {
            if due > now {
                break;
            }
            self.due.pop();
            let cell = Cell::new(i % width, i / width);
            let original = self.static_map.state(cell);
            let points = self.static_map.extent(cell);
            if self.combined.state(cell) == original && self.combined.extent(cell) == points {
                self.queued.set(cell, false)?;
                continue;
            }
            let refreshed = self.last_seen[i as usize] + self.config.decay;
            if refreshed > now {
                self.due.push(Due {
                    due: refreshed,
                    cell: i,
                });
                continue;
            }
            self.queued.set(cell, false)?;
            match points {
                Some(extent) => self.combined.set_occupied_within(cell, extent)?,
                None => self.combined.set(cell, original)?,
            }
            report.decayed += 1;
            grow(&mut report.changed, cell);
            grow(&mut report.reverted, cell);
        }
        Ok(())
    }

    /// Fill the scratch window from one scan.
    fn local_window(
        &mut self,
        scan: &PointCloud,
        map_t_sensor: &Pose3,
        floor: &FloorMap,
    ) -> Result<(), GridMapError> {
        let t = map_t_sensor.translation.vector;
        let q = map_t_sensor.rotation.coords;
        if let Some(v) = t.iter().chain(q.iter()).copied().find(|v| !v.is_finite()) {
            return Err(InvalidSetting {
                setting: "LiveLayer map_t_sensor",
                value: v,
                expected: "finite",
            }
            .into());
        }
        check_finite_points(scan.points())?;
        let g = *self.combined.geometry();
        let res = g.resolution;
        let n = self.n;
        let half = i64::from(n / 2);
        let (sx, sy) = g.cell_coords(t.xy());
        self.corner = (sx.saturating_sub(half), sy.saturating_sub(half));
        // Window coordinates: cells from the window's corner.
        let corner_m = g.origin + Vector2::new(self.corner.0 as f64, self.corner.1 as f64) * res;
        let to_window = |p: Point3<f64>| (p.coords.xy() - corner_m) / res;
        let size = Vector2::repeat(f64::from(n));
        self.state.fill(UNSEEN);
        self.counts.fill(0);
        self.extents.fill(CellExtent::CENTRE);
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.hit_stamp.fill(0);
            self.free_stamp.fill(0);
            self.stamp = 1;
        }
        self.beams.clear();
        let origin = Point3::from(t);
        let min_range2 = self.config.min_range * self.config.min_range;
        let rotation = map_t_sensor.rotation.to_rotation_matrix();
        let (n_us, band) = (n as usize, &self.config.band);
        for p in scan.points() {
            let p = origin
                + rotation * nalgebra::Vector3::new(f64::from(p.x), f64::from(p.y), f64::from(p.z));
            let (dx, dy) = (p.x - origin.x, p.y - origin.y);
            if dx * dx + dy * dy < min_range2 {
                continue;
            }
            let limits = band_at(floor, band, p.x, p.y);
            let kind = classify(p.z, limits);
            if kind == Height::Obstacle {
                let w = to_window(p);
                if w.x >= 0.0 && w.y >= 0.0 && w.x < size.x && w.y < size.y {
                    let k = w.y as usize * n_us + w.x as usize;
                    self.counts[k] = self.counts[k].saturating_add(1);
                    let within = Vector2::new(w.x - w.x.floor(), w.y - w.y.floor());
                    self.extents[k] = self.extents[k].union(CellExtent::at(within));
                }
            }
            // The part of the beam low enough to show the cells it crosses are free.
            let clear_top = (limits.0 - band.above_floor + self.config.clear_below).min(limits.1);
            let Some((a, b)) = below_top(origin, p, clear_top) else {
                continue;
            };
            let (a, b) = (to_window(a), to_window(b));
            let within = |v: Vector2<f64>| v.x >= 0.0 && v.y >= 0.0 && v.x < size.x && v.y < size.y;
            // The sensor is at the window's centre: clip only beams that leave it.
            let (a, b, cut) = if within(a) && within(b) {
                (a, b, false)
            } else {
                let Some(clipped) = clip_to_box(a, b, size) else {
                    continue;
                };
                clipped
            };
            let k = b.y as usize * n_us + b.x as usize;
            // The end cell is free when the beam ended on the floor there.
            let include_end = kind != Height::Obstacle && !cut;
            let seen = if include_end {
                &mut self.free_stamp[k]
            } else {
                &mut self.hit_stamp[k]
            };
            if *seen != self.stamp {
                *seen = self.stamp;
                self.beams.push((a, b, include_end));
            }
        }
        let min_points = self.config.min_points as u16;
        for (s, &c) in self.state.iter_mut().zip(&self.counts) {
            if c >= min_points {
                *s = SEEN_OCCUPIED;
            }
        }
        let state = &mut self.state;
        for &(a, b, include_end) in &self.beams {
            traverse(a, b, include_end, |x, y| {
                if x >= 0 && y >= 0 && x < i64::from(n) && y < i64::from(n) {
                    let s = &mut state[y as usize * n_us + x as usize];
                    if *s == UNSEEN {
                        *s = SEEN_FREE;
                    }
                }
            });
        }
        Ok(())
    }
}

/// Grow `rect` to hold `cell`.
fn grow(rect: &mut Option<CellRect>, cell: Cell) {
    let one = CellRect::cell(cell);
    *rect = Some(rect.map_or(one, |r| r.union(&one)));
}
