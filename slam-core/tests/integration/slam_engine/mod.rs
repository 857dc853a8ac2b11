//! The Graph-SLAM engine on a synthetic building with drifting odometry, driven by small
//! test-only backends (brute-force point-to-point ICP and dense Gauss-Newton), so the engine's own
//! logic (prediction, keyframes, local map, loop closure, edge frames, optimisation, outputs) is
//! checked against ground truth independently of the real backends.
#![allow(
    clippy::unwrap_used,
    clippy::panic,
    clippy::many_single_char_names,
    clippy::too_many_lines
)]

mod backends;
mod bad_input;
mod loops;
mod tracking;

use backends::{BruteIcp, DenseGaussNewton};
use nalgebra::Point3;
use slam_core::{
    EdgeInformation, GraphSlam, GraphSlamConfig, MapRegistrator, Optimizer, PointCloud, Pose3,
    ScanInput, ScanOutcome, pose3_from_xyz_rpy,
};

/// Points scattered at random (16 per square metre) on the walls, floor and pillars of a
/// 24 m x 12 m x 3 m hall: random, not a lattice, so that ICP cannot snap to a grid.
fn hall() -> Vec<Point3<f64>> {
    let mut pts = Vec::new();
    let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut rnd = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut patch = |f: &dyn Fn(f64, f64) -> Point3<f64>, a: f64, b: f64| {
        let n = (16.0 * a * b) as usize;
        for _ in 0..n {
            let (u, v) = (rnd() * a, rnd() * b);
            pts.push(f(u, v));
        }
    };
    patch(&|u, v| Point3::new(u, 0.0, v), 24.0, 3.0);
    patch(&|u, v| Point3::new(u, 12.0, v), 24.0, 3.0);
    patch(&|u, v| Point3::new(0.0, u, v), 12.0, 3.0);
    patch(&|u, v| Point3::new(24.0, u, v), 12.0, 3.0);
    patch(&|u, v| Point3::new(u, v, 0.0), 24.0, 12.0);
    // Pillars and boxes that break the symmetry.
    for (cx, cy, s) in [
        (6.0, 4.0, 0.6),
        (15.0, 8.5, 1.0),
        (19.0, 3.0, 0.5),
        (9.5, 9.0, 1.4),
        (12.0, 5.5, 0.4),
    ] {
        patch(&|u, v| Point3::new(cx + u, cy, v), s, 3.0);
        patch(&|u, v| Point3::new(cx + u, cy + s, v), s, 3.0);
        patch(&|u, v| Point3::new(cx, cy + u, v), s, 3.0);
        patch(&|u, v| Point3::new(cx + s, cy + u, v), s, 3.0);
    }
    pts
}

/// Ground-truth LiDAR poses around a rectangular loop (3 m .. 21 m by 2 m .. 10 m), 0.15 m apart,
/// ending back at the start.
fn loop_poses() -> Vec<Pose3> {
    let corners = [
        (3.0, 2.0),
        (21.0, 2.0),
        (21.0, 10.0),
        (3.0, 10.0),
        (3.0, 2.0),
    ];
    let mut out = Vec::new();
    for w in corners.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        let (dx, dy): (f64, f64) = (x1 - x0, y1 - y0);
        let len = dx.hypot(dy);
        let yaw = dy.atan2(dx);
        let n = (len / 0.15).round() as usize;
        for k in 0..n {
            let t = k as f64 / n as f64;
            out.push(pose3_from_xyz_rpy(
                x0 + t * dx,
                y0 + t * dy,
                1.0,
                0.0,
                0.0,
                yaw,
            ));
        }
    }
    out.push(pose3_from_xyz_rpy(3.0, 2.0, 1.0, 0.0, 0.0, 0.0));
    out
}

fn scan(world: &[Point3<f64>], pose: &Pose3) -> PointCloud {
    let inv = pose.inverse();
    PointCloud::from_points(
        world
            .iter()
            .filter(|p| (p.coords - pose.translation.vector).norm() < 9.0)
            .map(|p| (inv * p).cast::<f32>())
            .collect(),
    )
}

/// The odometry of `truth` with a 3 % scale error and a yaw drift of 1 degree per 10 m.
fn drifting_odometry(truth: &[Pose3]) -> Vec<Pose3> {
    let mut odom = vec![truth[0]];
    for w in truth.windows(2) {
        let d = w[0].inverse() * w[1];
        let dist = d.translation.vector.norm();
        let noisy = Pose3::from_parts((d.translation.vector * 1.03).into(), d.rotation)
            * pose3_from_xyz_rpy(0.0, 0.0, 0.0, 0.0, 0.0, (0.1f64).to_radians() * dist);
        odom.push(odom.last().unwrap() * noisy);
    }
    odom
}

/// Feeds scan `k` (0.2 s apart) of `world` seen from `truth`, with the odometry `odom`.
fn feed<R: MapRegistrator, C: MapRegistrator, O: Optimizer<Pose3>>(
    slam: &mut GraphSlam<R, C, O>,
    world: &[Point3<f64>],
    k: usize,
    truth: &Pose3,
    odom: Pose3,
) -> ScanOutcome {
    let cloud = scan(world, truth);
    slam.process(&ScanInput {
        stamp: k as f64 * 0.2,
        odom_t_body: Some(odom),
        body_t_lidar: Pose3::identity(),
        cloud: &cloud,
        gyro_orientation: None,
    })
}

/// Settings for the loop with the test ICP.
fn loop_config() -> GraphSlamConfig {
    GraphSlamConfig {
        keyframe_distance: 0.45,
        local_map_keyframes: 10,
        loop_neighbours: 5,
        loop_search_radius: 1.0,
        loop_max_mean_squared_error: 0.02,
        min_scan_points: 50,
        // The test-only registrator reports no real information (identity), so loop edges take
        // fixed sigmas here rather than the default registration information.
        loop_information: EdgeInformation::Fixed {
            translation_sigma: 0.02,
            rotation_sigma: 0.3f64.to_radians(),
        },
        ..GraphSlamConfig::default()
    }
}

/// The engine with the test backends.
fn brute_engine(
    config: GraphSlamConfig,
) -> Result<GraphSlam<BruteIcp, BruteIcp, DenseGaussNewton>, slam_core::InvalidSetting> {
    GraphSlam::try_new(
        config,
        BruteIcp { max_distance: 0.5 },
        BruteIcp { max_distance: 1.0 },
        BruteIcp { max_distance: 0.5 },
        DenseGaussNewton,
    )
}

/// Settings for runs without loop closure (the test ICP on the hall).
fn no_loop_config() -> GraphSlamConfig {
    GraphSlamConfig {
        keyframe_distance: 0.45,
        local_map_keyframes: 10,
        min_scan_points: 50,
        loop_search_radius: 1e-6,
        ..GraphSlamConfig::default()
    }
}
