//! Scan Context place recognition on the simulated building (seed 3): the descriptor of one
//! VLP-16 scan, and a query against an index of every 4th scan of a lap (the keyframes of a
//! 105 m lap and more), the work the SLAM engine adds per keyframe. Single thread; setup
//! outside the timed loops.
//!
//! `cargo bench -p spot-nav-benches --bench place_recognition`

// Bench setup that fails has no figures to report: stop loudly.
#![allow(clippy::panic)]

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use registration::{
    ScanContext, ScanContextConfig, ScanContextIndex, ScanContextIndexConfig, ScanContextRecognizer,
};
use slam_core::PlaceRecognizer;
use spot_nav_benches::mapped_building;

fn place_recognition(c: &mut Criterion) {
    let mapped = mapped_building::map(3, 4).unwrap_or_else(|e| panic!("{e}"));
    let scans = &mapped.scans;
    let config = ScanContextConfig::default();
    let contexts: Vec<ScanContext> = scans
        .iter()
        .map(|(_, s)| ScanContext::from_cloud(s, &config).unwrap_or_else(|e| panic!("{e}")))
        .collect();
    // Four copies of the lap's keyframes: an index the size of a 400 m run.
    let mut index = ScanContextIndex::new(ScanContextIndexConfig {
        exclude_recent: 0,
        ..ScanContextIndexConfig::default()
    })
    .unwrap_or_else(|e| panic!("{e}"));
    for copy in 0..4u64 {
        for (k, context) in contexts.iter().enumerate() {
            index
                .insert(copy * 10_000 + k as u64, context.clone())
                .unwrap_or_else(|e| panic!("{e}"));
        }
    }
    eprintln!(
        "place_recognition: {} scans, index of {} keyframes",
        scans.len(),
        index.len()
    );
    // The engine's recognizer over the same keyframes: a keyframe's descriptor, its query from
    // the scan's origin and from 0.5 m around it (5 descriptors, 5 queries).
    let mut places = ScanContextRecognizer::new(
        config.clone(),
        ScanContextIndexConfig {
            exclude_recent: 0,
            ..ScanContextIndexConfig::default()
        },
        ScanContextRecognizer::default_offset(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    for copy in 0..4 {
        for (k, (_, scan)) in scans.iter().enumerate() {
            places
                .add_keyframe(copy * 10_000 + k, scan)
                .unwrap_or_else(|e| panic!("{e}"));
        }
    }
    let mut group = c.benchmark_group("place_recognition");
    group.sample_size(30);
    let mut k = 0usize;
    group.bench_function(BenchmarkId::new("descriptor", "vlp16_scan"), |b| {
        b.iter(|| {
            k = (k + 1) % scans.len();
            black_box(ScanContext::from_cloud(&scans[k].1, &config))
        });
    });
    group.bench_function(BenchmarkId::new("query", index.len()), |b| {
        b.iter(|| {
            k = (k + 1) % contexts.len();
            black_box(index.query(&contexts[k]))
        });
    });
    group.bench_function(BenchmarkId::new("keyframe_candidates", index.len()), |b| {
        b.iter(|| {
            k = (k + 1) % scans.len();
            black_box(places.candidates(&scans[k].1))
        });
    });
    group.finish();
}

criterion_group!(benches, place_recognition);
criterion_main!(benches);
