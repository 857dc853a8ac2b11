//! `VoxelHashMap` against a brute-force search: the same k nearest points (by distance) for
//! random clouds of several shapes, cell sizes and radii, before and after removing owners.

use nalgebra::{Point3, Vector3};
use proptest::prelude::*;
use registration::VoxelHashMap;

/// Squared distances of the `k` nearest points within `r`, by brute force, in f32 as the map
/// computes them.
fn brute(points: &[Point3<f64>], q: &Point3<f64>, k: usize, r: f64) -> Vec<f32> {
    let f = |v: f64| v as f32;
    let mut d: Vec<f32> = points
        .iter()
        .map(|p| {
            let (x, y, z) = (f(p.x) - f(q.x), f(p.y) - f(q.y), f(p.z) - f(q.z));
            x * x + y * y + z * z
        })
        .filter(|&d2| d2 <= (r * r) as f32)
        .collect();
    d.sort_by(f32::total_cmp);
    d.truncate(k);
    d
}

/// Points of one of three shapes from unit samples: a 4 m cube; two walls and a floor, as a
/// corridor; a small cluster far from the origin at negative coordinates.
fn shaped(shape: usize, (a, b, c): (f64, f64, f64)) -> Point3<f64> {
    match shape {
        0 => Point3::new(4.0 * a, 4.0 * b, 4.0 * c),
        1 => match (c * 3.0) as usize {
            0 => Point3::new(10.0 * a, 0.0, 3.0 * b),
            1 => Point3::new(10.0 * a, 2.0, 3.0 * b),
            _ => Point3::new(10.0 * a, 2.0 * b, 0.0),
        },
        _ => Point3::new(-5000.0 + 0.5 * a, 3000.0 + 0.5 * b, -20.0 + 0.1 * c),
    }
}

fn unit3() -> impl Strategy<Value = (f64, f64, f64)> {
    (0.0..1.0f64, 0.0..1.0f64, 0.0..1.0f64)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// Every query (near the points and away from them, several k and radii) returns the
    /// brute-force answer, before and after one owner's points are removed.
    #[test]
    fn nearest_k_equals_brute_force(
        shape in 0..3usize,
        cell in prop::sample::select(vec![0.05, 0.25, 1.0]),
        samples in prop::collection::vec(unit3(), 1..1500),
        queries in prop::collection::vec(unit3(), 40),
    ) {
        let points: Vec<Point3<f64>> = samples.iter().map(|&u| shaped(shape, u)).collect();
        let mut map = VoxelHashMap::new(cell, 0.0).unwrap();
        for (i, p) in points.iter().enumerate() {
            prop_assert!(map.insert((i % 4) as u32, p));
        }
        prop_assert_eq!(map.len(), points.len());
        let lo = points[0];
        let mut remaining = points.clone();
        let mut out = Vec::new();
        for round in 0..2 {
            for &(a, b, c) in &queries {
                let q = lo + Vector3::new(a, b, c) * 5.0 - Vector3::new(0.5, 0.5, 0.5);
                for (k, r) in [(1, 0.3), (5, 1.0), (8, 0.5), (20, 2.5)] {
                    map.nearest_k(&q, k, r, &mut out);
                    let got: Vec<f32> = out.iter().map(|(d2, _)| *d2 as f32).collect();
                    prop_assert_eq!(got, brute(&remaining, &q, k, r), "k {} r {} round {}", k, r, round);
                    for (d2, p) in &out {
                        prop_assert!(((p - q).norm_squared() - d2).abs() < 1e-3 * (1.0 + d2));
                    }
                }
            }
            let removed = map.remove_owner(1);
            let before = remaining.len();
            remaining = points.iter().enumerate().filter(|(i, _)| i % 4 != 1).map(|(_, p)| *p).collect();
            if round == 0 {
                prop_assert_eq!(removed, before - remaining.len());
            }
            prop_assert_eq!(map.len(), remaining.len());
        }
    }
}

#[test]
fn thinning_keeps_the_oldest_point_and_hands_over_to_the_newest() {
    let mut map = VoxelHashMap::new(0.25, 0.1).unwrap();
    assert!(
        (map.cell_size() - 0.3).abs() < 1e-12,
        "cell rounds to whole voxels"
    );
    let a = Point3::new(0.01, 0.01, 0.01);
    map.insert(1, &a);
    assert!(
        !map.insert(1, &Point3::new(0.02, 0.01, 0.01)),
        "one point per voxel and owner"
    );
    map.insert(2, &Point3::new(0.05, 0.05, 0.05));
    map.insert(3, &Point3::new(0.07, 0.05, 0.05));
    map.insert(2, &Point3::new(0.15, 0.05, 0.05));
    assert_eq!(map.len(), 2);
    let (_, p) = map.nearest(&Point3::origin(), 1.0).unwrap();
    assert!(
        (p - a).norm() < 1e-6,
        "the oldest owner holds the voxel: {p}"
    );
    // Owner 1 leaves: the newest other owner (3) takes its voxel over.
    assert_eq!(map.remove_owner(1), 0, "the voxel stays held");
    let (_, p) = map.nearest(&Point3::origin(), 1.0).unwrap();
    assert!((p.x - 0.07).abs() < 1e-6, "owner 3 took over: {p}");
    assert!(
        !map.insert(3, &Point3::new(0.08, 0.05, 0.05)),
        "owner 3 holds the voxel now: its first point stays"
    );
    let (_, p) = map.nearest(&Point3::origin(), 1.0).unwrap();
    assert!((p.x - 0.07).abs() < 1e-6, "{p}");
    assert_eq!(map.remove_owner(2), 1);
    assert_eq!(map.remove_owner(3), 1);
    assert!(map.is_empty());
    assert!(map.nearest(&Point3::origin(), 1.0).is_none());
}

/// A sliding window built in place holds the same voxels as the window built whole.
#[test]
fn sliding_window_holds_the_voxels_of_its_owners() {
    // Scattered points (a golden-ratio sequence per axis), each scan 0.3 m further along x.
    let frac = |v: f64| v - v.floor();
    let scans: Vec<Vec<Point3<f64>>> = (0..12)
        .map(|i| {
            (0..400)
                .map(|j| {
                    let t = f64::from(j + 400 * i);
                    Point3::new(
                        0.3 * f64::from(i) + 2.0 * frac(t * 0.618_034),
                        2.0 * frac(t * 0.754_878),
                        0.5 * frac(t * 0.569_840),
                    )
                })
                .collect()
        })
        .collect();
    let window = 4;
    let mut map = VoxelHashMap::new(0.3, 0.1).unwrap();
    let voxels = |points: &mut dyn Iterator<Item = Point3<f64>>| {
        let mut v: Vec<[i64; 3]> = points
            .map(|p| {
                let f = |x: f64| (f64::from(x as f32) / 0.1).floor() as i64;
                [f(p.x), f(p.y), f(p.z)]
            })
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    };
    for (i, scan) in scans.iter().enumerate() {
        for p in scan {
            map.insert(i as u32, p);
        }
        if i >= window {
            map.remove_owner((i - window) as u32);
        }
        let first = i.saturating_sub(window - 1);
        let expected = voxels(&mut scans[first..=i].iter().flatten().copied());
        assert_eq!(voxels(&mut map.points()), expected, "window ending at {i}");
        assert_eq!(map.len(), expected.len());
    }
}

/// A reach of hundreds of cells over a sparse map (the search then reads the occupied cells
/// instead of enumerating rings) still equals brute force.
#[test]
fn far_reach_over_a_sparse_map() {
    let points: Vec<Point3<f64>> = (0..200)
        .map(|i| {
            let t = f64::from(i);
            Point3::new(
                40.0 * (t * 0.618).sin(),
                40.0 * (t * 0.754).cos(),
                (t * 0.57).sin(),
            )
        })
        .collect();
    let mut map = VoxelHashMap::new(0.05, 0.0).unwrap();
    for p in &points {
        map.insert(0, p);
    }
    let mut out = Vec::new();
    for q in [
        Point3::origin(),
        Point3::new(30.0, -10.0, 2.0),
        Point3::new(100.0, 0.0, 0.0),
    ] {
        for (k, r) in [(1, 50.0), (7, 80.0), (300, 200.0)] {
            map.nearest_k(&q, k, r, &mut out);
            let got: Vec<f32> = out.iter().map(|(d2, _)| *d2 as f32).collect();
            assert_eq!(got, brute(&points, &q, k, r), "q {q} k {k} r {r}");
        }
    }
}

#[test]
fn bad_input_is_refused_or_skipped() {
    // Cells may span any number of voxels (2,000 per axis here): voxels are keyed map-wide.
    let mut wide = VoxelHashMap::new(100.0, 0.05).unwrap();
    assert!(wide.insert(1, &Point3::new(10.01, 0.01, 0.01)));
    assert!(
        !wide.insert(1, &Point3::new(10.02, 0.02, 0.02)),
        "same voxel, same owner"
    );
    assert!(wide.insert(1, &Point3::new(60.01, 0.01, 0.01)));
    assert_eq!(wide.len(), 2);
    assert!(VoxelHashMap::new(0.0, 0.0).is_err());
    assert!(VoxelHashMap::new(f64::NAN, 0.0).is_err());
    assert!(VoxelHashMap::new(0.25, -1.0).is_err());
    let mut map = VoxelHashMap::new(0.25, 0.0).unwrap();
    assert!(!map.insert(0, &Point3::new(f64::NAN, 0.0, 0.0)));
    assert!(!map.insert(0, &Point3::new(0.0, f64::INFINITY, 0.0)));
    assert!(map.is_empty());
    map.insert(0, &Point3::new(0.0, 0.0, 0.0));
    let mut out = Vec::new();
    map.nearest_k(&Point3::new(f64::NAN, 0.0, 0.0), 3, 1.0, &mut out);
    assert!(out.is_empty());
    map.nearest_k(&Point3::origin(), 0, 1.0, &mut out);
    assert!(out.is_empty());
    map.nearest_k(&Point3::origin(), 3, -1.0, &mut out);
    assert!(out.is_empty());
}

/// Points beyond the cells `i32` can number are refused like non-finite ones; queries there read
/// every point; cells 2^21 apart share a key (the first ring of a query near the origin reads
/// the cells next to 2^31, which the full reading then read again: a far point came back twice);
/// an infinite reach (its ring count overflowed and the search stopped after the first ring):
/// the brute-force answer every time.
#[test]
fn extreme_coordinates_and_an_infinite_reach_equal_brute_force() {
    let mut map = VoxelHashMap::new(1.0, 0.0).unwrap();
    let mut kept = Vec::new();
    for i in 0..40 {
        let t = f64::from(i);
        for (p, numbered) in [
            (Point3::new(3.0 * t.sin(), 3.0 * t.cos(), 0.1 * t), true),
            (Point3::new(-3e9 - 1e7 * t, 0.0, 0.0), false),
            (Point3::new(3e9 + 1e7 * t, 5.0, 0.0), false),
            // Near cell 2^31 - 1, whose key is that of cell -1.
            (Point3::new(2_147_470_000.0 + 256.0 * t, 0.0, 0.0), true),
            // Cells 2^21 apart: one key.
            (Point3::new(2_097_152.0 + 0.3 * t, 0.5, 0.5), true),
        ] {
            assert_eq!(map.insert(0, &p), numbered, "{p}");
            if numbered {
                kept.push(p);
            }
        }
    }
    let mut out = Vec::new();
    for q in [
        Point3::origin(),
        Point3::new(0.3, 0.5, 0.5),
        Point3::new(-3.2e9, 0.0, 0.0),
        Point3::new(3.1e9, 5.0, 0.0),
        Point3::new(2_147_480_000.0, 0.0, 0.0),
    ] {
        for (k, r) in [
            (1, f64::INFINITY),
            (5, f64::INFINITY),
            (200, f64::INFINITY),
            (3, 10.0),
        ] {
            map.nearest_k(&q, k, r, &mut out);
            let got: Vec<f32> = out.iter().map(|(d2, _)| *d2 as f32).collect();
            assert_eq!(got, brute(&kept, &q, k, r), "q {q} k {k} r {r}");
        }
    }
}
