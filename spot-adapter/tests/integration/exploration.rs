//! Autonomous exploration of a small simulated building with no map and no route: the
//! Graph-SLAM engine maps live, the explorer picks frontiers, the navigator walks to them.
//! Coverage is measured against the simulator's floor plan (the floor free at the robot's
//! inflation and reachable from the start), collisions and distance on its ground truth; the
//! greedy nearest-frontier baseline runs beside it on the same buildings in an ignored test
//! that gives the README's figures.
#![allow(clippy::unwrap_used)]

use gridmap::CellState;
use nalgebra::Point3;
use nalgebra::Vector2;
use slam_core::Pose3;
use spot_adapter::nav::{
    ExplorationError, ExplorationOutcome, ExplorationReport, ExplorerConfig, FrontierChoice,
    NavError, NavigatorConfig, explore,
};
use spot_adapter::pipelines::{
    point_to_plane_localiser, point_to_plane_slam, point_to_plane_tracker, slam_config,
};
use spot_adapter::robot::{MobilityCommand, Robot, RobotDescription, Sample};
use spot_adapter::sim::{
    BoxKind, Building, BuildingConfig, CommandedSpot, Room, SimError, SimulationConfig, SolidBox,
    floor_coverage,
};

/// About the smallest building the generator makes (`BuildingConfig::small`: a 10 m x 10 m
/// corridor loop with shallow rooms round it and a core of rooms inside, about 17 m x 17 m,
/// 14-16 rooms).
pub fn small_building(seed: u64) -> Building {
    Building::generate(seed, &BuildingConfig::small()).unwrap()
}

/// An exploration's figures on the ground truth.
#[derive(Debug)]
pub struct Explored {
    pub report: ExplorationReport,
    /// Share of the reachable floor that is known free in the final grid.
    pub coverage: f64,
    /// True distance walked (metres).
    pub walked: f64,
    pub collisions: usize,
    pub seconds: f64,
    /// The engine's map frame in the world (the body's start pose).
    pub world_t_map: Pose3,
}

/// A box filling `room`'s door opening, wall-thick, up to above the lintel: a closed door.
fn door_shut(room: &Room) -> SolidBox {
    let across = Vector2::new(-room.inward.y, room.inward.x);
    let (a, b) = (room.door + 0.7 * across, room.door - 0.7 * across);
    let (c, d) = (room.door + 0.1 * room.inward, room.door - 0.1 * room.inward);
    let (lo, hi) = (a.inf(&b).inf(&c.inf(&d)), a.sup(&b).sup(&c.sup(&d)));
    SolidBox {
        min: Point3::new(lo.x, lo.y, 0.0),
        max: Point3::new(hi.x, hi.y, 3.0),
        kind: BoxKind::Obstacle,
    }
}

/// The simulated Spot, closing `room`'s door ([`door_shut`]) the first time the robot stands
/// within 3 m of the door and at least 1 m outside the room: a box dropped in the way during
/// the exploration. `shut_at` is the scan it happened on.
struct ShutsADoor {
    spot: CommandedSpot,
    room: Option<Room>,
    scans: usize,
    shut_at: Option<usize>,
}

impl Robot for ShutsADoor {
    type Error = SimError;

    fn description(&self) -> &RobotDescription {
        self.spot.description()
    }

    fn next_sample(&mut self) -> Result<Sample, SimError> {
        self.scans += 1;
        if let Some(room) = &self.room
            && self.shut_at.is_none()
        {
            let from_door = self.spot.position() - room.door;
            if from_door.norm() <= 3.0 && from_door.dot(&room.inward) <= -1.0 {
                self.spot.building_mut().add_box(door_shut(room))?;
                self.shut_at = Some(self.scans);
            }
        }
        self.spot.next_sample()
    }

    fn send(&mut self, command: &MobilityCommand) -> Result<(), SimError> {
        self.spot.send(command)
    }

    fn stop(&mut self) -> Result<(), SimError> {
        self.spot.stop()
    }
}

/// Explores `building` from its first corridor corner facing east with `choice`, at most
/// `max_cycles` scans, and measures it.
pub fn explore_building(
    building: &Building,
    choice: FrontierChoice,
    max_cycles: usize,
) -> Explored {
    explore_shutting(building, choice, max_cycles, None, None).0
}

/// [`explore_building`], closing `shut`'s door on the way ([`ShutsADoor`]); coverage is
/// measured on the building as it is at the end. Also returns the scan the door shut on. With
/// `keyframes_in_memory`, the engine keeps older keyframes' map clouds in a file
/// (`GraphSlam::with_keyframe_store`), so the growing map reads them back.
fn explore_shutting(
    building: &Building,
    choice: FrontierChoice,
    max_cycles: usize,
    shut: Option<Room>,
    keyframes_in_memory: Option<usize>,
) -> (Explored, Option<usize>) {
    let mut sim = SimulationConfig::default();
    // A quarter of the VLP-16's columns (0.8 degrees): rooms of a few metres are seen as well,
    // and the simulator and the engine take a quarter of the time.
    sim.lidar.columns = 450;
    let start = building.corridor_loop()[0];
    let mut spot = ShutsADoor {
        spot: CommandedSpot::new(building.clone(), start, 0.0, &sim).unwrap(),
        room: shut,
        scans: 0,
        shut_at: None,
    };
    // The engine's map frame is the odometry frame, which starts at the body's start pose.
    let world_t_map = spot.spot.body_pose();
    let mut slam = point_to_plane_slam(slam_config()).unwrap();
    if let Some(n) = keyframes_in_memory {
        let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"));
        slam = slam.with_keyframe_store(dir, n).unwrap();
    }
    let config = ExplorerConfig {
        choice,
        ..ExplorerConfig::default()
    };
    let (mut walked, mut last) = (0.0, None::<Vector2<f64>>);
    let started = std::time::Instant::now();
    // The tracker's settings (a 0.2 m map, normals when first needed): the navigator is made
    // afresh on each decision's map, and the localiser's normals up front on a 0.1 m map took
    // as long as the rest of the decision.
    let localiser = point_to_plane_tracker();
    let report = explore(
        &mut spot,
        &mut slam,
        &localiser,
        &NavigatorConfig::default(),
        &config,
        max_cycles,
        |cycle| {
            let truth = cycle.sample.ground_truth.unwrap().translation.vector.xy();
            walked += last.map_or(0.0, |p| (truth - p).norm());
            last = Some(truth);
        },
    )
    .unwrap();
    let seconds = started.elapsed().as_secs_f64();
    if let Some(n) = keyframes_in_memory {
        assert!(slam.keyframe_count() > n);
        assert_eq!(slam.keyframe_scans_in_memory(), n);
        assert_eq!(slam.report().keyframe_store_failures, 0);
    }
    let coverage = coverage(spot.spot.building(), start, &world_t_map, &report);
    let explored = Explored {
        report,
        coverage,
        walked,
        collisions: spot.spot.collisions(),
        seconds,
        world_t_map,
    };
    (explored, spot.shut_at)
}

/// The share of `building`'s floor free at the planning inflation and 4-connected to `start`
/// that the final grid knows free (`spot_adapter::sim::floor_coverage`, as the mission reports
/// it).
pub fn coverage(
    building: &Building,
    start: Vector2<f64>,
    world_t_map: &Pose3,
    report: &ExplorationReport,
) -> f64 {
    floor_coverage(
        building,
        start,
        world_t_map,
        report.navigation.occupancy(),
        NavigatorConfig::default().planning.inflation,
    )
    .share()
}

/// The exploration stopped by itself with at least 97 % of the reachable floor known free and no
/// collision.
fn assert_complete(e: &Explored) {
    assert_eq!(e.report.outcome, ExplorationOutcome::Complete);
    assert!(e.coverage >= 0.97, "coverage {:.3}", e.coverage);
    assert_eq!(e.collisions, 0);
}

fn print(name: &str, e: &Explored) {
    eprintln!(
        "{name}: {:?} after {} scans, {} decisions ({:.0} ms mean, {:.0} ms max); coverage {:.2} %, walked {:.1} m (estimated {:.1} m), {} collisions, {} frontiers given up {:?}, {} unreachable left; {:.1} s",
        e.report.outcome,
        e.report.cycles,
        e.report.decisions,
        e.report.decision_ms.iter().sum::<f64>() / e.report.decision_ms.len().max(1) as f64,
        e.report.decision_ms.iter().copied().fold(0.0, f64::max),
        100.0 * e.coverage,
        e.walked,
        e.report.walked,
        e.collisions,
        e.report.given_up.len(),
        e.report
            .given_up
            .iter()
            .map(|g| g.reason.name())
            .collect::<Vec<_>>(),
        e.report.last_decision.unreachable.len(),
        e.seconds
    );
}

/// Our explorer maps a small building to at least 97 % of the reachable floor with no collision
/// and stops by itself, with no frontier left. How far it walks against the greedy
/// nearest-frontier explorer is measured by [`against_the_greedy_explorer`], not here (ours, the
/// nearest revealing rule, 0.44-1.02x its distance on seeds 11-28, 0.66x in all; on one building
/// small changes of the settings move either by 10-30 %).
#[test]
fn explores_a_small_building_to_full_coverage() {
    let building = small_building(11);
    let ours = explore_building(&building, FrontierChoice::default(), 3000);
    print("nearest revealing", &ours);
    assert_complete(&ours);
    assert!(ours.report.last_decision.chosen.is_none());
}

/// A building with a closed door: the room behind it is neither reachable nor counted, the
/// explorer stops by itself with the rest of the floor mapped, and nothing of the room's floor
/// is known free (the door, a wall-thick box filling the opening to above the lintel, hides it).
#[test]
fn a_closed_door_leaves_its_room_out() {
    let mut building = small_building(12);
    let room = building.rooms()[0];
    let start = building.corridor_loop()[0];
    let open = floor_coverage(
        &building,
        start,
        &Pose3::identity(),
        &gridmap::OccupancyGrid::new(
            1,
            1,
            slam_core::GridGeometry::try_new(Vector2::zeros(), 1.0).unwrap(),
            CellState::Unknown,
        )
        .unwrap(),
        NavigatorConfig::default().planning.inflation,
    );
    building.add_box(door_shut(&room)).unwrap();
    let explored = explore_building(&building, FrontierChoice::default(), 3000);
    print("closed door", &explored);
    let shut = floor_coverage(
        &building,
        start,
        &explored.world_t_map,
        explored.report.navigation.occupancy(),
        NavigatorConfig::default().planning.inflation,
    );
    // The room's floor (0.5 m in from its walls) is no longer reachable.
    let (inner_min, inner_max) = (
        room.min + Vector2::new(0.5, 0.5),
        room.max - Vector2::new(0.5, 0.5),
    );
    let room_cells = (inner_max - inner_min).product() / 0.01;
    assert!(
        (open.reachable - shut.reachable) as f64 >= 0.9 * room_cells,
        "{} reachable cells with the door open, {} shut, the room {room_cells}",
        open.reachable,
        shut.reachable
    );
    assert_complete(&explored);
    // Nothing of the room is known free.
    let grid = explored.report.navigation.occupancy();
    let map_t_world = explored.world_t_map.inverse();
    let (mut inside, mut known) = (0usize, 0usize);
    let mut y = inner_min.y;
    while y <= inner_max.y {
        let mut x = inner_min.x;
        while x <= inner_max.x {
            inside += 1;
            let p = map_t_world * Point3::new(x, y, 0.0);
            if grid
                .occupied()
                .cell_at(p.coords.xy())
                .is_some_and(|c| grid.state(c) == CellState::Free)
            {
                known += 1;
            }
            x += 0.1;
        }
        y += 0.1;
    }
    eprintln!(
        "room {:?}-{:?}: {known} of {inside} points known free; reachable {} cells open, {} shut",
        room.min, room.max, open.reachable, shut.reachable
    );
    assert!(known * 50 <= inside, "{known} of {inside} known free");
}

/// A frontier that becomes unreachable when a box drops: the room whose door lies farthest
/// from the start is shut as the robot first comes near it. What the robot saw of the room
/// through the door stays on its map with its frontiers, and the explorer says so: they are
/// given up on the way or left unreachable at the end, never walked into. The exploration still
/// stops by itself with the floor that stays reachable mapped, and no collision. The engine
/// keeps only its newest 30 keyframes' map clouds in memory, the rest in a file, which the
/// growing map reads back when it renders.
#[test]
fn a_frontier_shut_off_by_a_dropped_box_is_given_up_and_reported() {
    let building = small_building(13);
    let start = building.corridor_loop()[0];
    let room = building
        .rooms()
        .iter()
        .max_by(|a, b| (a.door - start).norm().total_cmp(&(b.door - start).norm()))
        .copied()
        .unwrap();
    let (explored, shut_at) = explore_shutting(
        &building,
        FrontierChoice::default(),
        3000,
        Some(room),
        Some(30),
    );
    print("box dropped in a door", &explored);
    let shut_at = shut_at.expect("the robot came near the door");
    let world_t_map = explored.world_t_map;
    let in_room = |p: Vector2<f64>| {
        let w = world_t_map * Point3::new(p.x, p.y, 0.0);
        let w = w.coords.xy();
        (w.x >= room.min.x && w.x <= room.max.x && w.y >= room.min.y && w.y <= room.max.y)
            || (w - room.door).norm() <= 1.5
    };
    let given_up: Vec<_> = explored
        .report
        .given_up
        .iter()
        .filter(|g| in_room(g.goal))
        .map(|g| g.reason.name())
        .collect();
    let unreachable = explored
        .report
        .last_decision
        .unreachable
        .iter()
        .filter(|f| in_room(f.centroid))
        .count();
    eprintln!(
        "door of the room {:?}-{:?} shut at scan {shut_at}; its frontiers: given up {given_up:?}, {unreachable} unreachable at the end",
        room.min, room.max
    );
    assert!(
        !given_up.is_empty() || unreachable > 0,
        "no frontier of the shut room reported"
    );
    assert_complete(&explored);
}

/// Bad explorer settings are refused by name before the robot moves.
#[test]
fn bad_exploration_settings_are_refused_by_name() {
    let building = small_building(11);
    let sim = SimulationConfig::default();
    let start = building.corridor_loop()[0];
    for (config, name) in [
        (
            ExplorerConfig {
                sensor_range: f64::NAN,
                ..ExplorerConfig::default()
            },
            "ExplorerConfig::sensor_range",
        ),
        (
            ExplorerConfig {
                decide_every: 0,
                ..ExplorerConfig::default()
            },
            "ExplorerConfig::decide_every",
        ),
        (
            ExplorerConfig {
                localise_within: 0.0,
                ..ExplorerConfig::default()
            },
            "ExplorerConfig::localise_within",
        ),
        (
            ExplorerConfig {
                localise_within: 5.0,
                ..ExplorerConfig::default()
            },
            "ExplorerConfig::localise_within",
        ),
        (
            ExplorerConfig {
                choice: FrontierChoice::InformationGain { detour: -1.0 },
                ..ExplorerConfig::default()
            },
            "FrontierChoice::InformationGain::detour",
        ),
        (
            ExplorerConfig {
                choice: FrontierChoice::Tour {
                    keep_margin: f64::INFINITY,
                },
                ..ExplorerConfig::default()
            },
            "FrontierChoice::Tour::keep_margin",
        ),
        (
            ExplorerConfig {
                choice: FrontierChoice::NearestRevealing { min_gain: f64::NAN },
                ..ExplorerConfig::default()
            },
            "FrontierChoice::NearestRevealing::min_gain",
        ),
        (
            ExplorerConfig {
                choice: FrontierChoice::NearestRevealing { min_gain: -0.5 },
                ..ExplorerConfig::default()
            },
            "FrontierChoice::NearestRevealing::min_gain",
        ),
    ] {
        let mut spot = CommandedSpot::new(building.clone(), start, 0.0, &sim).unwrap();
        let mut slam = point_to_plane_slam(slam_config()).unwrap();
        let error = explore(
            &mut spot,
            &mut slam,
            &point_to_plane_localiser(),
            &NavigatorConfig::default(),
            &config,
            10,
            |_| {},
        )
        .unwrap_err();
        match error {
            ExplorationError::Navigation(NavError::InvalidConfig(setting)) => {
                assert_eq!(setting.setting, name);
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(slam.report().scans, 0, "refused before the first scan");
    }
}

/// The README's figures: the greedy explorer, the tour (`FrontierChoice::Tour`, 2 m margin),
/// the information gain (detour 4 m) and the nearest revealing rule
/// (`FrontierChoice::NearestRevealing`, 1 m² or `EXPLORATION_MIN_GAIN`) on small buildings, seeds
/// 11-14 or `EXPLORATION_SEEDS=15-16`, the rules named in `EXPLORATION_RULES` (default
/// `greedy,tour,gain,revealing`); coverage and collisions checked for every rule but the tour,
/// the distances printed; `EXPLORATION_BLANK=1` shuts the
/// north corridor's doors (2026-12-06, against greedy, seeds 11-16: tour 0.77x, 1.15x, 1.06x,
/// 1.02x, 0.83x, 1.14x; ours 1.01x, 1.02x, 1.35x, 0.83x, 0.83x, 0.85x, 100 % coverage on each;
/// with the doors shut, seeds 11-12, 100 % for each rule). About 20 s a building:
/// `cargo test -p spot-nav-adapter --release --test integration
/// exploration::against_the_greedy_explorer -- --ignored --nocapture`.
#[test]
#[ignore = "about a minute a building; the README's figures"]
fn against_the_greedy_explorer() {
    let seeds = std::env::var("EXPLORATION_SEEDS")
        .ok()
        .and_then(|s| {
            let (a, b) = s.split_once('-')?;
            Some(a.parse().ok()?..=b.parse().ok()?)
        })
        .unwrap_or(11..=14);
    // With `EXPLORATION_BLANK` set, the north corridor's doors are shut (a closed-door case).
    let config = BuildingConfig {
        blank_corridor: std::env::var("EXPLORATION_BLANK").is_ok(),
        ..BuildingConfig::small()
    };
    // `EXPLORATION_RULES=greedy,gain` runs only those (greedy first when named: the ratios).
    let rules =
        std::env::var("EXPLORATION_RULES").unwrap_or_else(|_| "greedy,tour,gain,revealing".into());
    let rules: Vec<&str> = rules.split(',').map(str::trim).collect();
    for seed in seeds {
        let building = Building::generate(seed, &config).unwrap();
        let mut runs: Vec<(&str, Explored)> = Vec::new();
        for (name, choice) in [
            ("greedy", FrontierChoice::GreedyNearestFrontier),
            ("tour", FrontierChoice::Tour { keep_margin: 2.0 }),
            ("gain", FrontierChoice::InformationGain { detour: 4.0 }),
            (
                "revealing",
                FrontierChoice::NearestRevealing {
                    min_gain: std::env::var("EXPLORATION_MIN_GAIN")
                        .ok()
                        .and_then(|g| g.parse().ok())
                        .unwrap_or(1.0),
                },
            ),
        ] {
            if !rules.contains(&name) {
                continue;
            }
            let e = explore_building(&building, choice, 3000);
            print(&format!("seed {seed} {name}"), &e);
            if let Some((_, greedy)) = runs.iter().find(|(n, _)| *n == "greedy") {
                eprintln!(
                    "seed {seed}: {name} walks {:.2}x the greedy explorer's distance",
                    e.walked / greedy.walked
                );
            }
            runs.push((name, e));
        }
        // The tour is not checked: it left 5 % of seed 14 unseen (see the README).
        for (_, e) in runs.iter().filter(|(name, _)| *name != "tour") {
            assert_eq!(e.report.outcome, ExplorationOutcome::Complete);
            assert!(e.coverage >= 0.97, "coverage {:.3}", e.coverage);
            assert_eq!(e.collisions, 0);
        }
    }
}
