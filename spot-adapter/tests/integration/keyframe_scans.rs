//! A dense scan's keyframes keep their whole scan for the map one a metre
//! (`GraphSlamConfig::keyframe_scan_spacing` in `slam_config`), the others the points their
//! registration used; the oracle is the same walk with every keyframe keeping its whole scan
//! (the same trajectory to the bit: only what is kept for the map differs).

#![allow(clippy::unwrap_used)]

use std::collections::HashSet;

use nalgebra::Vector3;

use slam_core::io::StampedPose;
use slam_core::{GraphSlamConfig, PointCloud};
use spot_adapter::pipelines::{point_to_plane_slam, slam_config};
use spot_adapter::robot::Sample;
use spot_adapter::sim::{SimulatedSpot, SimulationConfig};

/// What a walk gave: the map at 5 cm, each keyframe's position and how many points it kept,
/// how many kept their whole scan by the engine's count, and every scan's pose.
struct Mapped {
    map: PointCloud,
    kept: Vec<(Vector3<f64>, usize)>,
    whole: usize,
    trajectory: Vec<StampedPose>,
}

/// The walk `samples`, LiDAR-only.
fn mapped(config: GraphSlamConfig, samples: &[Sample]) -> Mapped {
    let mut slam = point_to_plane_slam(config).unwrap();
    for s in samples {
        slam.process(&s.lidar_only_input());
    }
    let kept = slam
        .keyframe_scans()
        .map(|scan| {
            let (pose, cloud) = scan.unwrap();
            (pose.translation.vector, cloud.len())
        })
        .collect();
    Mapped {
        map: slam.map(0.05).unwrap(),
        kept,
        whole: slam.report().whole_scans,
        trajectory: slam.scan_trajectory(),
    }
}

/// The 0.1 m voxels `cloud` has points in.
fn voxels(cloud: &PointCloud) -> HashSet<[i32; 3]> {
    cloud
        .points()
        .iter()
        .map(|p| [p.x, p.y, p.z].map(|v| (v / 0.1).floor() as i32))
        .collect()
}

/// The share of `of`'s voxels that `near` has points in too.
fn covered(of: &HashSet<[i32; 3]>, near: &HashSet<[i32; 3]>) -> f64 {
    of.intersection(near).count() as f64 / of.len() as f64
}

/// The share of `of`'s voxels with one of `near`'s beside them (the 27 around, 0.1 m a side).
fn beside(of: &HashSet<[i32; 3]>, near: &HashSet<[i32; 3]>) -> f64 {
    let offsets =
        (-1..=1).flat_map(|x| (-1..=1).flat_map(move |y| (-1..=1).map(move |z| [x, y, z])));
    let offsets: Vec<[i32; 3]> = offsets.collect();
    let hit = of
        .iter()
        .filter(|v| {
            offsets
                .iter()
                .any(|d| near.contains(&[v[0] + d[0], v[1] + d[1], v[2] + d[2]]))
        })
        .count();
    hit as f64 / of.len() as f64
}

#[test]
fn a_dense_walks_keyframes_keep_their_whole_scan_one_a_metre_and_the_map_stays_whole() {
    // The first 40 scans of the hand-held OS1-128 walk (20 s, about 20 m, one corner).
    let sim_config = SimulationConfig::handheld_os1_128(1);
    let sim = SimulatedSpot::corridor_loop(&sim_config).unwrap();
    let samples: Vec<Sample> = sim.take(40).collect();
    assert!(samples[0].cloud.len() > 100_000);

    let spaced = slam_config();
    assert!((spaced.keyframe_scan_spacing - 1.0).abs() < 1e-12);
    let every = GraphSlamConfig {
        keyframe_scan_spacing: 0.0,
        ..slam_config()
    };
    let spaced = mapped(spaced, &samples);
    let every = mapped(every, &samples);
    // The trajectory is the same to the bit.
    assert_eq!(spaced.trajectory, every.trajectory);
    let Mapped {
        map: spaced_map,
        kept: spaced_kept,
        whole,
        ..
    } = spaced;
    let Mapped {
        map: every_map,
        kept: every_kept,
        whole: every_whole,
        ..
    } = every;
    eprintln!(
        "whole scans {whole} of {} keyframes (every: {every_whole} of {}); map points {} against {}",
        spaced_kept.len(),
        every_kept.len(),
        spaced_map.len(),
        every_map.len()
    );
    // Every keyframe keeps its whole scan (44,000 voxels of 5 cm or so) without the spacing.
    assert_eq!(every_whole, every_kept.len());
    assert!(
        every_kept.iter().all(|&(_, n)| n > 20_000),
        "{every_kept:?}"
    );
    // With it, about one keyframe in two at half a metre a scan, each whole scan as large, the
    // others the 0.25 m voxels their registration used.
    assert!(whole >= 8 && whole * 3 <= spaced_kept.len() * 2, "{whole}");
    let large = spaced_kept.iter().filter(|&&(_, n)| n > 20_000).count();
    let small = spaced_kept
        .iter()
        .filter(|&&(_, n)| (1_000..8_000).contains(&n))
        .count();
    assert_eq!(
        (large, small),
        (whole, spaced_kept.len() - whole),
        "{spaced_kept:?}"
    );
    // The whole scans a metre apart at least, and no keyframe a metre or more past the last.
    let mut last: Option<Vector3<f64>> = None;
    for &(at, n) in &spaced_kept {
        let from_last = last.map_or(f64::INFINITY, |l| (at - l).norm());
        if n > 20_000 {
            assert!(from_last >= 1.0, "a whole scan {from_last} m from the last");
            last = Some(at);
        } else {
            assert!(from_last < 1.0, "no whole scan for {from_last} m");
        }
    }
    // The map (measured): the spaced one has points in 89 % of the 0.1 m voxels of the one made
    // of every whole scan and a point beside every one of them (a voxel away at most), and
    // nothing that one lacks; a map of the registrations' points alone (a spacing longer than
    // the walk: only the first keyframe whole) has points in 53 % of them.
    let (s, e) = (voxels(&spaced_map), voxels(&every_map));
    let (complete, near, sharp) = (covered(&e, &s), beside(&e, &s), beside(&s, &e));
    let sparse = GraphSlamConfig {
        keyframe_scan_spacing: 1e3,
        ..slam_config()
    };
    let thin = covered(&e, &voxels(&mapped(sparse, &samples).map));
    eprintln!(
        "covered {complete:.4}, beside {near:.4}, within {sharp:.4}; registration's points alone {thin:.4}"
    );
    assert!(
        complete >= 0.85 && near >= 0.99 && sharp >= 0.99,
        "{complete} {near} {sharp}"
    );
    assert!(thin < 0.7, "{thin}");
}
