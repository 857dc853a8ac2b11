//! Perceptual aliasing: a building whose south corridor repeats one room every few metres
//! (`BuildingConfig::repeated_rooms`). Scan Context proposes the look-alike rooms as loops and
//! the geometric check accepts some of them (the copies match exactly); none may survive into
//! the final map. The simulator's ground truth is the oracle for which loops are wrong.
#![allow(clippy::unwrap_used)]

use std::collections::HashMap;

use slam_core::{GraphSlamConfig, LoopRejection, Pose3};
use spot_adapter::eval::TrajectoryEvaluation;
use spot_adapter::pipelines::{point_to_plane_slam, scan_context_places, slam_config};
use spot_adapter::sim::{SimulatedSpot, SimulationConfig};

/// What one lap of the seed's building gave.
struct Lap {
    ate: f64,
    report: slam_core::SlamReport,
    /// Loop edges in the final graph: (kept by the optimiser, translation error of the
    /// measurement against the ground truth's relative pose, metres).
    loops: Vec<(bool, f64)>,
}

/// One lap of the corridor loop of `seed`'s building, with repeated rooms when `aliased`,
/// through point-to-plane SLAM with `config`, with Scan Context when `places`.
fn lap(seed: u64, aliased: bool, places: bool, config: GraphSlamConfig) -> Lap {
    let mut sim_config = SimulationConfig::with_seed(seed);
    sim_config.building.repeated_rooms = aliased;
    let sim = SimulatedSpot::corridor_loop(&sim_config).unwrap();
    let body_t_lidar = sim.body_t_lidar();
    let truth = sim.ground_truth();
    let mut slam = point_to_plane_slam(config).unwrap();
    if places {
        slam = slam.with_place_recognizer(scan_context_places());
    }
    let mut world_t_lidar: HashMap<u64, Pose3> = HashMap::new();
    for sample in sim {
        world_t_lidar.insert(
            sample.stamp.to_bits(),
            sample.ground_truth.unwrap() * body_t_lidar,
        );
        slam.process(&sample.scan_input());
    }
    let loops = crate::common::loop_edges_against_truth(&slam, &world_t_lidar);
    let (e, _) =
        TrajectoryEvaluation::of_lidar_trajectory(slam.scan_trajectory(), &body_t_lidar, &truth)
            .unwrap();
    Lap {
        ate: e.ate.rmse,
        report: slam.report().clone(),
        loops,
    }
}

/// Look-alike rooms are proposed and pass the geometric check, yet the final graph keeps only
/// loops that the ground truth confirms, and the map is as accurate as without place
/// recognition. The drift gate is what holds: with it off, graduated non-convexity weighs every
/// wrong loop out on building 2 but keeps a run of 7 on building 1, each one room (11.7 m) off
/// and all agreeing with one another, which bend the graph within the odometry's noise (ATE
/// 4.1 m); that run is printed, not asserted.
fn no_wrong_loop_survives(seed: u64) {
    let with = lap(seed, true, true, slam_config());
    let without = lap(seed, true, false, slam_config());
    // The drift gate off: what the geometric check alone lets through.
    let ungated = lap(
        seed,
        true,
        true,
        GraphSlamConfig {
            loop_max_drift_rate: 1e3,
            ..slam_config()
        },
    );
    let wrong = |l: &Lap| l.loops.iter().filter(|(_, e)| *e > 0.3).count();
    let kept_wrong = |l: &Lap| l.loops.iter().filter(|(k, e)| *k && *e > 0.3).count();
    eprintln!(
        "seed {seed}: {} place candidates, {} refused beyond the drift, {} loops closed, {} weighted out, ATE {:.4} m (without place recognition {:.4} m); \
         without the drift gate {} wrong loops in the graph, {} kept, ATE {:.3} m",
        with.report.place_candidates,
        with.report.loop_rejections.get(LoopRejection::BeyondDrift),
        with.report.loops_closed,
        with.report.loops_weighted_out,
        with.ate,
        without.ate,
        wrong(&ungated),
        kept_wrong(&ungated),
        ungated.ate
    );
    assert!(
        wrong(&ungated) >= 1,
        "the repeated rooms fooled no geometric check: no aliasing to defend against"
    );
    assert_eq!(kept_wrong(&with), 0, "{:?}", with.loops);
    assert!(with.report.loop_rejections.get(LoopRejection::BeyondDrift) >= 1);
    assert!(with.ate <= 0.05, "ATE {} m", with.ate);
    assert!(
        with.ate <= without.ate + 0.01,
        "ATE {} m with place recognition, {} m without",
        with.ate,
        without.ate
    );
}

#[test]
fn no_wrong_loop_survives_on_the_aliased_building_1() {
    no_wrong_loop_survives(1);
}

#[test]
fn no_wrong_loop_survives_on_the_aliased_building_2() {
    no_wrong_loop_survives(2);
}
