//! Register two LiDAR scans and print `target_T_source`.
//!
//! ```sh
//! cargo run --release --example register -- SOURCE TARGET [--method p2p|p2plane|loam] \
//!     [--voxel M] [--init x,y,z,roll,pitch,yaw] [--layout vlp16|hdl32e|os1-128] [--reference FILE] \
//!     [--repeat N] [--config FILE] [--print-config]
//! ```
//!
//! Files are PCD, PLY or KITTI `.bin`. `--voxel` sets the ICP voxel (default 0.25 m); `--init`
//! is the initial guess (metres, degrees); `--layout` gives LOAM the ring layout of clouds
//! without a ring field (default VLP-16); `--reference` reads a 4x4 row-major `target_T_source`
//! and prints the result's distance to it; `--repeat N` runs preparation and alignment N times
//! (after one untimed run) and prints the best and median times; `--config FILE` reads the ICP
//! (`[icp]`, an `IcpConfig`) and LOAM settings (`[loam]`, a `LoamConfig`) from a TOML file, the
//! options given winning over it, and `--print-config` prints them. With no files it registers the bundled HDL-32E pair
//! (`small_gicp`'s data, MIT) against its reference pose. Exits with status 1 when the alignment
//! stopped at its iteration cap (after printing the result).

use std::num::NonZeroUsize;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::{Parser, ValueEnum};
use nalgebra::{Matrix4, UnitQuaternion};
use registration::{
    IcpConfig, LidarLayout, LoamConfig, LoamRegistrator, PointToPlaneIcp, PointToPointIcp,
};
use serde::{Deserialize, Serialize};
use slam_core::io::read_cloud;
use slam_core::{Alignment, PointCloud, Pose3, Registrator, pose3_from_xyz_rpy};
use spot_adapter::record::ReturnFilter;
use spot_nav_examples::{
    SettingsArgs, Timings, data, out, parse_numbers, print_settings, value_name,
};

/// Register two LiDAR scans and print `target_T_source`.
///
/// Reads PCD, PLY or KITTI `.bin` files; prints the pose, the iterations, inliers, RMSE,
/// degeneracy and times, and the distance to a reference pose when one is given. With no files it registers the bundled HDL-32E pair (`small_gicp`'s data, MIT) against its
/// reference pose. Fails when the alignment stopped at its iteration cap (after printing the
/// result).
#[derive(Debug, Parser)]
#[command(name = "register")]
struct Args {
    /// The scan to move onto the target (with TARGET; neither: the bundled pair).
    #[arg(value_name = "SOURCE", requires = "target")]
    source: Option<PathBuf>,
    /// The scan held fixed.
    #[arg(value_name = "TARGET")]
    target: Option<PathBuf>,
    /// The registration method.
    #[arg(long, value_enum, default_value_t = Method::PointToPlane)]
    method: Method,
    /// Voxel size of both clouds for ICP (metres) [default: the settings' `icp.source_voxel`
    /// and `icp.target_voxel`, 0.25].
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    voxel: Option<f32>,
    /// Initial guess of `target_T_source`: metres and degrees (roll, pitch, yaw).
    #[arg(
        long,
        value_name = "x,y,z,roll,pitch,yaw",
        allow_hyphen_values = true,
        value_parser = parse_numbers::<6>
    )]
    init: Option<[f64; 6]>,
    /// Ring layout for LOAM when a cloud has no ring field [default: the settings'
    /// `loam.features.layout`, vlp16; hdl32e for the bundled pair].
    #[arg(long, value_enum)]
    layout: Option<Layout>,
    /// A 4x4 row-major `target_T_source` to compare the result with [default: the bundled
    /// pair's reference, for the bundled pair].
    #[arg(long, value_name = "FILE")]
    reference: Option<PathBuf>,
    /// Run preparation and alignment N times (after one untimed run) and print the best and
    /// median times.
    #[arg(
        long,
        value_name = "N",
        allow_negative_numbers = true,
        default_value = "1"
    )]
    repeat: NonZeroUsize,
    /// The ICP (`[icp]`) and LOAM (`[loam]`) settings: `--config FILE`, `--print-config`.
    #[command(flatten)]
    settings: SettingsArgs,
}

/// The settings file of `register` (`--config`, `--print-config`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
struct Settings {
    /// Point-to-point and point-to-plane ICP.
    icp: IcpConfig,
    /// LOAM; by default with a wide first robust threshold (1 m: a pair may start far from its
    /// answer) and the pair's ring layout.
    loam: LoamConfig,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            icp: IcpConfig::default(),
            loam: LoamConfig {
                initial_tukey_threshold: 1.0,
                ..LoamConfig::default()
            },
        }
    }
}

/// `--method`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Method {
    /// Point-to-point ICP.
    #[value(name = "p2p")]
    PointToPoint,
    /// Point-to-plane ICP.
    #[value(name = "p2plane")]
    PointToPlane,
    /// LOAM edge and planar features.
    #[value(name = "loam")]
    Loam,
}

/// `--layout`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Layout {
    /// Velodyne VLP-16.
    #[value(name = "vlp16")]
    Vlp16,
    /// Velodyne HDL-32E.
    #[value(name = "hdl32e")]
    Hdl32e,
    /// Ouster OS1-128.
    #[value(name = "os1-128")]
    Os1_128,
}

impl Layout {
    fn lidar_layout(self) -> LidarLayout {
        match self {
            Self::Vlp16 => LidarLayout::VLP16,
            Self::Hdl32e => LidarLayout::HDL32E,
            Self::Os1_128 => LidarLayout::OS1_128,
        }
    }
}

/// The files and settings of one run, defaults filled in.
struct Job {
    source: PathBuf,
    target: PathBuf,
    /// The ring layout of the pair, unless the settings or `--layout` give one.
    layout: LidarLayout,
    reference: Option<PathBuf>,
    init: Pose3,
}

impl Job {
    fn new(args: &Args) -> Self {
        let init = args
            .init
            .map_or_else(Pose3::identity, |[x, y, z, r, p, w]| {
                pose3_from_xyz_rpy(x, y, z, r.to_radians(), p.to_radians(), w.to_radians())
            });
        match (&args.source, &args.target) {
            (Some(source), Some(target)) => Self {
                source: source.clone(),
                target: target.clone(),
                layout: LidarLayout::VLP16,
                reference: args.reference.clone(),
                init,
            },
            _ => Self {
                source: data::pair_source(),
                target: data::pair_target(),
                layout: LidarLayout::HDL32E,
                reference: Some(args.reference.clone().unwrap_or_else(data::pair_reference)),
                init,
            },
        }
    }
}

fn main() -> ExitCode {
    spot_nav_examples::run(|| register(&Args::parse()))
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

/// The time line: one run's two parts, or the best and median of several.
fn print_times(timed: &Timed) -> Result<()> {
    let summary = |v: &[f64]| Timings::new(v.iter().copied()).context("no run");
    let (prepare, align) = (summary(&timed.prepare_ms)?, summary(&timed.align_ms)?);
    if prepare.len() == 1 {
        out!(
            "time        {:.1} ms prepare + {:.1} ms align",
            prepare.best(),
            align.best()
        )
    } else {
        let total = Timings::new(
            timed
                .prepare_ms
                .iter()
                .zip(&timed.align_ms)
                .map(|(p, a)| p + a),
        )
        .context("no run")?;
        out!(
            "time        prepare + align: best {:.1} ms, median {:.1} ms of {} runs \
             (best prepare {:.1} ms, best align {:.1} ms)",
            total.best(),
            total.median(),
            total.len(),
            prepare.best(),
            align.best()
        )
    }
}

/// The cloud at `path` without its no-return points (exact zeros, inside the housing), which
/// would pair with each other; says how many there were.
fn read_returns(path: &Path, which: &str) -> Result<PointCloud> {
    let cloud = read_cloud(path).with_context(|| path.display().to_string())?;
    let returns = ReturnFilter::default();
    let (cloud, d) = returns.apply(cloud);
    if d.no_return + d.non_finite > 0 {
        out!(
            "{which:<11} {} no-return points (zeros or within {} m) and {} non-finite removed",
            d.no_return,
            returns.min_range,
            d.non_finite
        )?;
    }
    Ok(cloud)
}

fn register(args: &Args) -> Result<()> {
    let job = Job::new(args);
    let mut defaults = Settings::default();
    defaults.loam.features.layout = job.layout;
    let mut settings = args.settings.load(defaults)?;
    if let Some(voxel) = args.voxel {
        settings.icp.source_voxel = voxel;
        settings.icp.target_voxel = voxel;
    }
    if let Some(layout) = args.layout {
        settings.loam.features.layout = layout.lidar_layout();
    }
    if let Some(format) = args.settings.print_config {
        return print_settings(&settings, format);
    }
    let Settings { icp, loam } = settings;
    let repeat = args.repeat.get();
    let source = read_returns(&job.source, "source")?;
    let target = read_returns(&job.target, "target")?;
    let timed = match args.method {
        Method::PointToPoint => run(
            &PointToPointIcp { config: icp },
            &source,
            &target,
            &job.init,
            repeat,
        )?,
        Method::PointToPlane => run(
            &PointToPlaneIcp { config: icp },
            &source,
            &target,
            &job.init,
            repeat,
        )?,
        Method::Loam => run(
            &LoamRegistrator { config: loam },
            &source,
            &target,
            &job.init,
            repeat,
        )?,
    };
    let a = &timed.alignment;
    let (t, q) = (a.pose.translation.vector, a.pose.rotation.coords);
    out!(
        "source      {} ({} points)",
        job.source.display(),
        source.len()
    )?;
    out!(
        "target      {} ({} points)",
        job.target.display(),
        target.len()
    )?;
    out!("method      {}", value_name(&args.method))?;
    out!(
        "target_T_source (x y z qx qy qz qw)\n            {:.6} {:.6} {:.6} {:.6} {:.6} {:.6} {:.6}",
        t.x,
        t.y,
        t.z,
        q.x,
        q.y,
        q.z,
        q.w
    )?;
    out!(
        "iterations  {} ({})",
        a.iterations,
        if a.converged {
            "converged"
        } else {
            "iteration cap"
        }
    )?;
    out!(
        "inliers     {} ({:.1} %)",
        a.inliers,
        100.0 * a.inlier_ratio
    )?;
    out!("rmse        {:.4} m", a.rmse)?;
    out!(
        "degeneracy  smallest/largest information eigenvalue {:.2e}",
        a.min_eigenvalue_ratio
    )?;
    print_times(&timed)?;
    if let Some(path) = &job.reference {
        let e = read_reference(path)?.inverse() * a.pose;
        out!(
            "vs reference {:.3} deg, {:.2} cm",
            e.rotation.angle().to_degrees(),
            100.0 * e.translation.vector.norm()
        )?;
    }
    if !a.converged {
        bail!(
            "the alignment stopped at its iteration cap ({} iterations) without converging",
            a.iterations
        );
    }
    Ok(())
}
