//! Mapping on the robot: the Graph-SLAM engine fed live (the point-cloud service's scans, the
//! body odometry from the robot state as its prior) while Spot walks a route of waypoints or
//! turns once in place; the map saved to and loaded from a folder.
//!
//! Every pose here is in the *start frame*: the body's frame where the run started (x forward,
//! y left, metres), which is also the frame of a saved map.

use std::path::Path;

use anyhow::{Context, Result, bail};
use nalgebra::Vector2;
use posegraph::g2o::{G2oGraph, read_g2o, write_g2o};
use slam_core::io::{PcdEncoding, PlyEncoding, read_pcd, write_pcd, write_ply};
use slam_core::{PointCloud, Pose3, PoseGraph, ScanOutcome, wrap_angle};
use spot_adapter::grpc::SpotClient;
use spot_adapter::nav::{NavigationMap, NavigationMapConfig};
use spot_adapter::pipelines::{point_to_plane_slam, slam_config};
use spot_adapter::robot::{MobilityCommand, MotionLimits, Robot, VelocityCommand};

/// The map cloud of a saved map (PCD, start frame); what `--map DIR` reads.
pub(crate) const MAP_PCD: &str = "map.pcd";
/// The same cloud as PLY, for viewers.
const MAP_PLY: &str = "map.ply";
/// The optimised pose graph (g2o `VERTEX_SE3:QUAT`, keyframe LiDAR poses in the start frame).
pub(crate) const GRAPH_G2O: &str = "graph.g2o";
/// The occupancy grid, ROS `map_server` style (`grid.yaml` beside `grid.pgm`).
const GRID_YAML: &str = "grid.yaml";

/// Read a route file: one waypoint `x y` (or `x,y`) a line, metres in the start frame; blank
/// lines and `#` comments are skipped.
///
/// # Errors
/// A file that cannot be read, a line that is not two finite numbers, or no waypoint at all.
pub(crate) fn read_route(path: &Path) -> Result<Vec<Vector2<f64>>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("route {}", path.display()))?;
    let mut route = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or_default().trim();
        if line.is_empty() {
            continue;
        }
        let numbers: Vec<f64> = line
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|w| !w.is_empty())
            .map(str::parse)
            .collect::<Result<_, _>>()
            .ok()
            .filter(|v: &Vec<f64>| v.len() == 2 && v.iter().all(|x| x.is_finite()))
            .with_context(|| {
                format!(
                    "route {} line {}: {line:?} is not `x y` (metres)",
                    path.display(),
                    n + 1
                )
            })?;
        route.push(Vector2::new(numbers[0], numbers[1]));
    }
    if route.is_empty() {
        bail!("route {} has no waypoint", path.display());
    }
    Ok(route)
}

/// What a waypoint walk needs to steer: turn toward the next waypoint, walk when it is ahead.
struct RouteFollower<'a> {
    route: &'a [Vector2<f64>],
    next: usize,
    limits: &'a MotionLimits,
    max_speed: f64,
}

/// A waypoint is reached within this distance, metres.
const WAYPOINT_TOLERANCE: f64 = 0.15;

impl RouteFollower<'_> {
    /// The command toward the next waypoint from `start_t_body`; `None` once the last is reached.
    fn command(&mut self, start_t_body: &Pose3) -> Option<VelocityCommand> {
        let position = start_t_body.translation.vector.xy();
        let yaw = start_t_body.rotation.euler_angles().2;
        loop {
            let to = self.route.get(self.next)? - position;
            if to.norm() < WAYPOINT_TOLERANCE {
                println!("waypoint {} of {} reached", self.next + 1, self.route.len());
                self.next += 1;
                continue;
            }
            let error = wrap_angle(to.y.atan2(to.x) - yaw);
            let max_turn = self.limits.max_yaw_rate;
            let yaw_rate = (1.5 * error).clamp(-max_turn, max_turn);
            // Turn in place while the waypoint is well off the heading, then walk, slowing on
            // the approach (0.8 m/s per metre left, never below a crawl the robot still takes).
            let forward = if error.abs() > 0.5 {
                0.0
            } else {
                (0.8 * to.norm()).clamp(0.1, self.max_speed) * error.cos()
            };
            return Some(VelocityCommand::new(forward, yaw_rate));
        }
    }
}

/// A map made on the robot, in the start frame.
pub(crate) struct Mapped {
    /// Every keyframe cloud at its optimised pose, 5 cm voxels.
    pub(crate) map: PointCloud,
    /// Occupancy from the keyframes' beams.
    pub(crate) navigation: NavigationMap,
    /// The optimised pose graph (keyframe LiDAR poses).
    pub(crate) graph: PoseGraph<Pose3>,
    /// The engine's estimate of the body after the last scan.
    pub(crate) start_t_body: Pose3,
}

/// Map with the Graph-SLAM engine while Spot walks `route` (waypoints in the start frame) or,
/// without one, turns once in place at `turn_rate` (rad/s); at most `max_scans` scans.
///
/// # Errors
/// Any robot error (the caller's client then stops the robot), a route not walked in
/// `max_scans` scans, an engine that kept no keyframe, or a grid that cannot be built.
pub(crate) fn map_live(
    spot: &mut SpotClient,
    route: Option<&[Vector2<f64>]>,
    turn_rate: f64,
    max_speed: f64,
    max_scans: usize,
    lidar_height: f64,
) -> Result<Mapped> {
    let mut slam = point_to_plane_slam(slam_config())?;
    let odom_t_start = spot.frame_tree()?.a_t_b("odom", "body")?;
    // The engine's map frame is the odometry frame (its first keyframe sits at its odometry
    // pose); the start frame is the body's at the start.
    let start_t_odom = odom_t_start.inverse();
    let limits = spot.description().limits.clone();
    let mut follower = route.map(|route| RouteFollower {
        route,
        next: 0,
        limits: &limits,
        max_speed,
    });
    let (mut turned, mut last_yaw) = (0.0, None::<f64>);
    let mut start_t_body = Pose3::identity();
    for scan in 1.. {
        if scan > max_scans {
            bail!(
                "mapping did not end in {max_scans} scans (--cycles): {}",
                if route.is_some() {
                    "the route was not walked"
                } else {
                    "the robot did not turn a full circle"
                }
            );
        }
        let sample = spot.next_sample()?;
        if let ScanOutcome::Skipped(reason) = slam.process(&sample.scan_input()) {
            eprintln!("scan {scan} skipped by the engine: {reason:?}");
        }
        if let Some(map_t_lidar) = slam.current_lidar_pose() {
            start_t_body = start_t_odom * map_t_lidar * sample.body_t_lidar.inverse();
        }
        let command = if let Some(follower) = follower.as_mut() {
            follower.command(&start_t_body)
        } else {
            // The turn is counted on the engine's estimate: an odometry that over- or
            // under-counts turns would end the turn short of or past a full circle.
            let yaw = start_t_body.rotation.euler_angles().2;
            if let Some(last) = last_yaw {
                turned += wrap_angle(yaw - last);
            }
            last_yaw = Some(yaw);
            (turned < std::f64::consts::TAU).then(|| VelocityCommand::new(0.0, turn_rate))
        };
        match command {
            Some(command) => spot.send(&MobilityCommand::Velocity(command))?,
            None => break,
        }
    }
    spot.stop()?;
    let report = slam.report();
    println!(
        "mapped: {} scans, {} keyframes, {} loops closed",
        report.scans, report.keyframes, report.loops_closed
    );
    if report.keyframes == 0 {
        bail!(
            "the SLAM engine kept no keyframe of {} scans (see the skipped scans above)",
            report.scans
        );
    }
    let scans: Vec<(Pose3, PointCloud)> = slam
        .keyframe_scans()
        .map(|scan| scan.map(|(pose, cloud)| (start_t_odom * pose, cloud.into_owned())))
        .collect::<Result<_, _>>()?;
    let refs: Vec<(Pose3, &PointCloud)> = scans.iter().map(|(p, c)| (*p, c)).collect();
    let navigation =
        NavigationMap::from_scans(&refs, lidar_height, &NavigationMapConfig::default())?;
    let mut graph = slam.graph().clone();
    for (i, (pose, _)) in scans.iter().enumerate() {
        graph.set_pose(i, *pose);
    }
    Ok(Mapped {
        map: slam.map(0.05)?.transformed(&start_t_odom),
        navigation,
        graph,
        start_t_body,
    })
}

/// Save `mapped` in `dir` (made if missing): the map cloud (`map.pcd`, `map.ply`), the pose
/// graph (`graph.g2o`) and the occupancy grid (`grid.yaml` with `grid.pgm`).
///
/// # Errors
/// A file that cannot be written.
pub(crate) fn save(dir: &Path, mapped: &Mapped) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("{}", dir.display()))?;
    write_pcd(dir.join(MAP_PCD), &mapped.map, PcdEncoding::Binary)?;
    write_ply(
        dir.join(MAP_PLY),
        &mapped.map,
        PlyEncoding::BinaryLittleEndian,
    )?;
    write_g2o(dir.join(GRAPH_G2O), &G2oGraph::Se3(mapped.graph.clone()))?;
    gridmap::write_ros_map(mapped.navigation.occupancy(), dir.join(GRID_YAML))?;
    println!(
        "map saved in {}: {MAP_PCD} ({} points), {MAP_PLY}, {GRAPH_G2O} ({} keyframes), {GRID_YAML}",
        dir.display(),
        mapped.map.len(),
        mapped.graph.node_count()
    );
    Ok(())
}

/// A map to navigate on: the cloud and the LiDAR poses it was seen from (start frame).
pub(crate) struct LoadedMap {
    pub(crate) map: PointCloud,
    pub(crate) viewpoints: Vec<Pose3>,
}

/// Load a map saved by [`save`] (a folder: `map.pcd` and `graph.g2o`, whose keyframes are the
/// viewpoints), or a PCD file alone (viewed from `fallback_viewpoint`).
///
/// # Errors
/// A missing or unreadable file, or a graph that is not SE(3).
pub(crate) fn load(path: &Path, fallback_viewpoint: Pose3) -> Result<LoadedMap> {
    if !path.is_dir() {
        let map = read_pcd(path).with_context(|| format!("map {}", path.display()))?;
        return Ok(LoadedMap {
            map,
            viewpoints: vec![fallback_viewpoint],
        });
    }
    let map = read_pcd(path.join(MAP_PCD))
        .with_context(|| format!("map {}", path.join(MAP_PCD).display()))?;
    let graph = match read_g2o(path.join(GRAPH_G2O))
        .with_context(|| format!("graph {}", path.join(GRAPH_G2O).display()))?
    {
        G2oGraph::Se3(graph) => graph,
        G2oGraph::Se2(_) => bail!("{} is a 2D graph", path.join(GRAPH_G2O).display()),
    };
    println!(
        "map loaded from {}: {} points, {} keyframes",
        path.display(),
        map.len(),
        graph.node_count()
    );
    Ok(LoadedMap {
        map,
        viewpoints: graph.nodes().iter().map(|n| n.pose).collect(),
    })
}
