//! Scan Context place recognition on the simulated Spot, scored against the simulator's ground
//! truth: a lap of the corridor loop, then the same lap walked backwards, a keyframe every
//! metre. Every keyframe queries the index of the keyframes at least 30 m of walking older; a
//! candidate is right when its true position is within 3 m of the query's. Precision and
//! recall of the best candidate at the index's default distance threshold, and the heading it
//! gives, are checked; the table for other thresholds is printed.
#![allow(clippy::unwrap_used)]

use nalgebra::Vector2;
use registration::{ScanContextConfig, ScanContextIndexConfig, ScanContextRecognizer};
use slam_core::PlaceRecognizer;
use spot_adapter::sim::{Building, Route, SimulatedSpot, SimulationConfig};

/// Precision and recall of the best candidate per query, and the worst heading error of the
/// right ones (radians).
struct Scores {
    queries_with_revisit: usize,
    returned: usize,
    right: usize,
    found_revisits: usize,
    worst_yaw_error: f64,
    /// (distance, right, query had a revisit) of every best candidate.
    best: Vec<(f64, bool, bool)>,
    any_right: usize,
}

fn score(seed: u64) -> Scores {
    // Walking at 1.2 m/s: half the scans of the default speed between keyframes 1 m apart.
    let mut config = SimulationConfig::with_seed(seed);
    config.speed = 1.2;
    let building = Building::generate(seed, &config.building).unwrap();
    let c = *building.corridor_loop();
    // Forwards round the loop, then backwards: revisits facing the same way and the other way.
    let route = Route::new(
        vec![c[0], c[1], c[2], c[3], c[0], c[3], c[2], c[1], c[0]],
        false,
    )
    .unwrap();
    let sim = SimulatedSpot::new(building, &route, &config).unwrap();
    let mut places = ScanContextRecognizer::new(
        ScanContextConfig::default(),
        ScanContextIndexConfig {
            exclude_recent: 30,
            // Every candidate, to score each threshold.
            max_distance: 1.0,
            ..ScanContextIndexConfig::default()
        },
        ScanContextRecognizer::default_offset(),
    )
    .unwrap();
    let mut keyframes: Vec<(Vector2<f64>, f64)> = Vec::new();
    let mut last: Option<Vector2<f64>> = None;
    let mut scores = Scores {
        queries_with_revisit: 0,
        returned: 0,
        right: 0,
        found_revisits: 0,
        worst_yaw_error: 0.0,
        best: Vec::new(),
        any_right: 0,
    };
    for sample in sim {
        let truth = sample.ground_truth.unwrap() * sample.body_t_lidar;
        let here = truth.translation.vector.xy();
        if last.is_some_and(|p| (here - p).norm() < 1.0) {
            continue;
        }
        last = Some(here);
        let yaw = truth.rotation.euler_angles().2;
        let searchable = keyframes.len().saturating_sub(30);
        let revisit = keyframes[..searchable]
            .iter()
            .any(|(p, _)| (p - here).norm() <= 3.0);
        scores.queries_with_revisit += usize::from(revisit);
        let found = places.candidates(&sample.cloud).unwrap();
        if revisit
            && found
                .iter()
                .any(|f| (keyframes[f.keyframe].0 - here).norm() <= 3.0)
        {
            scores.any_right += 1;
        }
        if let Some(best) = found.first() {
            scores.returned += 1;
            let (p, candidate_yaw) = keyframes[best.keyframe];
            scores
                .best
                .push((best.distance, (p - here).norm() <= 3.0, revisit));
            if (p - here).norm() <= 3.0 {
                scores.right += 1;
                scores.found_revisits += usize::from(revisit);
                let error = (best.yaw - (yaw - candidate_yaw) + std::f64::consts::PI)
                    .rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI;
                scores.worst_yaw_error = scores.worst_yaw_error.max(error.abs());
            }
        }
        places.add_keyframe(keyframes.len(), &sample.cloud).unwrap();
        keyframes.push((here, yaw));
    }
    scores
}

/// The scores of building `seed`, printed with the table of thresholds, checked at the
/// index's default threshold.
fn revisits_are_recognised_both_ways_round_with_their_heading(seed: u64) {
    {
        let s = score(seed);
        eprintln!(
            "seed {seed}: {} queries with a revisit, {} with a right candidate among those returned; worst heading error of a right candidate {:.1} deg",
            s.queries_with_revisit,
            s.any_right,
            s.worst_yaw_error.to_degrees()
        );
        let at = |t: f64| {
            let kept: Vec<_> = s.best.iter().filter(|b| b.0 <= t).collect();
            let right = kept.iter().filter(|b| b.1).count();
            let found = kept.iter().filter(|b| b.1 && b.2).count();
            (
                right as f64 / kept.len().max(1) as f64,
                found as f64 / s.queries_with_revisit.max(1) as f64,
            )
        };
        for t in [0.04, 0.06, 0.08, 0.10, 0.12] {
            let (precision, recall) = at(t);
            eprintln!("  distance <= {t:.2}: precision {precision:.3}, recall {recall:.3}");
        }
        let (precision, recall) = at(ScanContextIndexConfig::default().max_distance);
        assert!(
            s.queries_with_revisit >= 50
                && precision >= 0.85
                && recall >= 0.5
                && s.worst_yaw_error < 0.1,
            "{} revisits, precision {precision}, recall {recall}, heading off by {} rad",
            s.queries_with_revisit,
            s.worst_yaw_error
        );
    }
}

#[test]
fn revisits_are_recognised_on_building_1() {
    revisits_are_recognised_both_ways_round_with_their_heading(1);
}

#[test]
fn revisits_are_recognised_on_building_2() {
    revisits_are_recognised_both_ways_round_with_their_heading(2);
}

#[test]
fn revisits_are_recognised_on_building_3() {
    revisits_are_recognised_both_ways_round_with_their_heading(3);
}
