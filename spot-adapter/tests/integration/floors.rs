//! Buildings of several floors: the floors setting, the staircase and the slab as rays see
//! them, and the tour's heights against the steps.

#![allow(clippy::unwrap_used)]

use nalgebra::{Point3, Vector2, Vector3};
use spot_adapter::sim::{
    BoxKind, Building, BuildingConfig, FloorsTour, HitTarget, SLAB_THICKNESS, STAIRS_SPEED,
    SimError,
};

fn two_floors(seed: u64) -> Building {
    let config = BuildingConfig {
        floors: 2,
        ..BuildingConfig::default()
    };
    Building::generate(seed, &config).unwrap()
}

/// The kind of box a ray hit, if it hit one.
fn kind(building: &Building, target: HitTarget) -> Option<BoxKind> {
    match target {
        HitTarget::Box(i) => Some(building.boxes()[i].kind),
        _ => None,
    }
}

#[test]
fn floors_outside_one_to_three_are_refused_by_name() {
    for floors in [0, 4, 100] {
        let config = BuildingConfig {
            floors,
            ..BuildingConfig::default()
        };
        match Building::generate(1, &config) {
            Err(SimError::InvalidConfig(e)) => {
                assert_eq!(e.setting, "floors");
                assert!((e.value - floors as f64).abs() < 1e-12);
            }
            other => panic!("{floors} floors: expected an invalid floors, got {other:?}"),
        }
    }
    // One floor is the default, and the same building as before the setting existed.
    let one = BuildingConfig {
        floors: 1,
        ..BuildingConfig::default()
    };
    assert_eq!(BuildingConfig::default(), one);
    let b = Building::generate(1, &one).unwrap();
    assert_eq!(b.floors(), 1);
    assert!(b.staircases().is_empty());
    assert!((b.top_ceiling() - b.ceiling_height()).abs() < 1e-15);
    // Every seed's layout has rooms for the staircases, and a tour over them.
    for seed in 0..30 {
        let floors = 2 + (seed % 2) as usize;
        let config = BuildingConfig {
            floors,
            ..BuildingConfig::default()
        };
        let b = Building::generate(seed, &config).unwrap();
        assert_eq!(b.floors(), floors);
        assert_eq!(b.staircases().len(), floors - 1);
        FloorsTour::new(&b).unwrap();
    }
}

/// Seed 5's flight has a landing midway (a storey of 17 rises), seed 11's is one run (16).
/// Each floor above the ground has rooms of its own round the same corridor ring and core
/// (where the staircases stand), and its grid (`occupancy_grid_on`) agrees with rays cast down
/// onto it (the oracle: a point whose ray stops above the floor or falls through it is in a
/// blocked cell; a cell whose 3 x 3 rays 0.1 m apart all land on the floor is free). With
/// `repeat_floor_plan` every floor has the ground floor's rooms.
#[test]
fn each_floor_has_rooms_of_its_own_round_the_same_core() {
    use spot_adapter::sim::SimRng;
    for (seed, floors) in [(5, 2), (11, 3)] {
        let config = BuildingConfig {
            floors,
            ..BuildingConfig::default()
        };
        let b = Building::generate(seed, &config).unwrap();
        let ring = b.corridor_loop();
        let in_core = |r: &spot_adapter::sim::Room| {
            r.min.x > ring[0].x && r.max.x < ring[2].x && r.min.y > ring[0].y && r.max.y < ring[2].y
        };
        let ground = b.grid_on(0);
        for k in 1..floors {
            let (here, below) = (b.rooms_on(k), b.rooms_on(0));
            let core = |rooms: &[spot_adapter::sim::Room]| -> Vec<_> {
                rooms.iter().filter(|r| in_core(r)).copied().collect()
            };
            assert_eq!(core(here), core(below), "seed {seed} floor {k}");
            let outer: Vec<_> = here.iter().filter(|r| !in_core(r)).collect();
            assert!(
                outer.iter().any(|r| !below.contains(r)),
                "seed {seed} floor {k}: the same rooms as the ground floor"
            );
            for f in b.staircases() {
                assert!(here.contains(&f.room), "seed {seed} floor {k}");
            }
            for r in here {
                assert!(b.clearance_on(k, r.entry_point(), None) > 0.4, "{r:?}");
            }
            let grid = b.grid_on(k);
            let differ = (0..grid.height())
                .flat_map(|y| (0..grid.width()).map(move |x| slam_core::Cell::new(x, y)))
                .filter(|&c| grid.is_blocked(c) != ground.is_blocked(c))
                .count();
            let share = differ as f64 / f64::from(grid.width() * grid.height());
            assert!(share > 0.02, "seed {seed} floor {k}: {share}");
        }
        assert!(b.rooms_on(floors).is_empty());
        // The grid of each floor against rays down onto it.
        let mut rng = SimRng::new(seed, 7);
        for k in 0..floors {
            let z = b.floor_height(k);
            let grid = b.occupancy_grid_on(k, 0.1).unwrap();
            let lands = |p: Vector2<f64>| {
                let origin = Point3::new(p.x, p.y, z + 0.99);
                let hit = b.cast_ray(&origin, &-Vector3::z(), 10.0).unwrap();
                origin.z - hit.range
            };
            let (mut blocked, mut free) = (0, 0);
            for _ in 0..20_000 {
                let p = Vector2::new(
                    rng.range(0.3, b.size().x - 0.3),
                    rng.range(0.3, b.size().y - 0.3),
                );
                let cell = grid.cell_at(p).unwrap();
                if (lands(p) - z).abs() > 0.01 {
                    assert!(grid.is_blocked(cell), "seed {seed} floor {k}: {p:?}");
                    blocked += 1;
                } else if (-1..=1).all(|i| {
                    (-1..=1).all(|j| {
                        let q = p + Vector2::new(f64::from(i), f64::from(j)) * 0.1;
                        (lands(q) - z).abs() <= 0.01
                    })
                }) {
                    assert!(!grid.is_blocked(cell), "seed {seed} floor {k}: {p:?}");
                    free += 1;
                }
            }
            assert!(blocked > 1000 && free > 5000, "{blocked} {free}");
        }
        // Every floor a copy of the ground floor's rooms, when asked.
        let repeated = Building::generate(
            seed,
            &BuildingConfig {
                repeat_floor_plan: true,
                ..config
            },
        )
        .unwrap();
        for k in 1..floors {
            assert_eq!(repeated.rooms_on(k), repeated.rooms_on(0));
        }
        assert_eq!(repeated.rooms_on(0), b.rooms_on(0));
    }
}

#[test]
fn rays_see_each_step_the_slab_and_through_the_stairwell() {
    for (seed, landing) in [(5, true), (11, false)] {
        rays_see_the_flight_of(seed, landing);
    }
}

fn rays_see_the_flight_of(seed: u64, landing: bool) {
    use spot_adapter::sim::MAX_RISES_WITHOUT_LANDING;
    let b = two_floors(seed);
    let storey = b.floor_height(1);
    assert!((storey - b.ceiling_height() - SLAB_THICKNESS).abs() < 1e-12);
    let flight = b.staircases()[0];
    // The oracle: step k's top at k rises, the rises dividing the storey evenly; treads 0.28 m
    // deep, but for a landing halfway up a storey of more than 16 rises (1.2 m deep).
    let rises = flight.steps + 1;
    let rise = storey / rises as f64;
    assert!((0.15..=0.21).contains(&rise), "rise {rise}");
    assert_eq!(flight.landing.is_some(), landing, "seed {seed}");
    assert_eq!(landing, rises > MAX_RISES_WITHOUT_LANDING, "seed {seed}");
    let landing_step = landing.then_some(rises / 2);
    let depth = |k: usize| if Some(k) == landing_step { 1.2 } else { 0.28 };
    let down = -Vector3::z();
    let mut front = 0.0;
    for k in 1..=flight.steps {
        let p = flight.foot + flight.up * (front + 0.5 * depth(k));
        for at in [p, flight.foot + flight.up * (front + 0.05)] {
            let origin = Point3::new(at.x, at.y, k as f64 * rise + 0.3);
            let hit = b.cast_ray(&origin, &down, 10.0).unwrap();
            assert_eq!(
                kind(&b, hit.target),
                Some(BoxKind::Step),
                "seed {seed} step {k}"
            );
            assert!(
                (origin.z - hit.range - k as f64 * rise).abs() < 1e-9,
                "seed {seed} step {k}"
            );
        }
        front += depth(k);
    }
    assert!((flight.run() - front).abs() < 1e-9, "seed {seed}");
    // Up from the middle of the flight: through the stairwell to the upper floor's ceiling.
    let mid = flight.foot + flight.up * (0.5 * flight.run());
    let origin = Point3::new(mid.x, mid.y, 0.5 * storey + 0.5);
    let hit = b.cast_ray(&origin, &Vector3::z(), 20.0).unwrap();
    assert_eq!(hit.target, HitTarget::Ceiling);
    assert!((hit.range - (storey + b.ceiling_height() - origin.z)).abs() < 1e-9);
    // Up from the corridor: the slab's underside; down on the floor above: its top.
    let corridor = b.corridor_loop()[0];
    let origin = Point3::new(corridor.x, corridor.y, 1.0);
    let hit = b.cast_ray(&origin, &Vector3::z(), 20.0).unwrap();
    assert_eq!(kind(&b, hit.target), Some(BoxKind::Slab));
    assert!((hit.range - (b.ceiling_height() - 1.0)).abs() < 1e-9);
    let origin = Point3::new(corridor.x, corridor.y, storey + 0.7);
    let hit = b.cast_ray(&origin, &down, 20.0).unwrap();
    assert_eq!(kind(&b, hit.target), Some(BoxKind::Slab));
    assert!((hit.range - 0.7).abs() < 1e-9);
    // The ground floor's plan counts the staircase as an obstacle, the upper floor not.
    assert!(b.is_obstacle(mid));
    assert!(!b.is_obstacle(corridor));
}

#[test]
fn the_tour_climbs_every_floor_on_the_steps_and_comes_back_down() {
    for (seed, floors) in [(5, 2), (11, 3)] {
        let config = BuildingConfig {
            floors,
            ..BuildingConfig::default()
        };
        let b = Building::generate(seed, &config).unwrap();
        let tour = FloorsTour::new(&b).unwrap();
        let body = 0.5;
        let (poses, stairs) = tour.walk(0.6, 5.0, body).unwrap();
        let rise = b.staircases()[0].rise;
        let mut top = f64::NEG_INFINITY;
        for (k, p) in poses.iter().enumerate() {
            let t = p.pose.translation.vector;
            // The oracle: the surface straight below the body, as a ray finds it.
            let hit = b.cast_ray(&Point3::from(t), &-Vector3::z(), 20.0).unwrap();
            let ground = t.z - hit.range;
            assert!(
                (t.z - body - ground).abs() <= 0.5 * rise + 1e-9,
                "seed {seed}, sample {k}: body at {:.3} m over ground at {ground:.3} m",
                t.z
            );
            top = top.max(t.z - body);
            if stairs[k] && stairs.get(k + 1) == Some(&true) {
                // Along the slope at the stairs speed: in plan view between its cosine on the
                // steepest part (a rise over a tread) and all of it on a landing; the height
                // takes the steps' jolts, so the plan view is what is steady.
                let next = poses[k + 1].pose.translation.vector;
                let speed = (next - t).xy().norm() * 5.0;
                let steepest = STAIRS_SPEED * rise.atan2(0.28).cos();
                assert!(
                    speed > steepest - 0.02 && speed < STAIRS_SPEED + 0.02,
                    "plan-view speed {speed}"
                );
            }
        }
        assert!((top - b.floor_height(floors - 1)).abs() < 1e-9, "top {top}");
        let (first, last) = (poses[0].pose, poses[poses.len() - 1].pose);
        assert!((first.translation.vector - last.translation.vector).norm() < 1e-9);
        // Two passes over each flight; the lap of every floor makes the tour long.
        let climbs = stairs.windows(2).filter(|w| !w[0] && w[1]).count();
        assert_eq!(climbs, 2 * (floors - 1));
        assert!(tour.route().length() > 100.0 * floors as f64);
        // A quarter of the way up (on the steps below any landing) the body pitches with the
        // flight, nose up (a negative pitch) going up, nodding by 1.5 degrees at most.
        let flight = b.staircases()[0];
        let slope = (flight.rise / flight.tread).atan();
        let mid = poses
            .iter()
            .zip(&stairs)
            .find(|(p, on)| {
                **on && (p.pose.translation.z - body - 0.25 * flight.climb()).abs() < 0.1
            })
            .unwrap()
            .0;
        let (_, pitch, _) = mid.pose.rotation.euler_angles();
        assert!((pitch + slope).abs() < 0.05, "pitch {pitch}, slope {slope}");
    }
}

/// Graph-SLAM (point-to-plane, the robot's odometry, Scan Context as the `slam` example runs
/// it) over seed 10's tour of two floors (370 m; a flight with a landing, taken with the steps'
/// jolts; each floor with its own rooms round the same core), against the truth, at the issue's
/// bar: relative drift at most 0.3 %, end error 3 cm, ATE and end height within 5 cm, and
/// every pose on the upper floor within 5 cm of its true height (the estimate moved so that its
/// first pose is the truth's). Measured: ATE 1.0 cm, end 0.15 cm, 0.05 %. About 25 s in
/// release.
#[test]
fn two_floors_are_mapped_through_the_stairs_with_place_recognition() {
    two_floors_mapped(10, false);
}

/// The same over seed 2's floors of one repeated plan, the hard case: place recognition
/// matches the two floors' rooms, and the height gate
/// (`GraphSlamConfig::loop_max_height_drift_rate`) must refuse those loops (checked to fail
/// with the gate off: ATE 1.5 m, 5.2 m low at the end). Also checked to fail without the
/// odometry edges' tilt information (`GraphSlamConfig::gravity_tilt_sigma` at 1000 rad: more
/// than 5 cm low at the upper floor's far end, the optimiser having tilted the floor). About
/// 25 s in release: `cargo test --release -p spot-nav-adapter --test integration --
/// --ignored two_floors_of_one_plan`.
#[test]
#[ignore = "about 25 s: maps a 408 m tour over two floors of one plan"]
fn two_floors_of_one_plan_are_mapped_through_the_stairs_with_place_recognition() {
    two_floors_mapped(2, true);
}

/// Maps seed `seed`'s tour of two floors (of one plan with `repeat_floor_plan`) and checks it.
fn two_floors_mapped(seed: u64, repeat_floor_plan: bool) {
    use slam_core::LoopRejection;
    use spot_adapter::eval::TrajectoryEvaluation;
    use spot_adapter::pipelines::{point_to_plane_slam, scan_context_places, slam_config};
    use spot_adapter::sim::{SimulatedSpot, SimulationConfig};

    let mut config = SimulationConfig::with_seed(seed);
    config.building.floors = 2;
    config.building.repeat_floor_plan = repeat_floor_plan;
    let sim = SimulatedSpot::floors_tour(&config).unwrap();
    let body_t_lidar = sim.body_t_lidar();
    let truth = sim.ground_truth();
    let storey = sim.building().floor_height(1) - sim.building().floor_height(0);
    let mut slam = point_to_plane_slam(slam_config())
        .unwrap()
        .with_place_recognizer(scan_context_places());
    for sample in sim {
        slam.process(&sample.scan_input());
    }
    let (e, _) =
        TrajectoryEvaluation::of_lidar_trajectory(slam.scan_trajectory(), &body_t_lidar, &truth)
            .unwrap();
    assert!(e.end_point.path_length > 350.0);
    eprintln!(
        "two floors: {:.1} m, ATE {:.4} m, end {:.4} m, segments {:.4} %, height {:.4} m",
        e.end_point.path_length,
        e.ate.rmse,
        e.loop_end_point_error,
        100.0 * e.segments.as_ref().unwrap().translation,
        e.height_drift
    );
    assert!(e.ate.rmse <= 0.05, "ATE {} m", e.ate.rmse);
    assert!(
        e.loop_end_point_error <= 0.03,
        "end error {} m",
        e.loop_end_point_error
    );
    let drift = e.segments.as_ref().unwrap().translation;
    assert!(drift <= 0.003, "relative drift {} %", 100.0 * drift);
    assert!(
        e.height_drift.abs() <= 0.05,
        "height drift {} m",
        e.height_drift
    );
    let report = slam.report();
    assert!(report.place_candidates > 0);
    if repeat_floor_plan {
        assert!(report.loop_rejections.get(LoopRejection::BeyondHeightDrift) > 0);
    }
    // The upper floor's heights, pose by pose (the simulator's samples carry its truth's stamps).
    let estimate = slam.scan_trajectory();
    let at = |stamp: f64| truth.iter().find(|t| (t.stamp - stamp).abs() < 1e-6);
    let (e0, t0) = (&estimate[0], at(estimate[0].stamp).unwrap());
    let align = t0.pose * (e0.pose * body_t_lidar.inverse()).inverse();
    let z0 = t0.pose.translation.z;
    let mut upper = 0;
    for e in &estimate {
        let Some(t) = at(e.stamp) else { continue };
        if (t.pose.translation.z - z0 - storey).abs() > 0.05 {
            continue;
        }
        upper += 1;
        let z = (align * e.pose * body_t_lidar.inverse()).translation.z;
        let error = z - t.pose.translation.z;
        assert!(error.abs() <= 0.05, "{:.1} s: {error:+.3} m", e.stamp);
    }
    assert!(upper > 1000, "{upper} poses on the upper floor");
}

/// The tour's body poses split by height (`gridmap::FloorLevels`) give one floor per storey at
/// the building's floor heights plus the body's height, every pose standing on a floor on that
/// floor (the oracle: the building's own floor heights, and the tour's flags for the poses on
/// the stairs), and the changes of floor the tour makes, up and back down.
#[test]
fn the_tour_splits_into_its_floors_by_height() {
    use gridmap::{FloorLevels, FloorLevelsConfig};
    for (seed, floors) in [(5, 2), (11, 3)] {
        let config = BuildingConfig {
            floors,
            ..BuildingConfig::default()
        };
        let b = Building::generate(seed, &config).unwrap();
        let body = 0.5;
        let (poses, stairs) = FloorsTour::new(&b).unwrap().walk(0.6, 5.0, body).unwrap();
        let positions: Vec<Point3<f64>> = poses
            .iter()
            .map(|p| Point3::from(p.pose.translation.vector))
            .collect();
        let split = FloorLevels::split(&positions, &FloorLevelsConfig::default()).unwrap();
        assert_eq!(split.levels().len(), floors, "seed {seed}");
        for (k, level) in split.levels().iter().enumerate() {
            let truth = b.floor_height(k) + body;
            assert!((level.height - truth).abs() < 0.02, "floor {k}: {level:?}");
        }
        for (i, p) in positions.iter().enumerate() {
            if !stairs[i] {
                let k = (0..floors)
                    .find(|&k| (p.z - body - b.floor_height(k)).abs() < 0.05)
                    .unwrap();
                assert_eq!(split.floor_of(i), Some(k), "seed {seed}, pose {i}");
            }
        }
        let changes: Vec<(usize, usize)> = split.changes().iter().map(|c| (c.from, c.to)).collect();
        let mut expected: Vec<(usize, usize)> = (1..floors).map(|k| (k - 1, k)).collect();
        expected.extend((1..floors).rev().map(|k| (k, k - 1)));
        assert_eq!(changes, expected, "seed {seed}");
    }
}

/// The stairs links a tour's walk gives, on each floor's true planning grid (the floor plan
/// inflated by the navigator's 0.3 m): one link per flight although the tour climbs and comes
/// back down each, its foot on the lower floor and its top on the upper one (the oracle: the
/// building's staircases). Each end is the walk's last cell a cell clear of the inflation round
/// the steps (upstairs: round the stairwell): 0.35-0.6 m from them in plan, in front of the
/// flight's end (0.3 m or more beyond it along the flight), within 1.1 m of its foot or top. The
/// link's length is the flight's and the walk to its ends: longer than the flight by the ends'
/// 0.35 m each, shorter than the flight plus 1.5 times the straight lines to the ends. A route
/// over the floors from the start to the top floor goes up every flight.
#[test]
fn the_tours_stairs_become_links_between_the_floors_grids() {
    use spot_adapter::nav::{FloorCell, FloorGraph, RouteLeg, stairs_links};
    for (seed, floors) in [(5, 2), (11, 3)] {
        let (b, positions, split, floor_grids) = tour_on_true_grids(seed, floors);
        let grids: Vec<_> = floor_grids.iter().collect();
        let grid = &floor_grids[0];
        let links = stairs_links(&positions, &split, &grids).unwrap();
        assert_eq!(links.len(), floors - 1, "seed {seed}: {links:?}");
        for (k, stairs) in b.staircases().iter().enumerate() {
            let link = links
                .iter()
                .find(|l| l.foot.floor == k)
                .unwrap_or_else(|| panic!("seed {seed}: no link from floor {k}: {links:?}"));
            assert_eq!(link.top.floor, k + 1);
            let (lower, upper) = (grids[k], grids[k + 1]);
            let foot = lower.cell_center(link.foot.cell);
            let top = upper.cell_center(link.top.cell);
            assert!(!lower.is_blocked(link.foot.cell) && !upper.is_blocked(link.top.cell));
            let steps = stairs.step_boxes();
            let off_steps = steps
                .iter()
                .map(|s| rect_distance(foot, s.min.xy().coords, s.max.xy().coords))
                .fold(f64::INFINITY, f64::min);
            let (well_min, well_max) = stairs.stairwell();
            let off_well = rect_distance(top, well_min, well_max);
            let in_front_of_foot = (foot - stairs.foot).dot(&-stairs.up);
            let in_front_of_top = (top - stairs.top()).dot(&stairs.up);
            let (to_foot, to_top) = ((foot - stairs.foot).norm(), (top - stairs.top()).norm());
            let ends = format!(
                "seed {seed} floor {k}: foot {foot} ({off_steps:.3} m off the steps, \
                 {in_front_of_foot:.3} in front, {to_foot:.3} away), top {top} ({off_well:.3} m \
                 off the stairwell, {in_front_of_top:.3} in front, {to_top:.3} away)"
            );
            assert!((0.35..=0.6).contains(&off_steps), "{ends}");
            assert!((0.35..=0.6).contains(&off_well), "{ends}");
            assert!(in_front_of_foot >= 0.3 && in_front_of_top >= 0.3, "{ends}");
            assert!(to_foot < 1.1 && to_top < 1.1, "{ends}");
            let flight = stairs.run().hypot(stairs.climb());
            assert!(
                link.length > flight + 0.7 && link.length < flight + 1.5 * (to_foot + to_top),
                "{ends}: {} m against a {flight} m flight",
                link.length
            );
        }
        // From the start to where the tour stood on the top floor.
        let start = grid
            .cell_at(Vector2::new(positions[0].x, positions[0].y))
            .unwrap();
        let up = (0..positions.len())
            .find(|&i| split.floor_of(i) == Some(floors - 1))
            .unwrap();
        let top_grid = grids[floors - 1];
        let on_top = (up..positions.len())
            .filter(|&i| split.floor_of(i) == Some(floors - 1))
            .filter_map(|i| top_grid.cell_at(Vector2::new(positions[i].x, positions[i].y)))
            .find(|&c| !top_grid.is_blocked(c))
            .unwrap();
        let graph = FloorGraph::new(grids.clone(), links.clone()).unwrap();
        let route = graph
            .route(
                FloorCell {
                    floor: 0,
                    cell: start,
                },
                FloorCell {
                    floor: floors - 1,
                    cell: on_top,
                },
            )
            .unwrap()
            .unwrap();
        let ups = route
            .legs
            .iter()
            .filter(|l| matches!(l, RouteLeg::Stairs { up: true, .. }))
            .count();
        assert_eq!(ups, floors - 1, "seed {seed}: {route:?}");
    }
}

/// Fewer grids than floors, fewer positions than the walk split, and a position on a flight
/// that is not finite are refused by name.
#[test]
fn stairs_from_a_walk_that_does_not_fit_are_refused() {
    use spot_adapter::nav::{NavError, stairs_links};
    let (_, positions, split, floor_grids) = tour_on_true_grids(5, 2);
    let grids: Vec<_> = floor_grids.iter().collect();
    assert!(matches!(
        stairs_links(&positions, &split, &grids[..1]),
        Err(NavError::NoSuchFloor { .. })
    ));
    let named = |r: &Result<_, NavError>| matches!(r, Err(NavError::InvalidConfig(e)) if e.setting == "stairs_links positions");
    let short = stairs_links(&positions[..positions.len() / 2], &split, &grids);
    assert!(named(&short), "{short:?}");
    let change = split.changes()[0];
    let mut broken = positions.clone();
    broken[usize::midpoint(change.left_at, change.arrived_at)] = Point3::new(f64::NAN, 0.0, 1.0);
    let bad = stairs_links(&broken, &split, &grids);
    assert!(named(&bad), "{bad:?}");
}

/// The floors tour of building `seed` with `floors` floors: the building, the tour's body
/// positions, their split into floors, and each floor's true planning grid (the plan: the
/// ground floor's obstacles, the first flight's steps among them; plus the flight rising from
/// that floor and the stairwell of the one arriving; inflated by 0.3 m).
/// Plan-view distance from `p` to the rectangle `min`..`max` (0 inside).
trait GridOn {
    /// Floor `k`'s true grid at 0.1 m.
    fn grid_on(&self, k: usize) -> slam_core::BitGrid;
}

impl GridOn for Building {
    fn grid_on(&self, k: usize) -> slam_core::BitGrid {
        self.occupancy_grid_on(k, 0.1).unwrap()
    }
}

fn rect_distance(p: Vector2<f64>, min: Vector2<f64>, max: Vector2<f64>) -> f64 {
    let dx = (min.x - p.x).max(p.x - max.x).max(0.0);
    let dy = (min.y - p.y).max(p.y - max.y).max(0.0);
    dx.hypot(dy)
}

fn tour_on_true_grids(
    seed: u64,
    floors: usize,
) -> (
    Building,
    Vec<Point3<f64>>,
    gridmap::FloorLevels,
    Vec<slam_core::BitGrid>,
) {
    use gridmap::{FloorLevels, FloorLevelsConfig, inflate};
    let config = BuildingConfig {
        floors,
        ..BuildingConfig::default()
    };
    let b = Building::generate(seed, &config).unwrap();
    let (poses, _) = FloorsTour::new(&b).unwrap().walk(0.6, 5.0, 0.5).unwrap();
    let positions: Vec<Point3<f64>> = poses
        .iter()
        .map(|p| Point3::from(p.pose.translation.vector))
        .collect();
    let split = FloorLevels::split(&positions, &FloorLevelsConfig::default()).unwrap();
    let grids = (0..floors)
        .map(|k| {
            let plan = b.occupancy_grid_on(k, 0.1).unwrap();
            inflate(&plan, 0.3).unwrap()
        })
        .collect();
    (b, positions, split, grids)
}

/// The flights of a tour, found from scans along it (at the true poses, so that the test is of
/// the stairs' marking, not of SLAM) and marked on the grids of both floors each joins: against
/// the building's staircases (the oracle), every cell whose centre lies on a flight at least a
/// cell in from its edges is stairs on both grids (neither a wall nor floor), no stairs cell
/// lies more than 0.2 m off a flight on the floor it rises from (0.35 m on the floor it
/// reaches, where its stairwell with the edge is marked), and the floors' planning grids block the flights while
/// the links between them still join the floors near each flight's foot and top.
#[test]
fn the_flights_are_stairs_on_the_grids_of_both_floors_they_join() {
    use gridmap::CellState;
    for (seed, floors) in [(5, 2), (11, 3)] {
        let TourWalk {
            building: b,
            lidar_poses,
            positions,
            split,
        } = tour_walk(seed, floors);
        let scans = scans_along(&b, &lidar_poses, seed, 0.5, Some(10.0));
        let maps = floor_maps(&scans, &positions, &split);
        assert_eq!(maps.flights().len(), floors - 1, "seed {seed}");
        assert_eq!(maps.links().len(), floors - 1, "seed {seed}");
        for (s, flight) in b.staircases().iter().enumerate() {
            let outside = |c: Vector2<f64>| outside_flight(flight, c);
            for k in [s, s + 1] {
                let grid = maps.map(k).unwrap().unwrap().occupancy();
                let planning = maps.planning(k).unwrap();
                let (mut inner, mut marked) = (0, 0);
                for y in 0..grid.height() {
                    for x in 0..grid.width() {
                        let cell = slam_core::Cell::new(x, y);
                        let centre = grid.geometry().cell_center(cell);
                        let off = outside(centre);
                        let stairs = grid.state(cell) == CellState::Stairs;
                        if off <= -0.1 {
                            inner += 1;
                            marked += usize::from(stairs);
                            assert!(planning.is_blocked(cell));
                        }
                        // Another flight's cells are that flight's.
                        let other = b
                            .staircases()
                            .iter()
                            .enumerate()
                            .any(|(o, f)| o != s && outside_flight(f, centre) <= 0.35);
                        // Upstairs the stairwell, 0.1 m wider than the flight, is marked with
                        // its edge.
                        let bound = if k == s { 0.2 } else { 0.35 };
                        if stairs && !other {
                            assert!(
                                off <= bound,
                                "seed {seed} flight {s} floor {k}: stairs {off:.2} m off the flight at {centre}"
                            );
                        }
                    }
                }
                assert!(inner > 300, "seed {seed}: {inner} cells on flight {s}");
                assert_eq!(
                    marked, inner,
                    "seed {seed} flight {s} floor {k}: {marked} of {inner} cells on the flight marked"
                );
            }
            let link = maps.links().iter().find(|l| l.foot.floor == s).unwrap();
            assert_eq!(link.top.floor, s + 1);
            let foot = maps.planning(s).unwrap().cell_center(link.foot.cell);
            let top = maps.planning(s + 1).unwrap().cell_center(link.top.cell);
            // The walk's last and first cells free of the flight's inflation and of the unseen
            // (these scans are a few, 0.5 m apart).
            assert!(
                (foot - flight.foot).norm() < 2.0,
                "seed {seed}: foot {foot}"
            );
            assert!((top - flight.top()).norm() < 2.0, "seed {seed}: top {top}");
        }
    }
}

/// Plan-view distance of `c` outside `flight`'s rectangle, from its foot to its top and its
/// width across (metres, negative inside).
fn outside_flight(flight: &spot_adapter::sim::Staircase, c: Vector2<f64>) -> f64 {
    let across = Vector2::new(-flight.up.y, flight.up.x);
    let d = c - flight.foot;
    let along = d.dot(&flight.up);
    let side = d.dot(&across).abs();
    (-along)
        .max(along - flight.run())
        .max(side - 0.5 * flight.width)
}

/// A floors tour of building `seed` with `floors` floors: the building, the tour's true
/// LiDAR poses (`world_T_lidar`, 5 Hz at 0.6 m/s), their positions and their split into floors.
pub(crate) struct TourWalk {
    pub building: Building,
    pub lidar_poses: Vec<slam_core::Pose3>,
    pub positions: Vec<Point3<f64>>,
    pub split: gridmap::FloorLevels,
}

/// [`TourWalk`] of building `seed` with `floors` floors.
pub(crate) fn tour_walk(seed: u64, floors: usize) -> TourWalk {
    use gridmap::{FloorLevels, FloorLevelsConfig};
    let config = BuildingConfig {
        floors,
        ..BuildingConfig::default()
    };
    let building = Building::generate(seed, &config).unwrap();
    let geometry = spot_adapter::robot::SpotGeometry::default();
    let (poses, _) = FloorsTour::new(&building)
        .unwrap()
        .walk(0.6, 5.0, geometry.body_height)
        .unwrap();
    let lidar_poses: Vec<slam_core::Pose3> = poses
        .iter()
        .map(|p| p.pose * geometry.body_t_lidar)
        .collect();
    let positions: Vec<Point3<f64>> = lidar_poses
        .iter()
        .map(|p| Point3::from(p.translation.vector))
        .collect();
    let split = FloorLevels::split(&positions, &FloorLevelsConfig::default()).unwrap();
    TourWalk {
        building,
        lidar_poses,
        positions,
        split,
    }
}

/// Scans of `b` from `lidar_poses` (true, `world_T_lidar`), one every `spacing` metres of the
/// walk (within `near_stairs` metres of a flight's foot when given).
/// The maps per floor (default settings, 0.3 m inflation) of `scans` (`map_T_lidar`, cloud)
/// along the walk through `positions`, split into floors as `split`.
pub(crate) fn floor_maps(
    scans: &[(slam_core::Pose3, slam_core::PointCloud)],
    positions: &[Point3<f64>],
    split: &gridmap::FloorLevels,
) -> spot_adapter::nav::FloorMaps {
    use spot_adapter::nav::{FloorMaps, NavigationMapConfig};
    use spot_adapter::robot::SpotGeometry;
    let geometry = SpotGeometry::default();
    let keyframes: Vec<_> = scans.iter().map(|(p, c)| (*p, c)).collect();
    let lidar_height = geometry.body_height + geometry.body_t_lidar.translation.z;
    FloorMaps::build(
        &keyframes,
        positions,
        split,
        lidar_height,
        &NavigationMapConfig::default(),
        0.3,
    )
    .unwrap()
}

pub(crate) fn scans_along(
    b: &Building,
    lidar_poses: &[slam_core::Pose3],
    seed: u64,
    spacing: f64,
    near_stairs: Option<f64>,
) -> Vec<(slam_core::Pose3, slam_core::PointCloud)> {
    use spot_adapter::sim::{LidarConfig, SimRng, SpinningLidar};
    let lidar = SpinningLidar::new(LidarConfig::vlp16()).unwrap();
    let mut rng = SimRng::new(seed, 7);
    let near = |p: &Point3<f64>| {
        near_stairs.is_none_or(|reach| {
            b.staircases()
                .iter()
                .any(|s| (p.xy().coords - s.foot).norm() < reach)
        })
    };
    let mut last: Option<Point3<f64>> = None;
    let mut scans = Vec::new();
    for pose in lidar_poses {
        let p = Point3::from(pose.translation.vector);
        if near(&p) && last.is_none_or(|q| (p - q).norm() >= spacing) {
            scans.push((*pose, lidar.scan(b, pose, &mut rng)));
            last = Some(p);
        }
    }
    scans
}
