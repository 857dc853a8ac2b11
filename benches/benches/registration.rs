//! Registration on `small_gicp`'s HDL-32E pair at 0.25 m voxels, single thread: preparation
//! (downsampling, k-d tree, normals) and alignment timed separately and together.
//!
//! `cargo bench -p spot-nav-benches --bench registration`

use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};
use registration::{PointToPlaneIcp, PointToPointIcp};
use slam_core::io::read_ply;
use slam_core::{PointCloud, Pose3, Registrator};

fn pair() -> Option<(PointCloud, PointCloud)> {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let source = read_ply(root.join("registration/tests/data/source.ply")).ok()?;
    let target = read_ply(root.join("slam-core/tests/data/hdl32e_pair_target.ply")).ok()?;
    Some((source, target))
}

fn bench_backend<R: Registrator>(
    c: &mut Criterion,
    name: &str,
    r: &R,
    source: &PointCloud,
    target: &PointCloud,
) {
    let mut group = c.benchmark_group("registration_hdl32e_pair_0.25m");
    group.sample_size(20);
    group.bench_function(BenchmarkId::new(name, "prepare"), |b| {
        b.iter(|| {
            (
                r.prepare_source(source).is_ok(),
                r.prepare_target(target).is_ok(),
            )
        });
    });
    // A fresh target per iteration: targets compute normals on first use and keep them.
    if let Ok(s) = r.prepare_source(source) {
        group.bench_function(BenchmarkId::new(name, "align"), |b| {
            b.iter_batched(
                || r.prepare_target(target),
                |t| {
                    t.and_then(|t| r.align(&s, &t, &Pose3::identity()))
                        .map(|a| a.rmse)
                },
                BatchSize::LargeInput,
            );
        });
    }
    group.bench_function(BenchmarkId::new(name, "prepare_and_align"), |b| {
        b.iter(|| {
            let (Ok(s), Ok(t)) = (r.prepare_source(source), r.prepare_target(target)) else {
                return f64::NAN;
            };
            r.align(&s, &t, &Pose3::identity())
                .map_or(f64::NAN, |a| a.rmse)
        });
    });
    group.finish();
}

fn registration(c: &mut Criterion) {
    let Some((source, target)) = pair() else {
        eprintln!("registration: test data missing; skipping");
        return;
    };
    bench_backend(
        c,
        "PointToPlaneIcp",
        &PointToPlaneIcp::default(),
        &source,
        &target,
    );
    bench_backend(
        c,
        "PointToPointIcp",
        &PointToPointIcp::default(),
        &source,
        &target,
    );
}

criterion_group!(benches, registration);
criterion_main!(benches);
