//! Walking to a goal on another floor: maps of each floor from scans along the floors tour (at
//! the true poses, so that the test is of the walk, not of SLAM), then the simulated Spot
//! driven by `drive_across_floors` from the ground floor up the stairs to a goal upstairs and
//! back down to one on the ground floor. The oracle: the simulator's true pose and floor.

#![allow(clippy::unwrap_used, clippy::panic)]

use crate::floors::{TourWalk, floor_maps, scans_along, tour_walk};
use nalgebra::{Point3, Vector2};
use slam_core::Cell;
use slam_core::{PointCloud, Pose3};
use spot_adapter::nav::{
    DriveOutcome, FloorCell, FloorGraph, FloorMaps, FloorPoint, NavigatorConfig, StairsClimbConfig,
    drive_across_floors,
};
use spot_adapter::pipelines::point_to_plane_localiser;
use spot_adapter::sim::{
    Building, BuildingConfig, CommandedSpot, STAIRS_JOLT, STAIRS_NOD, SimulationConfig,
};

/// Building `seed` with `floors` floors, its maps per floor and each floor's localisation
/// cloud, from a scan every metre of the floors tour.
fn mapped(seed: u64, floors: usize) -> (Building, FloorMaps, Vec<PointCloud>) {
    let TourWalk {
        building: b,
        lidar_poses,
        positions,
        split,
    } = tour_walk(seed, floors);
    let scans: Vec<(Pose3, PointCloud)> = scans_along(&b, &lidar_poses, seed, 1.0, None)
        .into_iter()
        .map(|(pose, cloud)| (pose, cloud.voxel_downsample(0.05).unwrap()))
        .collect();
    let maps = floor_maps(&scans, &positions, &split);
    let keyframes: Vec<(Pose3, &PointCloud)> = scans.iter().map(|(p, c)| (*p, c)).collect();
    let clouds = maps.clouds(&keyframes, 0.05).unwrap();
    (b, maps, clouds)
}

/// Up the stairs to a goal in the upper floor's far corridor corner, then back down to one in
/// the ground floor's: each reached within 0.10 m on the right floor, one flight each way, no
/// collision.
#[test]
fn a_goal_upstairs_is_reached_over_the_stairs_and_one_downstairs_on_the_way_back() {
    let (b, maps, clouds) = mapped(5, 2);
    assert_eq!(maps.links().len(), 1);
    let corners = *b.corridor_loop();
    let start = corners[0];
    let config = SimulationConfig::default();
    let mut spot = CommandedSpot::new(b, start, 0.0, &config).unwrap();
    let registrator = point_to_plane_localiser();
    let mut pose = spot.body_pose();
    let mut floor = 0;
    for goal in [
        FloorPoint {
            floor: 1,
            at: corners[2],
        },
        FloorPoint {
            floor: 0,
            at: 0.5 * (corners[1] + corners[2]),
        },
    ] {
        let report = drive_across_floors(
            &mut spot,
            &maps,
            &clouds,
            &registrator,
            &NavigatorConfig::default(),
            StairsClimbConfig::default(),
            (floor, pose),
            goal,
            3000,
        )
        .unwrap();
        assert_eq!(report.outcome, DriveOutcome::Arrived, "{report:?}");
        assert_eq!(report.flights, 1, "{report:?}");
        assert_eq!(spot.floor(), goal.floor, "{report:?}");
        let truth = spot.body_pose();
        let off = (truth.translation.vector.xy() - goal.at).norm();
        assert!(
            off < 0.10,
            "{off:.3} m from the goal on floor {}",
            goal.floor
        );
        assert!(
            (truth.translation.z - spot.building().floor_height(goal.floor) - 0.5).abs() < 0.01,
            "standing on floor {}: {}",
            goal.floor,
            truth.translation.z
        );
        assert_eq!(spot.collisions(), 0);
        pose = report.pose;
        floor = report.floor;
    }
}

/// A goal off every floor's map, on a floor the maps do not have, or not finite is refused by
/// name before the robot moves; one that no walk and no stairs reach is no path, before it
/// moves.
#[test]
fn a_goal_that_is_on_no_floor_is_refused_before_moving() {
    use spot_adapter::nav::{DriveError, NavError};
    let (b, maps, clouds) = mapped(5, 2);
    let start = b.corridor_loop()[0];
    let mut spot = CommandedSpot::new(b, start, 0.0, &SimulationConfig::default()).unwrap();
    let pose = spot.body_pose();
    let registrator = point_to_plane_localiser();
    let mut to = |goal: FloorPoint| {
        drive_across_floors(
            &mut spot,
            &maps,
            &clouds,
            &registrator,
            &NavigatorConfig::default(),
            StairsClimbConfig::default(),
            (0, pose),
            goal,
            100,
        )
    };
    let off = to(FloorPoint {
        floor: 1,
        at: Vector2::new(500.0, 3.0),
    });
    assert!(
        matches!(
            off,
            Err(DriveError::Navigation(NavError::OffFloorMap {
                floor: 1,
                ..
            }))
        ),
        "{off:?}"
    );
    let nan = to(FloorPoint {
        floor: 1,
        at: Vector2::new(f64::NAN, 3.0),
    });
    assert!(
        matches!(
            nan,
            Err(DriveError::Navigation(NavError::NonFiniteGoal { .. }))
        ),
        "{nan:?}"
    );
    let missing = to(FloorPoint {
        floor: 7,
        at: Vector2::new(3.0, 3.0),
    });
    assert!(
        matches!(
            missing,
            Err(DriveError::Navigation(NavError::NoSuchFloor {
                floor: 7,
                ..
            }))
        ),
        "{missing:?}"
    );
    // A free cell upstairs that no walk and no stairs reach (a pocket the inflation closes):
    // no path, before the robot moves.
    let grids: Vec<_> = (0..2).map(|k| maps.planning(k).unwrap()).collect();
    let graph = FloorGraph::new(grids.clone(), maps.links().to_vec()).unwrap();
    let start = FloorCell {
        floor: 0,
        cell: grids[0].cell_at(pose.translation.vector.xy()).unwrap(),
    };
    let upstairs = grids[1];
    let pocket = (0..upstairs.height())
        .step_by(3)
        .flat_map(|y| {
            (0..upstairs.width())
                .step_by(3)
                .map(move |x| Cell::new(x, y))
        })
        .filter(|&c| !upstairs.is_blocked(c))
        .take(400)
        .find(|&c| {
            graph
                .route(start, FloorCell { floor: 1, cell: c })
                .unwrap()
                .is_none()
        })
        .expect("a free cell upstairs that no route reaches");
    let cut_off = to(FloorPoint {
        floor: 1,
        at: upstairs.cell_center(pocket),
    })
    .unwrap();
    assert_eq!(cut_off.outcome, DriveOutcome::NoPath);
    assert!(cut_off.route.is_none());
    assert_eq!(cut_off.cycles, 0);
    assert!((spot.body_pose().translation.vector - pose.translation.vector).norm() < 1e-9);
}

/// The simulated Spot on a flight (the oracle: the staircase's own steps; seed 5's has a
/// landing midway): with the stairs mode off it cannot walk onto the flight; with it on it
/// climbs, its body rising with the steps (a jolt at each step's edge, within half a rise of the
/// step under it) and pitched nose up as steeply as a rise over a tread, nodding with each
/// step, and stands on the upper floor past the top.
#[test]
fn the_simulated_spot_climbs_a_flight_only_in_the_stairs_mode() {
    use spot_adapter::robot::VelocityCommand;
    let b = Building::generate(
        5,
        &BuildingConfig {
            floors: 2,
            ..BuildingConfig::default()
        },
    )
    .unwrap();
    let flight = b.staircases()[0];
    let start = flight.foot - flight.up * 0.6;
    let yaw = flight.up.y.atan2(flight.up.x);
    let config = SimulationConfig::default();
    let mut spot = CommandedSpot::new(b, start, yaw, &config).unwrap();
    let ahead = VelocityCommand::new(0.3, 0.0);
    for _ in 0..10 {
        spot.step(ahead);
    }
    let along = |spot: &CommandedSpot| (spot.position() - flight.foot).dot(&flight.up);
    assert!(
        along(&spot) < -0.2,
        "walked onto the flight: {}",
        along(&spot)
    );
    assert!(spot.collisions() > 0);
    let refused = spot.collisions();
    assert!(flight.landing.is_some());
    let (mut highest_pitch, mut jolt) = (0.0_f64, 0.0_f64);
    while along(&spot) < flight.run() + 0.6 {
        spot.step_on_stairs(ahead);
        let body = spot.body_pose();
        let u = along(&spot);
        if u > 0.3 && u < flight.run() - 0.3 {
            // Within half a rise of the step under the body (the body's ground is a line
            // through the step tops).
            let ground = body.translation.z - 0.5;
            assert!(
                (ground - flight.surface_at(u)).abs() <= 0.5 * flight.rise + 1e-9,
                "{u:.2} m up: ground {ground:.3} against the step's {:.3}",
                flight.surface_at(u)
            );
            // Off the smooth line through the treads' middles (as far as half a rise).
            jolt = jolt.max((ground - flight.walk_height(u)).abs());
            let (_, pitch, _) = body.rotation.euler_angles();
            highest_pitch = highest_pitch.max(-pitch);
        }
    }
    assert!(
        jolt > 0.1 * flight.rise && jolt <= STAIRS_JOLT * 0.5 * flight.rise + 1e-9,
        "jolt {jolt}"
    );
    assert_eq!(spot.collisions(), refused);
    assert_eq!(spot.floor(), 1);
    assert!((spot.body_pose().translation.z - spot.building().floor_height(1) - 0.5).abs() < 1e-9);
    let slope = (flight.rise / flight.tread).atan();
    assert!(
        highest_pitch > slope + 0.5 * STAIRS_NOD && highest_pitch < slope + STAIRS_NOD + 1e-9,
        "pitch {highest_pitch} against {slope} and a {STAIRS_NOD} rad nod"
    );
}

/// A stairs controller refuses a walk it cannot follow and settings it cannot use, by name.
#[test]
fn a_stairs_climb_refuses_a_walk_too_short_or_not_finite_and_bad_settings() {
    use spot_adapter::nav::{NavError, StairsClimb};
    let named = |r: Result<StairsClimb, NavError>, name: &str| match r {
        Err(NavError::InvalidConfig(e)) => assert_eq!(e.setting, name),
        other => panic!("{name}: {other:?}"),
    };
    let id = Pose3::identity();
    let ok = StairsClimbConfig::default();
    named(
        StairsClimb::new(&[Point3::origin()], id, id, ok),
        "StairsClimb walk",
    );
    named(
        StairsClimb::new(
            &[Point3::origin(), Point3::new(f64::NAN, 0.0, 0.0)],
            id,
            id,
            ok,
        ),
        "StairsClimb walk",
    );
    let walk = [Point3::origin(), Point3::new(1.0, 0.0, 0.5)];
    for (bad, name) in [
        (
            StairsClimbConfig { speed: 0.0, ..ok },
            "StairsClimbConfig::speed",
        ),
        (
            StairsClimbConfig {
                run_out: f64::NAN,
                ..ok
            },
            "StairsClimbConfig::run_out",
        ),
        (
            StairsClimbConfig {
                max_yaw_rate: -1.0,
                ..ok
            },
            "StairsClimbConfig::max_yaw_rate",
        ),
    ] {
        named(StairsClimb::new(&walk, id, id, bad), name);
    }
}

/// Each floor's grid against that floor's true plan (the oracle: the building's boxes on that
/// floor, `Building::clearance_on`; each floor has its own rooms and furniture): on every
/// floor, as on the ground floor (whose grid is made as a single floor's is), 99.5 % of the
/// occupied cells lie within 0.15 m of a true obstacle and 98 % of the known-free cells outside
/// every one (those inside are under desks and crates the beams pass over). Before each
/// storey's floor was held to its level, 4 % of an upper floor's occupied cells were its own
/// floor, beside the stairwell.
#[test]
fn each_floors_grid_matches_its_floor_plan() {
    use gridmap::CellState;
    let (b, maps, _) = mapped(11, 3);
    let mut figures = Vec::new();
    for k in 0..3 {
        let grid = maps.map(k).unwrap().unwrap().occupancy();
        let (mut occupied, mut near, mut free, mut outside) = (0_usize, 0_usize, 0_usize, 0_usize);
        for y in 0..grid.height() {
            for x in 0..grid.width() {
                let cell = Cell::new(x, y);
                let clearance = b.clearance_on(k, grid.geometry().cell_center(cell), None);
                match grid.state(cell) {
                    CellState::Occupied => {
                        occupied += 1;
                        near += usize::from(clearance <= 0.15);
                    }
                    CellState::Free => {
                        free += 1;
                        outside += usize::from(clearance > 0.0);
                    }
                    _ => {}
                }
            }
        }
        let share = |a: usize, b: usize| a as f64 / b as f64;
        figures.push((share(near, occupied), share(outside, free)));
        assert!(free > 100_000, "floor {k}: {free} free cells");
    }
    eprintln!("(occupied near an obstacle, known-free outside) per floor: {figures:?}");
    for &(near, outside) in &figures {
        assert!(near > 0.995 && outside > 0.98, "{figures:?}");
    }
}
