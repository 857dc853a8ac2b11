//! Registration on `small_gicp`'s HDL-32E pair at 0.25 m voxels, single thread: preparation
//! (downsampling, k-d tree, normals or features) and alignment timed separately and together;
//! and the LOAM odometry step of the simulated Spot: features of a VLP-16 scan and their
//! alignment against a local map of the 40 previous keyframes.
//!
//! `cargo bench -p spot-nav-benches --bench registration`

use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};
use registration::{LidarLayout, LoamConfig, LoamRegistrator, PointToPlaneIcp, PointToPointIcp};
use slam_core::io::read_ply;
use slam_core::{MapRegistrator, PointCloud, Pose3, Registrator, pose3_from_xyz_rpy};
use spot_adapter::robot::Sample;
use spot_adapter::sim::{SimulatedSpot, SimulationConfig};

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
    // Single thread, as the peer: the ICP backends search correspondences on rayon's pool,
    // which this bench holds to one worker.
    if let Err(e) = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build_global()
    {
        eprintln!("registration: cannot hold the thread pool to one thread ({e}); skipping");
        return;
    }
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
    let mut loam = LoamConfig::default();
    loam.features.layout = LidarLayout::HDL32E;
    bench_backend(
        c,
        "LoamRegistrator",
        &LoamRegistrator { config: loam },
        &source,
        &target,
    );
}

/// The engine's LiDAR odometry with LOAM on the simulated Spot (seed 1, VLP-16 at 5 Hz): 40
/// keyframes 0.24 m apart form the local map (at their true poses); the next scan is aligned
/// to it from a guess 1 cm and 0.2 degrees off (the simulated Spot's odometry drifts 1.9 % of
/// distance: 5 mm over one 0.24 m keyframe step), and from 3 cm and 0.5 degrees off, with the
/// SLAM engine's settings (`LoamConfig::local_map_odometry`) and with every pick kept. Also the
/// local map built whole, and slid by one keyframe in place (what the engine does per keyframe).
fn loam_odometry_step(c: &mut Criterion) {
    let Ok(sim) = SimulatedSpot::corridor_loop(&SimulationConfig::with_seed(1)) else {
        eprintln!("loam_odometry_step: simulation failed; skipping");
        return;
    };
    let samples: Vec<Sample> = sim.take(2 * 41 + 1).collect();
    let world_t_lidar =
        |s: &Sample| s.ground_truth.unwrap_or_else(Pose3::identity) * s.body_t_lidar;
    let loam = LoamRegistrator {
        config: LoamConfig::local_map_odometry(),
    };
    let all_picks = LoamRegistrator::default();
    let keyframes: Vec<_> = samples
        .iter()
        .step_by(2)
        .take(40)
        .filter_map(|s| {
            let f = loam.prepare_source(&s.cloud).ok()?;
            Some((loam.keyframe_source(f), world_t_lidar(s)))
        })
        .collect();
    let parts: Vec<_> = keyframes.iter().map(|(f, p)| (f, *p)).collect();
    let Ok(map) = loam.target_from_sources(&parts) else {
        eprintln!("loam_odometry_step: local map failed; skipping");
        return;
    };
    let scan = &samples[2 * 41];
    let near =
        world_t_lidar(scan) * pose3_from_xyz_rpy(0.007, -0.007, 0.0, 0.0, 0.0, 0.2f64.to_radians());
    let far =
        world_t_lidar(scan) * pose3_from_xyz_rpy(0.02, -0.02, 0.01, 0.0, 0.0, 0.5f64.to_radians());
    let mut group = c.benchmark_group("loam_odometry_step");
    group.sample_size(30);
    group.bench_function("features", |b| {
        b.iter(|| loam.prepare_source(&scan.cloud).map(|f| f.len()));
    });
    group.bench_function("local_map_40_keyframes", |b| {
        b.iter(|| loam.target_from_sources(&parts).map(|m| m.planes().len()));
    });
    group.bench_function("slide_local_map_by_one_keyframe", |b| {
        // The engine's per-keyframe update: the newest keyframe in, the oldest out.
        let (newest, pose) = (&keyframes[39], keyframes[39].1);
        let Some(mut slid) = loam.empty_map() else {
            return;
        };
        for (i, (f, p)) in (0u32..).zip(&keyframes[..39]) {
            loam.add_to_map(&mut slid, i, f, p);
        }
        let mut next = 39u32;
        b.iter(|| {
            loam.add_to_map(&mut slid, next, &newest.0, &pose);
            loam.remove_from_map(&mut slid, next - 39);
            next += 1;
            slid.planes().len()
        });
    });
    for (name, r, guess) in [
        ("features_and_align", &loam, near),
        ("features_and_align_far_guess", &loam, far),
        ("features_and_align_all_picks", &all_picks, near),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| {
                r.prepare_source(&scan.cloud)
                    .and_then(|f| r.align(&f, &map, &guess))
                    .map(|a| a.rmse)
            });
        });
    }
    group.finish();
}

criterion_group!(benches, registration, loam_odometry_step);
criterion_main!(benches);
