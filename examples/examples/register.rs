//! Register two LiDAR scans and print `target_T_source`.
//!
//! ```sh
//! cargo run --release --example register -- SOURCE TARGET [--method p2p|p2plane|loam] \
//!     [--voxel M] [--init x,y,z,roll,pitch,yaw] [--layout vlp16|hdl32e|os1-128] [--reference FILE] \
//!     [--repeat N]
//! ```
//!
//! Files are PCD, PLY or KITTI `.bin`. `--voxel` sets the ICP voxel (default 0.25 m); `--init`
//! is the initial guess (metres, degrees); `--layout` gives LOAM the ring layout of clouds
//! without a ring field (default VLP-16); `--reference` reads a 4x4 row-major `target_T_source`
//! and prints the result's distance to it; `--repeat N` runs preparation and alignment N times
//! (after one untimed run) and prints the best and median times. With no files it registers the bundled HDL-32E pair
//! (`small_gicp`'s data, MIT) against its reference pose.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use nalgebra::{Matrix4, UnitQuaternion};
use registration::{
    IcpConfig, LidarLayout, LoamConfig, LoamRegistrator, PointToPlaneIcp, PointToPointIcp,
};
use slam_core::io::read_cloud;
use slam_core::{Alignment, PointCloud, Pose3, Registrator, pose3_from_xyz_rpy};

struct Args {
    source: PathBuf,
    target: PathBuf,
    method: String,
    voxel: f32,
    init: Pose3,
    layout: LidarLayout,
    reference: Option<PathBuf>,
    repeat: usize,
}

fn bundled(p: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(p)
}

fn parse_args() -> Result<Args> {
    let mut files = Vec::new();
    let mut args = Args {
        source: PathBuf::new(),
        target: PathBuf::new(),
        method: "p2plane".into(),
        voxel: 0.25,
        init: Pose3::identity(),
        layout: LidarLayout::VLP16,
        reference: None,
        repeat: 1,
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        let mut value = || it.next().with_context(|| format!("{a} needs a value"));
        match a.as_str() {
            "--method" => args.method = value()?,
            "--voxel" => args.voxel = value()?.parse().context("--voxel")?,
            "--init" => {
                let v: Vec<f64> = value()?
                    .split(',')
                    .map(str::parse)
                    .collect::<Result<_, _>>()
                    .context("--init x,y,z,roll,pitch,yaw")?;
                let [x, y, z, r, p, w] = v[..] else {
                    bail!("--init needs six numbers");
                };
                args.init =
                    pose3_from_xyz_rpy(x, y, z, r.to_radians(), p.to_radians(), w.to_radians());
            }
            "--layout" => {
                args.layout = match value()?.as_str() {
                    "vlp16" => LidarLayout::VLP16,
                    "hdl32e" => LidarLayout::HDL32E,
                    "os1-128" => LidarLayout::OS1_128,
                    other => bail!("unknown layout {other} (vlp16, hdl32e, os1-128)"),
                }
            }
            "--reference" => args.reference = Some(value()?.into()),
            "--repeat" => {
                args.repeat = value()?.parse().context("--repeat")?;
                if args.repeat == 0 {
                    bail!("--repeat needs at least 1");
                }
            }
            _ if a.starts_with("--") => bail!("unknown option {a}"),
            _ => files.push(PathBuf::from(a)),
        }
    }
    match files.len() {
        0 => {
            args.source = bundled("../registration/tests/data/source.ply");
            args.target = bundled("../slam-core/tests/data/hdl32e_pair_target.ply");
            args.reference
                .get_or_insert_with(|| bundled("../registration/tests/data/T_target_source.txt"));
            args.layout = LidarLayout::HDL32E;
        }
        2 => {
            args.target = files.pop().unwrap_or_default();
            args.source = files.pop().unwrap_or_default();
        }
        _ => bail!("give SOURCE and TARGET files, or none for the bundled pair"),
    }
    Ok(args)
}

fn read_reference(path: &Path) -> Result<Pose3> {
    let text = std::fs::read_to_string(path).with_context(|| path.display().to_string())?;
    let v: Vec<f64> = text
        .split_whitespace()
        .map(str::parse)
        .collect::<Result<_, _>>()
        .context("reference: 16 numbers")?;
    if v.len() != 16 {
        bail!("reference: expected 16 numbers, found {}", v.len());
    }
    let m = Matrix4::from_row_slice(&v);
    Ok(Pose3::from_parts(
        m.fixed_view::<3, 1>(0, 3).into_owned().into(),
        UnitQuaternion::from_matrix(&m.fixed_view::<3, 3>(0, 0).into_owned()),
    ))
}

/// What `run` measured: the last result, and per run the preparation and alignment times (ms).
struct Timed {
    alignment: Alignment,
    prepare_ms: Vec<f64>,
    align_ms: Vec<f64>,
}

/// Prepare both clouds and align, `repeat` times.
fn run<R: Registrator>(
    r: &R,
    source: &PointCloud,
    target: &PointCloud,
    init: &Pose3,
    repeat: usize,
) -> Result<Timed> {
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    let (mut prepare_ms, mut align_ms) = (Vec::new(), Vec::new());
    let mut alignment = None;
    // Repeated runs start with an untimed one: the first pays for page faults and allocations.
    if repeat > 1 {
        r.align(&r.prepare_source(source)?, &r.prepare_target(target)?, init)?;
    }
    for _ in 0..repeat {
        let t0 = Instant::now();
        let s = r.prepare_source(source)?;
        let t = r.prepare_target(target)?;
        let t1 = Instant::now();
        alignment = Some(r.align(&s, &t, init)?);
        prepare_ms.push(ms(t1 - t0));
        align_ms.push(ms(t1.elapsed()));
    }
    Ok(Timed {
        alignment: alignment.context("no run")?,
        prepare_ms,
        align_ms,
    })
}

/// Smallest and median of `v` (not empty).
fn best_and_median(mut v: Vec<f64>) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    (v[0], v[v.len() / 2])
}

/// The time line: one run's two parts, or the best and median of several.
fn print_times(timed: &Timed, repeat: usize) {
    if repeat == 1 {
        println!(
            "time        {:.1} ms prepare + {:.1} ms align",
            timed.prepare_ms[0], timed.align_ms[0]
        );
    } else {
        let total: Vec<f64> = timed
            .prepare_ms
            .iter()
            .zip(&timed.align_ms)
            .map(|(p, a)| p + a)
            .collect();
        let (best, median) = best_and_median(total);
        let (prepare, _) = best_and_median(timed.prepare_ms.clone());
        let (align, _) = best_and_median(timed.align_ms.clone());
        println!(
            "time        prepare + align: best {best:.1} ms, median {median:.1} ms of {repeat} runs \
             (best prepare {prepare:.1} ms, best align {align:.1} ms)"
        );
    }
}

fn main() -> Result<()> {
    let args = parse_args()?;
    let source = read_cloud(&args.source).with_context(|| args.source.display().to_string())?;
    let target = read_cloud(&args.target).with_context(|| args.target.display().to_string())?;
    let icp = IcpConfig {
        source_voxel: args.voxel,
        target_voxel: args.voxel,
        ..IcpConfig::default()
    };
    let mut loam = LoamConfig::default();
    loam.features.layout = args.layout;
    // A pair may start far from its answer: begin with a wide robust threshold.
    loam.initial_tukey_threshold = 1.0;
    let timed = match args.method.as_str() {
        "p2p" => run(
            &PointToPointIcp { config: icp },
            &source,
            &target,
            &args.init,
            args.repeat,
        )?,
        "p2plane" => run(
            &PointToPlaneIcp { config: icp },
            &source,
            &target,
            &args.init,
            args.repeat,
        )?,
        "loam" => run(
            &LoamRegistrator { config: loam },
            &source,
            &target,
            &args.init,
            args.repeat,
        )?,
        other => bail!("unknown method {other} (p2p, p2plane, loam)"),
    };
    let a = &timed.alignment;
    let (t, q) = (a.pose.translation.vector, a.pose.rotation.coords);
    println!(
        "source      {} ({} points)",
        args.source.display(),
        source.len()
    );
    println!(
        "target      {} ({} points)",
        args.target.display(),
        target.len()
    );
    println!("method      {}", args.method);
    println!(
        "target_T_source (x y z qx qy qz qw)\n            {:.6} {:.6} {:.6} {:.6} {:.6} {:.6} {:.6}",
        t.x, t.y, t.z, q.x, q.y, q.z, q.w
    );
    println!(
        "iterations  {} ({})",
        a.iterations,
        if a.converged {
            "converged"
        } else {
            "iteration cap"
        }
    );
    println!(
        "inliers     {} ({:.1} %)",
        a.inliers,
        100.0 * a.inlier_ratio
    );
    println!("rmse        {:.4} m", a.rmse);
    println!(
        "degeneracy  smallest/largest information eigenvalue {:.2e}",
        a.min_eigenvalue_ratio
    );
    print_times(&timed, args.repeat);
    if let Some(path) = &args.reference {
        let e = read_reference(path)?.inverse() * a.pose;
        println!(
            "vs reference {:.3} deg, {:.2} cm",
            e.rotation.angle().to_degrees(),
            100.0 * e.translation.vector.norm()
        );
    }
    Ok(())
}
