//! `FloorMaps`: a walk over several floors as one navigation map per floor, each flight of
//! stairs the walk took marked as stairs on the grids of both floors it joins, and the flights
//! as links between the floors' planning grids for [`FloorGraph`](crate::nav::FloorGraph).

use gridmap::{Climb, FloorLevels, UnknownCells, inflate, stairs_cells};
use nalgebra::{Point3, Vector2};
use slam_core::{BitGrid, PointCloud, Pose3};

use crate::nav::NavError;
use crate::nav::config::NavigationMapConfig;
use crate::nav::floor_route::StairsLink;
use crate::nav::navigation_map::NavigationMap;
use crate::nav::stairs_links::SAME_FLIGHT;
use crate::nav::stairs_links::stairs_links_with_walks;

/// The walk over a flight is looked at from this far (in plan view) before it leaves one floor
/// to this far after it reaches the other (metres): the poses between two floors' height bands
/// cover the middle of a flight, the first and last steps lie beyond them.
const FLIGHT_ENDS: f64 = 1.0;
/// A storey's floor lies within this of its level's height (metres): the floor estimate's
/// tiles are kept within it ([`NavigationMap::from_scans_at_level`]). Beside a stairwell the
/// estimate sank 0.1-0.2 m (to the top steps and the last riser), and the floor's own returns
/// rose into the obstacle band: 4 % of an upper floor's occupied cells were none.
const FLOOR_LEVEL_TOLERANCE: f64 = 0.05;

/// Points up to this far below and above the walk's ground on a flight are read for its
/// treads and what stands over them (metres): more than the headroom looked at.
const STOREY_MARGIN: f64 = 1.5;

/// A flight of stairs the walk took, as found on the floors' grids.
#[derive(Clone, Debug, PartialEq)]
pub struct Flight {
    /// The floor it rises from (an index into [`FloorLevels::levels`]).
    pub lower: usize,
    /// The floor it reaches.
    pub upper: usize,
    /// Its cells on the lower floor's grid (none when that floor has no map).
    pub cells_on_lower: usize,
    /// Its cells on the upper floor's grid.
    pub cells_on_upper: usize,
}

/// A flight while the walk is read: its floors, where the walk left the lower and reached the
/// upper floor (plan view), and the cells its walks marked on each.
struct FlightMarks {
    lower: usize,
    upper: usize,
    foot: Vector2<f64>,
    top: Vector2<f64>,
    cells: [usize; 2],
}

/// A navigation map per floor of a walk over several floors, with the stairs between them.
///
/// Built from the walk's keyframes and positions ([`FloorMaps::build`]): floor `k`'s map from
/// the keyframes at its height (those on the stairs are in none), each flight the walk took
/// marked [`CellState::Stairs`](gridmap::CellState::Stairs) on both floors' grids (on the
/// lower one its steps, which the obstacle band sees as a wall; on the upper one its stairwell,
/// which it sees as floor or nothing), and the flights as [`StairsLink`]s between the floors'
/// planning grids.
#[derive(Debug)]
pub struct FloorMaps {
    floors: FloorLevels,
    maps: Vec<Result<NavigationMap, NavError>>,
    planning: Vec<Option<BitGrid>>,
    flights: Vec<Flight>,
    links: Vec<StairsLink>,
    walks: Vec<Vec<Point3<f64>>>,
}

impl FloorMaps {
    /// The maps of the walk through `positions` (the LiDAR's positions, in walking order, that
    /// `floors` was split from) with its `keyframes` (`map_T_lidar` and the scan), a LiDAR
    /// `lidar_height` metres above the floor, each floor's planning grid its occupancy with
    /// unknown cells blocked, inflated by `inflation` metres (the robot's half width and a
    /// margin).
    ///
    /// A floor whose keyframes give no map keeps the reason ([`FloorMaps::map`]); the stairs
    /// to it give no link.
    ///
    /// # Errors
    /// [`NavError::NavigationGrid`] for bad settings or an inflation that is not finite and
    /// non-negative; as [`stairs_links`](crate::nav::stairs_links) for positions that do not fit `floors`.
    pub fn build(
        keyframes: &[(Pose3, &PointCloud)],
        positions: &[Point3<f64>],
        floors: &FloorLevels,
        lidar_height: f64,
        config: &NavigationMapConfig,
        inflation: f64,
    ) -> Result<Self, NavError> {
        config.validate()?;
        let levels = floors.levels();
        let mut maps = maps_by_floor(keyframes, floors, lidar_height, config);
        let mut marks: Vec<FlightMarks> = Vec::new();
        for change in floors.changes() {
            if change.arrived_at >= positions.len() {
                // stairs_links below names the positions that do not fit.
                break;
            }
            let track = climb_track(positions, floors, change, lidar_height);
            let (lower, upper) = if levels[change.from].height <= levels[change.to].height {
                (change.from, change.to)
            } else {
                (change.to, change.from)
            };
            let ends = [positions[change.left_at], positions[change.arrived_at]];
            let (foot, top) = if lower == change.from {
                (ends[0].xy().coords, ends[1].xy().coords)
            } else {
                (ends[1].xy().coords, ends[0].xy().coords)
            };
            // Every walk over a flight adds what it saw of it; the walks over one flight are
            // one flight.
            let same = marks.iter().position(|f| {
                f.lower == lower
                    && f.upper == upper
                    && (f.foot - foot).norm() <= SAME_FLIGHT
                    && (f.top - top).norm() <= SAME_FLIGHT
            });
            let at = same.unwrap_or_else(|| {
                marks.push(FlightMarks {
                    lower,
                    upper,
                    foot,
                    top,
                    cells: [0, 0],
                });
                marks.len() - 1
            });
            let climb = Climb {
                track: &track,
                lower: levels[lower].height - lidar_height,
                upper: levels[upper].height - lidar_height,
            };
            let near = points_near(keyframes, &track, config.stairs.reach);
            for (n, floor) in [lower, upper].into_iter().enumerate() {
                let Ok(map) = &mut maps[floor] else { continue };
                let cells = stairs_cells(
                    map.occupancy(),
                    near.iter().copied(),
                    &climb,
                    &config.stairs,
                )
                .map_err(NavError::NavigationGrid)?;
                // On the floor it reaches the flight is a hole in the slab, wider than the
                // steps (a gap between their sides and the slab's edge, which reads as neither
                // floor nor step): its edge, two cells round the steps, is the stairwell too.
                let cells = if floor == upper {
                    grown_by_a_cell(&grown_by_a_cell(&cells))
                } else {
                    cells
                };
                let before = map.occupancy().stairs().count_blocked();
                map.mark_stairs(&cells)?;
                marks[at].cells[n] += map.occupancy().stairs().count_blocked() - before;
            }
        }
        let flights = marks
            .iter()
            .map(|f| Flight {
                lower: f.lower,
                upper: f.upper,
                cells_on_lower: f.cells[0],
                cells_on_upper: f.cells[1],
            })
            .collect();
        let planning: Vec<Option<BitGrid>> = maps
            .iter()
            .map(|m| match m {
                Ok(map) => inflate(
                    &map.occupancy().to_planning_grid(UnknownCells::Blocked),
                    inflation,
                )
                .map(Some)
                .map_err(NavError::NavigationGrid),
                Err(_) => Ok(None),
            })
            .collect::<Result<_, _>>()?;
        let (links, walks) = match planning
            .iter()
            .map(Option::as_ref)
            .collect::<Option<Vec<_>>>()
        {
            Some(grids) => stairs_links_with_walks(positions, floors, &grids)?
                .into_iter()
                .unzip(),
            None => (Vec::new(), Vec::new()),
        };
        Ok(Self {
            floors: floors.clone(),
            maps,
            planning,
            flights,
            links,
            walks,
        })
    }

    /// The floors, as split.
    #[must_use]
    pub fn floors(&self) -> &FloorLevels {
        &self.floors
    }

    /// Floor `k`'s map, or why its keyframes gave none; `None` for a floor not in the walk.
    #[must_use]
    pub fn map(&self, k: usize) -> Option<Result<&NavigationMap, &NavError>> {
        self.maps.get(k).map(Result::as_ref)
    }

    /// Floor `k`'s planning grid (its occupancy, unknown and stairs cells blocked, inflated);
    /// `None` when the floor has no map.
    #[must_use]
    pub fn planning(&self, k: usize) -> Option<&BitGrid> {
        self.planning.get(k).and_then(Option::as_ref)
    }

    /// The flights the walk took, as marked on the floors' grids (one per flight, however often
    /// the walk took it).
    #[must_use]
    pub fn flights(&self) -> &[Flight] {
        &self.flights
    }

    /// The walk over link `i` (the LiDAR's positions, map frame) from its foot to its top: the
    /// way a stairs controller takes over the flight ([`crate::nav::StairsClimb`]).
    #[must_use]
    pub fn link_walk(&self, i: usize) -> Option<&[Point3<f64>]> {
        self.walks.get(i).map(Vec::as_slice)
    }

    /// Each floor's localisation cloud for [`drive_across_floors`](crate::nav::drive_across_floors):
    /// the `keyframes` (`map_T_lidar` and the scan, as given to [`FloorMaps::build`]) whose
    /// height is that floor's, merged in the map frame and thinned to one point per `voxel`
    /// (metres). A floor with no keyframe gets an empty cloud.
    ///
    /// # Errors
    /// [`slam_core::CloudError`] when `voxel` is not positive and finite, or a point lies more
    /// than 2^63 voxels from the origin.
    pub fn clouds(
        &self,
        keyframes: &[(Pose3, &PointCloud)],
        voxel: f32,
    ) -> Result<Vec<PointCloud>, slam_core::CloudError> {
        (0..self.floors.levels().len())
            .map(|k| {
                let points: Vec<_> = keyframes
                    .iter()
                    .filter(|(pose, _)| self.floors.floor_at(pose.translation.z) == Some(k))
                    .flat_map(|(pose, cloud)| cloud.transformed(pose).points().to_vec())
                    .collect();
                PointCloud::from_points(points).voxel_downsample(voxel)
            })
            .collect()
    }

    /// The stairs as links between the floors' planning grids
    /// ([`stairs_links`](crate::nav::stairs_links)); none when a floor has no map.
    #[must_use]
    pub fn links(&self) -> &[StairsLink] {
        &self.links
    }
}

/// `cells` and every cell next to one (8-neighbourhood).
fn grown_by_a_cell(cells: &BitGrid) -> BitGrid {
    let mut grown = cells.clone();
    let (w, h) = (cells.width(), cells.height());
    for y in 0..h {
        for x in 0..w {
            if !cells.is_blocked(slam_core::Cell::new(x, y)) {
                continue;
            }
            for ny in y.saturating_sub(1)..=(y + 1).min(h - 1) {
                for nx in x.saturating_sub(1)..=(x + 1).min(w - 1) {
                    // In bounds by construction.
                    let _ = grown.set(slam_core::Cell::new(nx, ny), true);
                }
            }
        }
    }
    grown
}

/// Floor `k`'s map from the keyframes at its height (those on the stairs are in none), its
/// floor within [`FLOOR_LEVEL_TOLERANCE`] of the level's height, or why there is none, for each
/// floor.
fn maps_by_floor(
    keyframes: &[(Pose3, &PointCloud)],
    floors: &FloorLevels,
    lidar_height: f64,
    config: &NavigationMapConfig,
) -> Vec<Result<NavigationMap, NavError>> {
    (0..floors.levels().len())
        .map(|k| {
            let on_floor: Vec<(Pose3, &PointCloud)> = keyframes
                .iter()
                .filter(|(pose, _)| floors.floor_at(pose.translation.z) == Some(k))
                .copied()
                .collect();
            let level = floors.levels()[k].height - lidar_height;
            NavigationMap::from_scans_at_level(
                &on_floor,
                lidar_height,
                (level, FLOOR_LEVEL_TOLERANCE),
                config,
            )
        })
        .collect()
}

/// The ground under the walk over the flight of `change`: from [`FLIGHT_ENDS`] before it left
/// its floor to as far after it reached the other.
fn climb_track(
    positions: &[Point3<f64>],
    floors: &FloorLevels,
    change: gridmap::LevelChange,
    lidar_height: f64,
) -> Vec<Point3<f64>> {
    let within =
        |i: usize, end: usize| (positions[i].xy() - positions[end].xy()).norm() <= FLIGHT_ENDS;
    let mut first = change.left_at;
    while first > 0
        && floors.floor_of(first - 1) == Some(change.from)
        && within(first - 1, change.left_at)
    {
        first -= 1;
    }
    let mut last = change.arrived_at;
    while last + 1 < positions.len()
        && floors.floor_of(last + 1) == Some(change.to)
        && within(last + 1, change.arrived_at)
    {
        last += 1;
    }
    positions[first..=last]
        .iter()
        .map(|p| Point3::new(p.x, p.y, p.z - lidar_height))
        .collect()
}

/// The points of `keyframes` (in the map's frame, each with its sensor's position) within `reach` of `track`'s bounding box in
/// plan view and within a storey of its heights: all [`stairs_cells`] looks at.
fn points_near(
    keyframes: &[(Pose3, &PointCloud)],
    track: &[Point3<f64>],
    reach: f64,
) -> Vec<(Point3<f64>, Point3<f64>)> {
    let margin = Vector2::repeat(reach);
    let lo = track
        .iter()
        .fold(Vector2::repeat(f64::INFINITY), |m, p| m.inf(&p.xy().coords))
        - margin;
    let hi = track
        .iter()
        .fold(Vector2::repeat(f64::NEG_INFINITY), |m, p| {
            m.sup(&p.xy().coords)
        })
        + margin;
    let (z_lo, z_hi) = track
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.z), b.max(p.z))
        });
    let (z_lo, z_hi) = (z_lo - STOREY_MARGIN, z_hi + STOREY_MARGIN);
    let mut near = Vec::new();
    for (pose, cloud) in keyframes {
        let origin = Point3::from(pose.translation.vector);
        for p in cloud.points() {
            let q = pose * p.cast::<f64>();
            if q.x >= lo.x
                && q.x <= hi.x
                && q.y >= lo.y
                && q.y <= hi.y
                && q.z >= z_lo
                && q.z <= z_hi
            {
                near.push((q, origin));
            }
        }
    }
    near
}
