//! Many random goals on buildings the navigator was not tuned on: each leg starts where the last
//! ended; reached, collisions and the final error are measured on the simulator's ground truth.
//! Boxes are dropped on two legs' routes after mapping, so the same twenty legs test both the
//! plain walks and replanning around new obstacles. Each building is mapped once for all its
//! tests.
#![allow(clippy::unwrap_used)]

use std::sync::OnceLock;

use crate::common::{Start, building_and_map, random_goals, run_legs};
use nalgebra::{Translation3, UnitQuaternion};
use slam_core::{PointCloud, Pose3};
use spot_adapter::nav::{DriveOutcome, NavigationMap, NavigatorConfig};
use spot_adapter::sim::Building;

/// Building `seed` (4, 5 or 6) and its maps, made on first use.
fn mapped(seed: u64) -> &'static (Building, PointCloud, NavigationMap) {
    static MAPS: [OnceLock<(Building, PointCloud, NavigationMap)>; 3] =
        [const { OnceLock::new() }; 3];
    MAPS[usize::try_from(seed - 4).unwrap()].get_or_init(|| building_and_map(seed))
}

/// 20 random goals on `seed`'s building, with 0.6 m boxes dropped after mapping on the routes
/// of the legs in `boxes_before`: prints the legs, returns (reached within 0.10 m, collisions).
fn twenty_goals(seed: u64, boxes_before: &[usize]) -> (usize, usize) {
    let (building, map, navigation) = mapped(seed);
    let start = building.corridor_loop()[0];
    let goals = random_goals(building, map, start, 20, seed);
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
    eprintln!("seed {seed}: {reached} of 20 reached within 0.10 m, {collisions} collisions");
    (reached, collisions)
}

/// Navigation starts with the estimate 0.5 m and 10 degrees off the truth: the localiser finds
/// the robot again within 10 s (50 scans) and it reaches its goal, in every building.
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

/// Twenty random goals, with two boxes dropped on routes after mapping (before legs 3 and 11):
/// at least 19 reached within 0.10 m by ground truth, no collision.
fn twenty_goals_two_boxes(seed: u64) {
    let (reached, collisions) = twenty_goals(seed, &[3, 11]);
    assert!(reached >= 19, "{reached} of 20");
    assert_eq!(collisions, 0);
}

#[test]
fn twenty_random_goals_and_two_boxes_on_building_4() {
    twenty_goals_two_boxes(4);
}

#[test]
fn twenty_random_goals_and_two_boxes_on_building_5() {
    twenty_goals_two_boxes(5);
}

#[test]
fn twenty_random_goals_and_two_boxes_on_building_6() {
    twenty_goals_two_boxes(6);
}
