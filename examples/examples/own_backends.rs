//! Your own backends plugged into spot-nav, on a simulated Spot: a registrator, an optimizer and a
//! planner written here, outside the library, used by the Graph-SLAM engine and the navigator.
//!
//! - `CountingIcp` (a `MapRegistrator`): our point-to-plane ICP with every call forwarded, the
//!   alignments counted. It registers the odometry and refines the loops.
//! - `CountingLevenbergMarquardt` (an `Optimizer`): our Levenberg-Marquardt, its runs counted.
//! - `GridDijkstra` (a `slam_core::Planner`): Dijkstra's algorithm on the planning grid, written
//!   here, and `OwnPlanner` (a `NavPlanner`) that builds it on each grid the navigator plans on.
//!   It refuses grids over its cell budget with its own error, carried by `PlanError::Backend`.
//!
//! 1. Mapping: Spot walks one lap of the building's corridor loop; the engine maps it with the
//!    backends above. Prints the ATE against the simulator's ground truth.
//! 2. Navigation: from where the lap ended, the navigator walks Spot to the entry of the room
//!    farthest away, planning with `OwnPlanner`. Prints how far the true body ended from it.
//!
//! The loop refinement's ICP settings (an `IcpConfig`) and the navigator's (a `NavigatorConfig`)
//! come from a TOML file, `examples/config/own_backends.toml` unless `--config` names another,
//! read with serde and the `toml` crate: fields the file leaves out keep their defaults.
//!
//! Like a crate of your own, this file uses nothing of spot-nav but the one `spot-adapter`
//! dependency (with its `serde` feature): the prelude, and the backend crates it re-exports.
//!
//! Exits with status 1 when the ATE exceeds `--max-ate`, a backend was never called, or the
//! goal was not reached within 0.10 m.
//!
//! `cargo run --release -p spot-nav-examples --example own_backends -- [--seed N] [--max-ate M] [--config FILE]`

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::process::ExitCode;
use std::sync::atomic::{AtomicUsize, Ordering};

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::Parser;
use serde::Deserialize;
use spot_adapter::pathfind::movement::DIRECTIONS;
use spot_adapter::prelude::{
    Alignment, Cell, CommandedSpot, DriveOutcome, GraphSlam, GridPath, IcpConfig,
    LevenbergMarquardt, MapRegistrator, NavPlanner, NavigationMap, Navigator, NavigatorConfig,
    OptimizationReport, OptimizeError, Optimizer, PlanError, Planner, PlanningGrid, Point3,
    PointCloud, PointToPlaneIcp, PointToPointIcp, Pose3, PoseGraph, RegistrationError, Registrator,
    Robot, SimulatedSpot, SimulationConfig, TrajectoryEvaluation, drive, point_to_plane_localiser,
    point_to_plane_tracker, slam_config,
};
use spot_adapter::slam_core::{BitGrid, Reach, SweepAlignment, validate_endpoints};
use spot_nav_examples::out;

/// A goal counts as reached within this distance of the true body (metres).
const REACHED_WITHIN: f64 = 0.10;

/// Scans the walk may take (5 minutes at 5 Hz).
const MAX_CYCLES: usize = 1500;

/// Map a simulated building with your own registrator and optimizer, then walk to a room with
/// your own planner.
#[derive(Parser, Debug)]
#[command(version)]
struct Args {
    /// The building and the run (the simulator's seed).
    #[arg(long, default_value_t = 3)]
    seed: u64,
    /// Fail above this absolute trajectory error of the mapping lap (metres, RMS).
    #[arg(long, default_value_t = 0.05)]
    max_ate: f64,
    /// The settings file (TOML: `[icp]`, `[navigator]`) [default: the bundled
    /// `examples/config/own_backends.toml`].
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
}

// ---------------------------------------------------------------------------------------------
// Settings from a file: spot-nav's configuration structs with its `serde` feature, each under a
// table. `serde(default)` here and on each struct: what the file leaves out keeps its default.

/// The settings file.
#[derive(Debug, Default, Deserialize)]
#[serde(default, deny_unknown_fields)]
struct Settings {
    /// The loop refinement's point-to-plane ICP.
    icp: IcpConfig,
    /// The navigator, and the map it plans on.
    navigator: NavigatorConfig,
}

impl Settings {
    /// The settings in the TOML file at `path`.
    fn read(path: &std::path::Path) -> Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read the settings file {}", path.display()))?;
        toml::from_str(&text).with_context(|| format!("settings file {}", path.display()))
    }
}

// ---------------------------------------------------------------------------------------------
// A registrator: ours, wrapped. Every method is forwarded: `MapRegistrator` has no defaults, so
// a wrapper that left out `empty_map`/`add_to_map`/`remove_from_map` would not compile (with
// defaults it would, and the engine would rebuild its local map whole for every keyframe instead
// of sliding it in place). A backend that builds maps only whole implements
// `WholeMapRegistrator` instead.

/// Point-to-plane ICP with its alignments counted.
#[derive(Debug, Default)]
struct CountingIcp {
    icp: PointToPlaneIcp,
    alignments: AtomicUsize,
}

impl CountingIcp {
    fn new(icp: PointToPlaneIcp) -> Self {
        Self {
            icp,
            alignments: AtomicUsize::new(0),
        }
    }

    fn alignments(&self) -> usize {
        self.alignments.load(Ordering::Relaxed)
    }

    fn count(&self) {
        self.alignments.fetch_add(1, Ordering::Relaxed);
    }
}

impl Registrator for CountingIcp {
    type Source = <PointToPlaneIcp as Registrator>::Source;
    type Target = <PointToPlaneIcp as Registrator>::Target;

    fn prepare_source(&self, cloud: &PointCloud) -> Result<Self::Source, RegistrationError> {
        self.icp.prepare_source(cloud)
    }

    fn prepare_target(&self, cloud: &PointCloud) -> Result<Self::Target, RegistrationError> {
        self.icp.prepare_target(cloud)
    }

    fn align(
        &self,
        source: &Self::Source,
        target: &Self::Target,
        initial: &Pose3,
    ) -> Result<Alignment, RegistrationError> {
        self.count();
        self.icp.align(source, target, initial)
    }

    fn align_within(
        &self,
        source: &Self::Source,
        target: &Self::Target,
        initial: &Pose3,
        reach: &Reach,
    ) -> Result<Alignment, RegistrationError> {
        self.count();
        self.icp.align_within(source, target, initial, reach)
    }

    fn align_sweep(
        &self,
        sweep: &PointCloud,
        target: &Self::Target,
        initial: &Pose3,
    ) -> Option<Result<SweepAlignment, RegistrationError>> {
        self.count();
        self.icp.align_sweep(sweep, target, initial)
    }
}

impl MapRegistrator for CountingIcp {
    fn target_from_sources(
        &self,
        parts: &[(&Self::Source, Pose3)],
    ) -> Result<Self::Target, RegistrationError> {
        self.icp.target_from_sources(parts)
    }

    fn fit_to_scan(&mut self, points: usize) {
        self.icp.fit_to_scan(points);
    }

    fn map_voxel(&self) -> Option<f32> {
        self.icp.map_voxel()
    }

    fn keyframe_source(&self, source: Self::Source) -> Self::Source {
        self.icp.keyframe_source(source)
    }

    fn source_voxel(&self) -> Option<f32> {
        self.icp.source_voxel()
    }

    fn empty_map(&self) -> Option<Self::Target> {
        self.icp.empty_map()
    }

    fn add_to_map(&self, map: &mut Self::Target, key: u32, source: &Self::Source, pose: &Pose3) {
        self.icp.add_to_map(map, key, source, pose);
    }

    fn remove_from_map(&self, map: &mut Self::Target, key: u32) {
        self.icp.remove_from_map(map, key);
    }

    fn ready_map_beside(&self, map: &mut Self::Target, beside: &mut (dyn FnMut() + Send)) {
        self.icp.ready_map_beside(map, beside);
    }

    fn ready_map_ahead(&self, map: &mut Self::Target) {
        self.icp.ready_map_ahead(map);
    }

    fn stored_source(&self, source: &Self::Source) -> Option<Vec<u8>> {
        self.icp.stored_source(source)
    }

    fn restored_source(&self, bytes: &[u8]) -> Option<Self::Source> {
        self.icp.restored_source(bytes)
    }
}

// ---------------------------------------------------------------------------------------------
// An optimizer: ours, wrapped.

/// Levenberg-Marquardt with its runs counted.
#[derive(Debug, Default)]
struct CountingLevenbergMarquardt {
    solver: LevenbergMarquardt,
    runs: usize,
}

impl Optimizer<Pose3> for CountingLevenbergMarquardt {
    fn optimize(
        &mut self,
        graph: &mut PoseGraph<Pose3>,
    ) -> Result<OptimizationReport, OptimizeError> {
        self.runs += 1;
        self.solver.optimize(graph)
    }
}

// ---------------------------------------------------------------------------------------------
// A planner of your own: Dijkstra's algorithm, 8-connected, diagonal steps sqrt(2) that cut no
// corner (pathfind's movement model, which the navigator checks every path it gets against).

/// A grid larger than the planner's cell budget: its own error, which the navigator passes on
/// as the source of [`PlanError::Backend`].
#[derive(Debug)]
struct GridTooLarge {
    cells: usize,
    budget: usize,
}

impl std::fmt::Display for GridTooLarge {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} cells exceed the budget of {}",
            self.cells, self.budget
        )
    }
}

impl std::error::Error for GridTooLarge {}

/// Dijkstra's algorithm on one grid (a [`Planner`] is built for one grid).
struct GridDijkstra<'g> {
    grid: &'g BitGrid,
    budget: usize,
}

impl Planner for GridDijkstra<'_> {
    fn plan(&mut self, start: Cell, goal: Cell) -> Result<Option<GridPath>, PlanError> {
        validate_endpoints(self.grid, start, goal)?;
        let (width, height) = (self.grid.width() as usize, self.grid.height() as usize);
        let cells = width * height;
        if cells > self.budget {
            let budget = self.budget;
            return Err(PlanError::backend(
                "grid-dijkstra",
                GridTooLarge { cells, budget },
            ));
        }
        let index = |c: Cell| c.y as usize * width + c.x as usize;
        let mut cost = vec![f64::INFINITY; cells];
        let mut parent = vec![usize::MAX; cells];
        // Costs are finite and not negative: their bits order as the numbers do.
        let mut open = BinaryHeap::new();
        cost[index(start)] = 0.0;
        open.push(Reverse((0.0f64.to_bits(), index(start))));
        let mut expanded = 0;
        while let Some(Reverse((bits, at))) = open.pop() {
            if f64::from_bits(bits) > cost[at] {
                continue; // an outdated entry
            }
            expanded += 1;
            if at == index(goal) {
                break;
            }
            let (x, y) = ((at % width) as i64, (at / width) as i64);
            for (dx, dy) in DIRECTIONS.map(|(dx, dy)| (i64::from(dx), i64::from(dy))) {
                let free = |x, y| self.grid.is_free_signed(x, y);
                let diagonal = dx != 0 && dy != 0;
                if !free(x + dx, y + dy) || (diagonal && !(free(x + dx, y) && free(x, y + dy))) {
                    continue;
                }
                let next = (y + dy) as usize * width + (x + dx) as usize;
                let step = if diagonal {
                    std::f64::consts::SQRT_2
                } else {
                    1.0
                };
                let through = cost[at] + step;
                if through < cost[next] {
                    cost[next] = through;
                    parent[next] = at;
                    open.push(Reverse((through.to_bits(), next)));
                }
            }
        }
        if cost[index(goal)].is_infinite() {
            return Ok(None);
        }
        let mut path = vec![goal];
        let mut at = index(goal);
        while at != index(start) {
            at = parent[at];
            path.push(Cell::new((at % width) as u32, (at / width) as u32));
        }
        path.reverse();
        Ok(Some(GridPath {
            cells: path,
            length: cost[index(goal)],
            expanded,
        }))
    }
}

/// The navigator's planner: [`GridDijkstra`] built on each grid it is handed, its queries
/// counted. It keeps nothing from one query to the next (`Memory = ()`).
#[derive(Debug)]
struct OwnPlanner {
    /// Grids of more cells are refused.
    budget: usize,
    queries: usize,
    /// Paths found.
    found: usize,
}

impl NavPlanner for OwnPlanner {
    type Memory = ();

    fn plan(
        &mut self,
        grid: &PlanningGrid,
        _memory: &mut (),
        start: Cell,
        goal: Cell,
    ) -> Result<Option<GridPath>, PlanError> {
        self.queries += 1;
        let mut dijkstra = GridDijkstra {
            grid: grid.blocked(),
            budget: self.budget,
        };
        let path = dijkstra.plan(start, goal)?;
        self.found += usize::from(path.is_some());
        Ok(path)
    }
}

// ---------------------------------------------------------------------------------------------

fn main() -> ExitCode {
    spot_nav_examples::run(|| own_backends(&Args::parse()))
}

/// The engine with the backends of this file.
type OwnSlam = GraphSlam<CountingIcp, PointToPointIcp, CountingLevenbergMarquardt>;

fn own_backends(args: &Args) -> Result<()> {
    let path = args.config.clone().unwrap_or_else(|| {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("config/own_backends.toml")
    });
    let settings = Settings::read(&path)?;
    let config = SimulationConfig::with_seed(args.seed);
    let sim = SimulatedSpot::corridor_loop(&config)?;
    let building = sim.building().clone();
    let body_t_lidar = sim.body_t_lidar();
    let truth = sim.ground_truth();

    // 1. Mapping with your registrator and optimizer.
    let mut slam = own_slam(settings.icp)?;
    for sample in sim {
        // A skipped scan is counted in the report.
        let _outcome = slam.process(&sample.scan_input());
    }
    let (evaluation, _) =
        TrajectoryEvaluation::of_lidar_trajectory(slam.scan_trajectory(), &body_t_lidar, &truth)?;
    let ate = evaluation.ate.rmse;
    let report = slam.report();
    let loops_closed = report.loops_closed;
    out!(
        "mapping     {} scans, {} keyframes, {loops_closed} loops closed; ATE {ate:.3} m",
        report.scans,
        report.keyframes,
    )?;
    let (odometry, refinements, runs) = (
        slam.registrator().alignments(),
        slam.loop_refine_registrator().alignments(),
        slam.optimizer().runs,
    );
    out!(
        "backends    registrator {odometry} odometry and {refinements} loop alignments; optimizer {runs} runs"
    )?;

    // 2. Navigation with your planner. The map frame is the odometry frame of the lap, which
    // starts at the first body pose; the LiDAR sits its mounting above the body.
    let world_t_map = truth.first().context("empty lap")?.pose;
    let map_t_lidar = slam.current_lidar_pose().context("no scan was mapped")?;
    let loaded = slam.keyframe_scans().collect::<Result<Vec<_>, _>>()?;
    let scans: Vec<(Pose3, &PointCloud)> = loaded.iter().map(|(p, c)| (*p, c.as_ref())).collect();
    let lidar_height = config.spot.body_height + config.spot.body_t_lidar.translation.z;
    let navigation =
        NavigationMap::from_scans(&scans, lidar_height, &settings.navigator.map_config())?;
    let lap_end = truth.last().context("empty lap")?.pose;
    let start = lap_end.translation.vector.xy();
    let goal_world = building
        .rooms()
        .iter()
        .map(spot_adapter::sim::Room::entry_point)
        .max_by(|a, b| (a - start).norm().total_cmp(&(b - start).norm()))
        .context("the building has no room")?;
    let goal = (world_t_map.inverse() * Point3::new(goal_world.x, goal_world.y, 0.0))
        .coords
        .xy();
    let mut spot = CommandedSpot::new(building, start, lap_end.rotation.euler_angles().2, &config)?;
    let planner = OwnPlanner {
        budget: 4_000_000,
        queries: 0,
        found: 0,
    };
    let mut navigator = Navigator::new(
        point_to_plane_localiser(),
        &slam.map(0.05)?,
        &navigation,
        map_t_lidar * body_t_lidar.inverse(),
        spot.description(),
        settings.navigator,
    )?
    .with_planner(planner);
    // What the backends were built with, read back from them.
    out!(
        "settings    {}: loop refinement kernel {:?}, reach {} m; navigator replans every {} cycles",
        path.display(),
        slam.loop_refine_registrator().icp.config.kernel,
        slam.loop_refine_registrator()
            .icp
            .config
            .max_correspondence_distance,
        navigator.config().replan_every
    )?;
    let walk = drive(&mut spot, &mut navigator, goal, MAX_CYCLES, |_| {})?;
    let error = (spot.position() - goal_world).norm();
    let OwnPlanner { queries, found, .. } = *navigator.planner();
    out!(
        "navigation  {:?} after {} cycles, {:.3} m from the goal; the planner answered {queries} queries, {found} with a path",
        walk.outcome,
        walk.cycles,
        error
    )?;

    if ate > args.max_ate {
        bail!("ATE {ate:.3} m exceeds --max-ate {:.3} m", args.max_ate);
    }
    if odometry == 0 || (refinements == 0 && loops_closed > 0) || runs == 0 {
        bail!("a backend of the engine was never called");
    }
    if found == 0 {
        bail!("the planner found no path");
    }
    if walk.outcome != DriveOutcome::Arrived || error > REACHED_WITHIN {
        bail!(
            "the goal was not reached: {:?}, {error:.3} m from it",
            walk.outcome
        );
    }
    Ok(())
}

/// The engine with your registrator (odometry as the pipelines' point-to-plane tracker, loop
/// refinement with `refine`) and optimizer; our point-to-point ICP checks loop candidates.
fn own_slam(refine: IcpConfig) -> Result<OwnSlam> {
    let loop_check = PointToPointIcp {
        config: IcpConfig {
            max_correspondence_distance: 1.0,
            pair_target_points: 1,
            ..IcpConfig::default()
        },
    };
    let refine = PointToPlaneIcp { config: refine };
    Ok(GraphSlam::try_new(
        slam_config(),
        CountingIcp::new(point_to_plane_tracker()),
        loop_check,
        CountingIcp::new(refine),
        CountingLevenbergMarquardt::default(),
    )?)
}
