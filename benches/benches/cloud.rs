//! Point-cloud primitives: voxel-grid downsampling throughput (points per second).
//!
//! `cargo bench -p spot-nav-benches --bench cloud`

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::Point3;
use slam_core::PointCloud;

/// A deterministic room-scale cloud: `n` points on the walls, floor and ceiling of a 20 x 12 x 3 m
/// box, with a few centimetres of noise (a stand-in for a LiDAR scan's spatial spread).
fn synthetic_room(n: usize) -> PointCloud {
    let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut rnd = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f32 / (1u64 << 53) as f32
    };
    let points = (0..n)
        .map(|i| {
            let (u, v, noise) = (rnd(), rnd(), (rnd() - 0.5) * 0.04);
            match i % 6 {
                0 => Point3::new(u * 20.0, noise, v * 3.0),
                1 => Point3::new(u * 20.0, 12.0 + noise, v * 3.0),
                2 => Point3::new(noise, u * 12.0, v * 3.0),
                3 => Point3::new(20.0 + noise, u * 12.0, v * 3.0),
                4 => Point3::new(u * 20.0, v * 12.0, noise),
                _ => Point3::new(u * 20.0, v * 12.0, 3.0 + noise),
            }
        })
        .collect();
    PointCloud::from_points(points)
}

fn voxel_downsample(c: &mut Criterion) {
    let mut group = c.benchmark_group("voxel_downsample");
    for &n in &[100_000usize, 1_000_000] {
        let cloud = synthetic_room(n);
        group.throughput(Throughput::Elements(n as u64));
        for &voxel in &[0.05f32, 0.25] {
            group.bench_with_input(
                BenchmarkId::new(format!("hash_centroid_{voxel}m"), n),
                &cloud,
                |b, cloud| b.iter(|| cloud.voxel_downsample(voxel)),
            );
        }
    }
    group.finish();
}

criterion_group!(benches, voxel_downsample);
criterion_main!(benches);
