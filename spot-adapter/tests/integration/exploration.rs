//! Autonomous exploration of a small simulated building with no map and no route: the
//! Graph-SLAM engine maps live, the explorer picks frontiers, the navigator walks to them.
//! Coverage is measured against the simulator's floor plan (the floor free at the robot's
//! inflation and reachable from the start), collisions and distance on its ground truth; the
//! greedy nearest-frontier baseline runs beside it on the same buildings in an ignored test
//! that gives the README's figures.
#![allow(clippy::unwrap_used)]

use nalgebra::Vector2;
use slam_core::Pose3;
use spot_adapter::nav::{
    ExplorationError, ExplorationOutcome, ExplorationReport, ExplorerConfig, FrontierChoice,
    NavError, NavigatorConfig, explore,
};
use spot_adapter::pipelines::{
    point_to_plane_localiser, point_to_plane_slam, point_to_plane_tracker, slam_config,
};
use spot_adapter::sim::{
    Building, BuildingConfig, CommandedSpot, SimulationConfig, floor_coverage,
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
}

/// Explores `building` from its first corridor corner facing east with `choice`, at most
/// `max_cycles` scans, and measures it.
pub fn explore_building(
    building: &Building,
    choice: FrontierChoice,
    max_cycles: usize,
) -> Explored {
    let mut sim = SimulationConfig::default();
    // A quarter of the VLP-16's columns (0.8 degrees): rooms of a few metres are seen as well,
    // and the simulator and the engine take a quarter of the time.
    sim.lidar.columns = 450;
    let start = building.corridor_loop()[0];
    let mut spot = CommandedSpot::new(building.clone(), start, 0.0, &sim).unwrap();
    // The engine's map frame is the odometry frame, which starts at the body's start pose.
    let world_t_map = spot.body_pose();
    let mut slam = point_to_plane_slam(slam_config()).unwrap();
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
    let coverage = coverage(building, start, &world_t_map, &report);
    Explored {
        report,
        coverage,
        walked,
        collisions: spot.collisions(),
        seconds,
    }
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

fn print(name: &str, e: &Explored) {
    eprintln!(
        "{name}: {:?} after {} scans, {} decisions ({:.0} ms mean, {:.0} ms max); coverage {:.1} %, walked {:.1} m (estimated {:.1} m), {} collisions, {} frontiers given up {:?}, {} unreachable left; {:.1} s",
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
/// nearest-frontier explorer is measured by [`against_the_greedy_explorer`], not here: ours is
/// not reliably better yet (0.93-1.24x its distance on seeds 11-14), and on one building small
/// changes of the settings move either by 20 % or more.
#[test]
fn explores_a_small_building_to_full_coverage() {
    let building = small_building(11);
    let ours = explore_building(&building, FrontierChoice::default(), 3000);
    print("information gain", &ours);
    assert_eq!(ours.report.outcome, ExplorationOutcome::Complete);
    assert!(ours.coverage >= 0.97, "coverage {:.3}", ours.coverage);
    assert_eq!(ours.collisions, 0);
    assert!(ours.report.last_decision.chosen.is_none());
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

/// The README's figures: the greedy explorer, the tour (`FrontierChoice::Tour`, 2 m margin) and
/// ours (the default) on small buildings, seeds 11-14 or `EXPLORATION_SEEDS=15-16`; coverage and
/// collisions checked for greedy and ours, the distances printed (2026-12-05, against greedy,
/// seeds 11-16: tour 1.02x, 0.97x, 1.39x, 1.53x, 1.20x, 1.54x; ours 1.05x, 1.00x, 1.27x, 1.72x,
/// 1.21x, 0.87x, 100 % coverage on each). About a minute a building:
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
    for seed in seeds {
        let building = small_building(seed);
        let greedy = explore_building(&building, FrontierChoice::GreedyNearestFrontier, 3000);
        print(&format!("seed {seed} greedy nearest"), &greedy);
        let mut runs = vec![("greedy", greedy)];
        for (name, choice) in [
            ("tour", FrontierChoice::Tour { keep_margin: 2.0 }),
            (
                "information gain",
                FrontierChoice::InformationGain { detour: 4.0 },
            ),
        ] {
            let e = explore_building(&building, choice, 3000);
            print(&format!("seed {seed} {name}"), &e);
            eprintln!(
                "seed {seed}: {name} walks {:.2}x the greedy explorer's distance",
                e.walked / runs[0].1.walked
            );
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
