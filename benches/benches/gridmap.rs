//! Map cloud to occupancy grid: one million points in the LiDAR slice of a 40 m x 30 m floor, binned
//! into a 0.05 m grid (480,000 cells) and inflated by Spot's 0.25 m radius, single thread.
//!
//! `cargo bench -p spot-nav-benches --bench gridmap`

// Bench setup that fails has no figures to report: stop loudly.
#![allow(clippy::panic)]

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use gridmap::{OccupancyGridBuilder, OccupancyGridConfig, UnknownCells, inflate};
use nalgebra::Point3;
use slam_core::PointCloud;

/// Walls of a building floor: an outer rectangle, corridor walls and pillars, with 2 cm noise,
/// all between 0.3 and 0.7 m high (inside the slice around a LiDAR at 0.5 m).
fn building_slice(n: usize) -> PointCloud {
    let mut s: u64 = 0x2545_F491_4F6C_DD1D;
    let mut rnd = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f32 / (1u64 << 53) as f32
    };
    let points = (0..n)
        .map(|i| {
            let (u, v, noise) = (rnd(), rnd(), (rnd() - 0.5) * 0.04);
            let z = 0.3 + 0.4 * v;
            match i % 8 {
                0 => Point3::new(u * 40.0, noise, z),
                1 => Point3::new(u * 40.0, 30.0 + noise, z),
                2 => Point3::new(noise, u * 30.0, z),
                3 => Point3::new(40.0 + noise, u * 30.0, z),
                4 => Point3::new(u * 40.0, 12.0 + noise, z),
                5 => Point3::new(u * 40.0, 16.0 + noise, z),
                6 => Point3::new(10.0 * (1.0 + (u * 3.0).floor()) + noise, u * 12.0, z),
                _ => {
                    let a = u * std::f32::consts::TAU;
                    Point3::new(20.0 + 0.3 * a.cos(), 23.0 + 0.3 * a.sin(), z)
                }
            }
        })
        .collect();
    PointCloud::from_points(points)
}

fn grid(c: &mut Criterion) {
    let cloud = building_slice(1_000_000);
    let builder = OccupancyGridBuilder::new(OccupancyGridConfig {
        resolution: 0.05,
        ..OccupancyGridConfig::default()
    })
    .unwrap_or_else(|e| panic!("{e}"));
    let sample = builder.build(&cloud, 0.5).unwrap_or_else(|e| panic!("{e}"));
    let cells = u64::from(sample.width()) * u64::from(sample.height());
    let mut group = c.benchmark_group("gridmap");
    group.sample_size(20);
    group.throughput(Throughput::Elements(cloud.len() as u64));
    group.bench_function(
        BenchmarkId::new("build_and_inflate", "1M_points_0.05m"),
        |b| {
            b.iter(|| {
                let g = builder.build(&cloud, 0.5).unwrap_or_else(|e| panic!("{e}"));
                inflate(&g.to_planning_grid(UnknownCells::Free), 0.25)
                    .unwrap_or_else(|e| panic!("{e}"))
            });
        },
    );
    group.bench_function(BenchmarkId::new("build", "1M_points_0.05m"), |b| {
        b.iter(|| builder.build(&cloud, 0.5).unwrap_or_else(|e| panic!("{e}")));
    });
    group.throughput(Throughput::Elements(cells));
    let planning = sample.to_planning_grid(UnknownCells::Free);
    group.bench_function(BenchmarkId::new("inflate", format!("{cells}_cells")), |b| {
        b.iter(|| inflate(&planning, 0.25).unwrap_or_else(|e| panic!("{e}")));
    });
    group.finish();
}

criterion_group!(benches, grid);
criterion_main!(benches);
