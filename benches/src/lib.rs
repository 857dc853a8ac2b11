//! Shared helpers for the benches: where the benchmark data lives, and the peers measured in the
//! same run.

use std::path::{Path, PathBuf};

use slam_core::{BitGrid, Cell};

/// Root of the public benchmark data: `$SPOT_NAV_DATA`, or `../shared/data` beside the workspace.
#[must_use]
pub fn data_root() -> PathBuf {
    std::env::var_os("SPOT_NAV_DATA").map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/data"),
        PathBuf::from,
    )
}

/// The data root when it exists; otherwise prints a notice naming the variable and returns `None`.
#[must_use]
pub fn data_root_or_notice(what: &str) -> Option<PathBuf> {
    let root = data_root();
    if root.is_dir() {
        Some(root)
    } else {
        eprintln!(
            "{what}: benchmark data not found at {} (set SPOT_NAV_DATA to the shared data folder); skipping",
            root.display()
        );
        None
    }
}

/// The Moving AI maps of the data folder `root` (`movingai/maps/SET/NAME.map` with a
/// `movingai/scenarios/SET/NAME.map.scen`), as `(set, name)` sorted by set and name.
#[must_use]
pub fn movingai_maps(root: &Path) -> Vec<(String, String)> {
    let scenarios = root.join("movingai/scenarios");
    let mut out = Vec::new();
    let Ok(sets) = std::fs::read_dir(&scenarios) else {
        return out;
    };
    for set in sets.flatten() {
        let Ok(files) = std::fs::read_dir(set.path()) else {
            continue;
        };
        let set = set.file_name().to_string_lossy().into_owned();
        for file in files.flatten() {
            let file = file.file_name().to_string_lossy().into_owned();
            if let Some(name) = file.strip_suffix(".map.scen")
                && root
                    .join(format!("movingai/maps/{set}/{name}.map"))
                    .is_file()
            {
                out.push((set.clone(), name.to_owned()));
            }
        }
    }
    out.sort();
    out
}

/// The maps a bench runs: those named in the comma-separated variable `var` (any map of the
/// data folder, or `all`), else `default`'s that the folder has.
#[must_use]
pub fn pick_movingai_maps(root: &Path, var: &str, default: &[&str]) -> Vec<(String, String)> {
    let found = movingai_maps(root);
    let picked = std::env::var(var).ok();
    let wanted = |name: &str| match picked.as_deref() {
        Some("all") => true,
        Some(list) => list.split(',').any(|m| m == name),
        None => default.contains(&name),
    };
    found.into_iter().filter(|(_, name)| wanted(name)).collect()
}

/// The peer planner: the `pathfinding` crate's generic `astar`, the common Rust choice, with a
/// successor closure that follows the same movement rule ([`pathfind::movement`]: 8-connected,
/// no corner cutting) and an octile heuristic. Costs are integers (`pathfinding` needs `Ord`):
/// 1 = 1e-6 cells, so lengths are exact to about 1e-6 per step.
pub mod pathfinding_peer {
    use pathfind::movement::{DIRECTIONS, can_step};

    use super::{BitGrid, Cell};

    /// Cost of a straight step.
    pub const STRAIGHT: u64 = 1_000_000;
    /// Cost of a diagonal step (sqrt(2) rounded).
    pub const DIAGONAL: u64 = 1_414_214;

    fn octile(a: (u32, u32), b: (u32, u32)) -> u64 {
        let dx = u64::from(a.0.abs_diff(b.0));
        let dy = u64::from(a.1.abs_diff(b.1));
        let (lo, hi) = if dx < dy { (dx, dy) } else { (dy, dx) };
        (hi - lo) * STRAIGHT + lo * DIAGONAL
    }

    /// How far the peer's length may lie from a scenario's optimum: the file's own tolerance
    /// plus what the rounded diagonal cost adds (at most one rounding error per diagonal step, and
    /// a path of length `L` has at most `L / sqrt 2` of them). A `version 1.0` file rounds to two
    /// decimals, which leaves no room for the rounding error on long paths.
    #[must_use]
    pub fn length_tolerance(optimal_length: f64, file_tolerance: f64) -> f64 {
        let per_diagonal = (DIAGONAL as f64 / STRAIGHT as f64 - std::f64::consts::SQRT_2).abs();
        file_tolerance + optimal_length / std::f64::consts::SQRT_2 * per_diagonal
    }

    /// Shortest path length (in cells) from `start` to `goal`, or `None`.
    #[must_use]
    pub fn astar_length(grid: &BitGrid, start: Cell, goal: Cell) -> Option<f64> {
        let goal_t = (goal.x, goal.y);
        let (_, cost) = pathfinding::directed::astar::astar(
            &(start.x, start.y),
            |&(x, y)| {
                let (x, y) = (i64::from(x), i64::from(y));
                let mut out: Vec<((u32, u32), u64)> = Vec::with_capacity(8);
                for (dx, dy) in DIRECTIONS {
                    let (dx, dy) = (i64::from(dx), i64::from(dy));
                    if can_step(grid, x, y, dx, dy) {
                        let cost = if dx != 0 && dy != 0 {
                            DIAGONAL
                        } else {
                            STRAIGHT
                        };
                        out.push((((x + dx) as u32, (y + dy) as u32), cost));
                    }
                }
                out
            },
            |&p| octile(p, goal_t),
            |&p| p == goal_t,
        )?;
        Some(cost as f64 / STRAIGHT as f64)
    }
}

/// A simulated building mapped as the navigator maps it: one lap of the corridor loop on the
/// simulated Spot, every few scans kept with its true LiDAR pose, the floor found under the
/// LiDAR poses and the obstacle band's occupancy with free space from the beams.
pub mod mapped_building {
    use gridmap::{
        FloorConfig, FloorMap, GridMapError, ObstacleBandConfig, OccupancyGrid,
        OccupancyGridBuilder, OccupancyGridConfig, floor_hints_below,
    };
    use slam_core::{PointCloud, Pose3};
    use spot_adapter::sim::{Building, BuildingConfig, Route, SimulatedSpot, SimulationConfig};

    /// The mapped building.
    #[derive(Debug)]
    pub struct MappedBuilding {
        /// Kept scans (LiDAR frame) with their true `world_T_lidar`.
        pub scans: Vec<(Pose3, PointCloud)>,
        /// The floor under the LiDAR poses (0.80 m above the floor).
        pub floor: FloorMap,
        /// The obstacle band's occupancy at 0.10 m, unknown where no beam passed.
        pub occupancy: OccupancyGrid,
    }

    /// Building `seed` of the default generator, mapped from every `every`-th scan of one lap
    /// (noise and drift of the default simulation).
    ///
    /// # Errors
    /// The simulation's or the grid's error, as text.
    pub fn map(seed: u64, every: usize) -> Result<MappedBuilding, String> {
        let config = SimulationConfig::default();
        let sim = Building::generate(seed, &BuildingConfig::default())
            .and_then(|b| SimulatedSpot::new(b.clone(), &Route::corridor_loop(&b), &config))
            .map_err(|e| e.to_string())?;
        let body_t_lidar = sim.body_t_lidar();
        let scans: Vec<(Pose3, PointCloud)> = sim
            .step_by(every.max(1))
            .filter_map(|s| s.ground_truth.map(|t| (t * body_t_lidar, s.cloud)))
            .collect();
        let grid = |e: GridMapError| e.to_string();
        let refs: Vec<(Pose3, &PointCloud)> = scans.iter().map(|(p, c)| (*p, c)).collect();
        let poses: Vec<Pose3> = scans.iter().map(|(p, _)| *p).collect();
        let lidar_height = config.spot.body_height + config.spot.body_t_lidar.translation.z;
        let hints = floor_hints_below(&poses, lidar_height);
        let floor =
            FloorMap::estimate_from_scans(&refs, &hints, &FloorConfig::default()).map_err(grid)?;
        let occupancy = OccupancyGridBuilder::new(OccupancyGridConfig::default())
            .and_then(|b| {
                b.build_floor_band_from_scans(&refs, &floor, &ObstacleBandConfig::default())
            })
            .map_err(grid)?;
        Ok(MappedBuilding {
            scans,
            floor,
            occupancy,
        })
    }
}

/// Resident memory of this process in MB (`VmRSS`), 0 where `/proc` has none.
#[must_use]
pub fn resident_mb() -> f64 {
    status_mb("VmRSS:")
}

/// The process's peak resident memory so far in MB (`VmHWM` in `/proc/self/status`, 0 where that
/// is unavailable): the high-water mark the kernel keeps, peaks between samples included.
#[must_use]
pub fn peak_resident_mb() -> f64 {
    status_mb("VmHWM:")
}

/// The `/proc/self/status` field `field` (a size in kB) in MB, 0 where unavailable.
fn status_mb(field: &str) -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix(field))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        })
        .map_or(0.0, |kb| kb / 1024.0)
}

/// The `q` quantile (nearest rank) of `ms`.
#[must_use]
pub fn quantile(ms: &[f64], q: f64) -> f64 {
    let mut sorted = ms.to_vec();
    sorted.sort_by(f64::total_cmp);
    let rank = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len().max(1));
    sorted.get(rank - 1).copied().unwrap_or(0.0)
}
