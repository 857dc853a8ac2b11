//! The live layer over the mapped simulated building (seed 3, 0.10 m cells): one VLP-16 scan
//! (16 x 1800 rays) fused into an 8 m x 8 m window over the static map, then the planning
//! layer refreshed over the changed rectangle; beside them what the map costs once (floor,
//! obstacle band with beams, planning layer) and a full planning-layer rebuild, the work the
//! refresh avoids. Single thread; setup outside the timed loops.
//!
//! `cargo bench -p spot-nav-benches --bench live_layer`

// Bench setup that fails has no figures to report: stop loudly.
#![allow(clippy::panic)]

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use gridmap::{
    FloorConfig, FloorMap, LiveLayer, LiveLayerConfig, ObstacleBandConfig, OccupancyGridBuilder,
    OccupancyGridConfig, PlanningGrid, PlanningGridConfig, floor_hints_below,
};
use slam_core::{PointCloud, Pose3};
use spot_nav_benches::mapped_building;

fn live_layer(c: &mut Criterion) {
    let mapped = mapped_building::map(3, 4).unwrap_or_else(|e| panic!("{e}"));
    let scans = &mapped.scans;
    let points = scans.iter().map(|(_, s)| s.len()).sum::<usize>() / scans.len();
    let (w, h) = (mapped.occupancy.width(), mapped.occupancy.height());
    eprintln!(
        "live_layer: {} scans of {points} points on average, map {w} x {h} cells",
        scans.len()
    );
    let mut layer = LiveLayer::new(mapped.occupancy.clone(), LiveLayerConfig::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let mut planning = PlanningGrid::new(&mapped.occupancy, PlanningGridConfig::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let mut group = c.benchmark_group("live_layer");
    group.sample_size(30);
    group.throughput(Throughput::Elements(points as u64));
    // Scans in turn, 0.2 s apart (5 Hz), so the decay queue works as in a walk.
    let (mut k, mut stamp) = (0usize, 0.0f64);
    group.bench_function(BenchmarkId::new("update", "8m_window"), |b| {
        b.iter(|| {
            k = (k + 1) % scans.len();
            stamp += 0.2;
            let (pose, scan) = &scans[k];
            black_box(layer.update(scan, pose, &mapped.floor, stamp))
        });
    });
    group.bench_function(
        BenchmarkId::new("update_and_refresh_planning", "8m_window"),
        |b| {
            b.iter(|| {
                k = (k + 1) % scans.len();
                stamp += 0.2;
                let (pose, scan) = &scans[k];
                let r = layer
                    .update(scan, pose, &mapped.floor, stamp)
                    .unwrap_or_else(|e| panic!("{e}"));
                for changed in [r.observed, r.reverted].into_iter().flatten() {
                    planning
                        .refresh(layer.combined(), changed)
                        .unwrap_or_else(|e| panic!("{e}"));
                }
                black_box(r)
            });
        },
    );
    group.throughput(Throughput::Elements(u64::from(w) * u64::from(h)));
    group.bench_function(
        BenchmarkId::new("planning_grid_rebuild", format!("{w}x{h}")),
        |b| {
            b.iter(|| {
                PlanningGrid::new(layer.combined(), PlanningGridConfig::default())
                    .unwrap_or_else(|e| panic!("{e}"))
            });
        },
    );
    group.sample_size(10);
    let refs: Vec<(Pose3, &PointCloud)> = scans.iter().map(|(p, c)| (*p, c)).collect();
    let poses: Vec<Pose3> = scans.iter().map(|(p, _)| *p).collect();
    let hints = floor_hints_below(&poses, 0.80);
    let builder =
        OccupancyGridBuilder::new(OccupancyGridConfig::default()).unwrap_or_else(|e| panic!("{e}"));
    group.throughput(Throughput::Elements((points * scans.len()) as u64));
    group.bench_function(
        BenchmarkId::new("map_floor_band_planning", format!("{}_scans", scans.len())),
        |b| {
            b.iter(|| {
                let floor = FloorMap::estimate_from_scans(&refs, &hints, &FloorConfig::default())
                    .unwrap_or_else(|e| panic!("{e}"));
                let grid = builder
                    .build_floor_band_from_scans(&refs, &floor, &ObstacleBandConfig::default())
                    .unwrap_or_else(|e| panic!("{e}"));
                PlanningGrid::new(&grid, PlanningGridConfig::default())
                    .unwrap_or_else(|e| panic!("{e}"))
            });
        },
    );
    group.finish();
}

criterion_group!(benches, live_layer);
criterion_main!(benches);
