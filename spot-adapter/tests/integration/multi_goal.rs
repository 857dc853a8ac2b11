//! Many random goals on buildings the navigator was not tuned on: each leg starts where the last
//! ended; reached, collisions and the final error are measured on the simulator's ground truth.
//! Boxes are dropped on two legs' routes after mapping, so the same legs test both the plain
//! walks and replanning around new obstacles. Each building is mapped once for all its tests.
//! The suite walks the first eight of each building's twenty goals, the second box dropped before
//! leg 6 instead of leg 11; the twenty, whose counts the README gives, are the ignored
//! `twenty_random_goals_*` tests.
#![allow(clippy::unwrap_used)]

use std::sync::OnceLock;

use crate::common::{Start, building_and_map, random_goals, run_legs};
use nalgebra::{Translation3, UnitQuaternion};
use slam_core::{PointCloud, Pose3, Registrator};
use spot_adapter::nav::{DriveOutcome, NavigationMap, NavigatorConfig};
use spot_adapter::pipelines::point_to_plane_localiser;
use spot_adapter::sim::{Building, CommandedSpot, SimulationConfig};

/// Building `seed` (4, 5 or 6) and its maps, made on first use.
fn mapped(seed: u64) -> &'static (Building, PointCloud, NavigationMap) {
    static MAPS: [OnceLock<(Building, PointCloud, NavigationMap)>; 3] =
        [const { OnceLock::new() }; 3];
    MAPS[usize::try_from(seed - 4).unwrap()].get_or_init(|| building_and_map(seed))
}

/// The first `count` of 20 random goals on `seed`'s building, with 0.6 m boxes dropped after
/// mapping on the routes of the legs in `boxes_before`: prints the legs, returns (reached within
/// 0.10 m, collisions).
fn random_legs(seed: u64, count: usize, boxes_before: &[usize]) -> (usize, usize) {
    let (building, map, navigation) = mapped(seed);
    let start = building.corridor_loop()[0];
    let mut goals = random_goals(building, map, start, 20, seed);
    goals.truncate(count);
    let start = Start {
        boxes_before: boxes_before.to_vec(),
        ..Start::at(start)
    };
    let legs = run_legs(
        building,
        map,
        navigation,
        &start,
        &goals,
        1500,
        &NavigatorConfig::default(),
    );
    let mut reached = 0;
    let mut collisions = 0;
    for (k, leg) in legs.iter().enumerate() {
        let ok = leg.outcome == DriveOutcome::Arrived && leg.error <= 0.10;
        reached += usize::from(ok);
        collisions += leg.collisions;
        eprintln!(
            "seed {seed} leg {k:2}: goal ({:5.1}, {:5.1}) {:?} after {:4} scans, {:5.1} m, {:.3} m off, {} collisions, localisation error up to {:.3} m",
            leg.goal.x,
            leg.goal.y,
            leg.outcome,
            leg.cycles,
            leg.walked,
            leg.error,
            leg.collisions,
            leg.worst_localisation
        );
    }
    eprintln!("seed {seed}: {reached} of {count} reached within 0.10 m, {collisions} collisions");
    (reached, collisions)
}

/// Navigation starts with the estimate 0.5 m and 10 degrees off the truth: the localiser finds
/// the robot again within 10 s (50 scans: the estimate within 5 cm), stays within 0.10 m from
/// then on (the navigation tests' bar; building 5's estimate wanders up to 5.2 cm in the last
/// half metre before its goal) and the robot reaches its goal, in every building.
fn kidnapped(seed: u64) {
    let (building, map, navigation) = mapped(seed);
    let start = building.corridor_loop()[0];
    let goals = random_goals(building, map, start, 1, seed + 100);
    let kidnap = Pose3::from_parts(
        Translation3::new(0.3, 0.4, 0.0),
        UnitQuaternion::from_euler_angles(0.0, 0.0, 10f64.to_radians()),
    );
    let start = Start {
        kidnap,
        ..Start::at(start)
    };
    let legs = run_legs(
        building,
        map,
        navigation,
        &start,
        &goals,
        1500,
        &NavigatorConfig::default(),
    );
    let leg = &legs[0];
    eprintln!("seed {seed} kidnapped: {leg:?}");
    let after = leg.localised_after.unwrap();
    assert!(after <= 50, "localised after {after} scans");
    assert!(
        leg.worst_after_localised < 0.10,
        "{} m off once localised",
        leg.worst_after_localised
    );
    assert_eq!(leg.outcome, DriveOutcome::Arrived);
    assert!(leg.error <= 0.10, "{} m off", leg.error);
    assert_eq!(leg.collisions, 0);
}

#[test]
fn a_kidnapped_start_recovers_on_building_4() {
    kidnapped(4);
}

#[test]
fn a_kidnapped_start_recovers_on_building_5() {
    kidnapped(5);
}

#[test]
fn a_kidnapped_start_recovers_on_building_6() {
    kidnapped(6);
}

/// The first `count` of twenty random goals, with two boxes dropped on routes after mapping
/// (before legs 3 and 11, or 3 and 6 when fewer than 12 are walked): reached within 0.10 m by
/// ground truth at the rate of 19 in 20 at least (one miss in twenty goals, none in
/// eight), no collision.
fn goals_and_two_boxes(seed: u64, count: usize) {
    let second_box = if count > 11 { 11 } else { 6 };
    let (reached, collisions) = random_legs(seed, count, &[3, second_box]);
    assert!(reached + count / 20 >= count, "{reached} of {count}");
    assert_eq!(collisions, 0);
}

#[test]
fn eight_random_goals_and_two_boxes_on_building_4() {
    goals_and_two_boxes(4, 8);
}

#[test]
fn eight_random_goals_and_two_boxes_on_building_5() {
    goals_and_two_boxes(5, 8);
}

#[test]
fn eight_random_goals_and_two_boxes_on_building_6() {
    goals_and_two_boxes(6, 8);
}

/// The README's figure: all twenty goals on the three buildings (about 3 minutes).
/// `cargo test -p spot-nav-adapter --release --test integration multi_goal::twenty -- --ignored --nocapture`
#[test]
#[ignore = "the README's 60-goal figure; the suite walks the first 8 of each building"]
fn twenty_random_goals_and_two_boxes_on_buildings_4_to_6() {
    for seed in 4..=6 {
        goals_and_two_boxes(seed, 20);
    }
}

/// The localiser's registration of a scan taken at each of the 20 goals (facing four ways),
/// started from the true pose, ends within 3 cm (and 1 degree) of it: the map does not pull a
/// scan off its place. With the map thinned to 0.25 m (the tracker's), the voxels of walls whose
/// both faces the lap saw centre inside the walls, and the scans at building 5's goal 3 (a room
/// seen mostly through one such wall) register 0.11 m and 0.6 degrees off.
fn registration_at_the_goals_matches_the_truth(seed: u64) {
    let (building, map, _) = mapped(seed);
    let start = building.corridor_loop()[0];
    let goals = random_goals(building, map, start, 20, seed);
    let icp = point_to_plane_localiser();
    let target = icp.prepare_target(map).unwrap();
    let sim = SimulationConfig::default();
    let mut worst = (0.0f64, 0.0f64, String::new());
    for (k, &goal) in goals.iter().enumerate() {
        for quarter in 0..4 {
            let yaw = f64::from(quarter) * std::f64::consts::FRAC_PI_2 + 0.3;
            let mut spot = CommandedSpot::new(building.clone(), goal, yaw, &sim).unwrap();
            let sample = spot.sense();
            let truth = sample.ground_truth.unwrap();
            let source = icp.prepare_source(&sample.cloud).unwrap();
            let a = icp
                .align(&source, &target, &(truth * sample.body_t_lidar))
                .unwrap();
            let off = truth.inverse() * (a.pose * sample.body_t_lidar.inverse());
            let (metres, radians) = (off.translation.vector.xy().norm(), off.rotation.angle());
            if metres > worst.0 {
                worst.2 = format!(
                    "goal {k} ({:.2}, {:.2}) facing {yaw:.2} rad, {:.0} % matched",
                    goal.x,
                    goal.y,
                    100.0 * a.inlier_ratio
                );
            }
            worst = (worst.0.max(metres), worst.1.max(radians), worst.2);
        }
    }
    let (metres, degrees) = (worst.0, worst.1.to_degrees());
    eprintln!(
        "building {seed}: registration at the goals at most {metres:.3} m ({}) and {degrees:.2} degrees off",
        worst.2
    );
    assert!(metres <= 0.03, "{metres:.3} m off at {}", worst.2);
    assert!(degrees <= 1.0, "{degrees:.2} degrees off");
}

#[test]
fn registration_at_the_goals_matches_the_truth_on_building_4() {
    registration_at_the_goals_matches_the_truth(4);
}

#[test]
fn registration_at_the_goals_matches_the_truth_on_building_5() {
    registration_at_the_goals_matches_the_truth(5);
}

#[test]
fn registration_at_the_goals_matches_the_truth_on_building_6() {
    registration_at_the_goals_matches_the_truth(6);
}
