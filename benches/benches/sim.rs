//! The simulated Spot: one full VLP-16 scan (16 x 1800 = 28,800 rays) and one OS1-128 scan
//! (128 x 1024 = 131,072 rays) against a generated building, the building's generation, and one
//! whole simulated sample (pose, odometry, scan) of Spot's walk and of a handheld OS1-128 walk
//! (motion-distorted, each column from the true pose at its firing time).
//!
//! `cargo bench -p spot-nav-benches --bench sim`

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::{Translation3, UnitQuaternion};
use slam_core::Pose3;
use spot_adapter::sim::{
    Building, BuildingConfig, LidarConfig, Route, SimRng, SimulatedSpot, SimulationConfig,
    SpinningLidar,
};

fn sim(c: &mut Criterion) {
    let mut group = c.benchmark_group("sim");
    let building = Building::generate(1, &BuildingConfig::default()).unwrap_or_else(|e| {
        eprintln!("building generation failed: {e}");
        std::process::exit(1)
    });
    let lidar = SpinningLidar::new(LidarConfig::default()).unwrap_or_else(|e| {
        eprintln!("lidar model failed: {e}");
        std::process::exit(1)
    });
    // Poses spread around the corridor loop, mixing corridor views and long diagonals.
    let route = Route::corridor_loop(&building);
    let poses: Vec<Pose3> = (0..16)
        .map(|k| {
            let p = route.pose_at(route.length() * f64::from(k) / 16.0);
            Pose3::from_parts(
                Translation3::new(p.translation.x, p.translation.y, 0.8),
                UnitQuaternion::from_euler_angles(0.0, 0.0, p.rotation.angle()),
            )
        })
        .collect();
    group.throughput(Throughput::Elements(lidar.directions().len() as u64));
    let mut rng = SimRng::new(0, 0);
    let mut k = 0;
    group.bench_function("vlp16_scan", |b| {
        b.iter(|| {
            k = (k + 1) % poses.len();
            black_box(lidar.scan(&building, &poses[k], &mut rng))
        });
    });
    group.bench_function("vlp16_scan_moving", |b| {
        b.iter(|| {
            k = (k + 1) % poses.len();
            let end = poses[k] * Pose3::translation(0.12, 0.0, 0.0);
            black_box(lidar.scan_moving(&building, &poses[k], &end, &mut rng))
        });
    });
    let os1 = SpinningLidar::new(LidarConfig::os1_128()).unwrap_or_else(|e| {
        eprintln!("lidar model failed: {e}");
        std::process::exit(1)
    });
    group.throughput(Throughput::Elements(os1.directions().len() as u64));
    group.bench_function("os1_128_scan", |b| {
        b.iter(|| {
            k = (k + 1) % poses.len();
            black_box(os1.scan(&building, &poses[k], &mut rng))
        });
    });
    group.throughput(Throughput::Elements(1));
    group.bench_function("building_generate", |b| {
        b.iter(|| black_box(Building::generate(black_box(7), &BuildingConfig::default())));
    });
    group.bench_function("simulated_sample", |b| {
        b.iter_batched(
            || SimulatedSpot::corridor_loop(&SimulationConfig::with_seed(1)),
            |sim| black_box(sim.map(|mut s| s.next())),
            criterion::BatchSize::LargeInput,
        );
    });
    let handheld = SimulationConfig::handheld_os1_128(1);
    group.bench_function("handheld_os1_128_sample", |b| {
        b.iter_batched(
            || SimulatedSpot::corridor_loop(&handheld),
            |sim| black_box(sim.map(|mut s| s.next())),
            criterion::BatchSize::LargeInput,
        );
    });
    group.finish();
}

criterion_group!(benches, sim);
criterion_main!(benches);
