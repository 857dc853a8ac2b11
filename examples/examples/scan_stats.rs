//! Read a real LiDAR scan and print its statistics and voxel-downsampled sizes.
//!
//! `cargo run --release --example scan_stats [FILE.pcd|FILE.ply|FILE.bin]`
//!
//! With no argument it reads the bundled HDL-32E scan from the parking-garage sequence
//! (`slam-core/tests/data`, MIT licence of libwave; see that folder's README).

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::Parser;
use slam_core::io::read_cloud;
use spot_adapter::record::ReturnFilter;
use spot_nav_examples::{data, out, quantile};

/// Read a LiDAR scan and print its statistics and voxel-downsampled sizes.
///
/// Prints the point count, channels, bounds, range percentiles and the sizes after 5, 10 and
/// 25 cm voxel downsampling. Fails when the scan has no finite point.
#[derive(Debug, Parser)]
#[command(name = "scan_stats")]
struct Args {
    /// The scan: PCD, PLY or KITTI `.bin` (by extension).
    #[arg(value_name = "FILE", default_value_os_t = data::garage_scan())]
    file: PathBuf,
}

fn main() -> ExitCode {
    spot_nav_examples::run(|| scan_stats(&Args::parse()))
}

fn scan_stats(args: &Args) -> Result<()> {
    let path = &args.file;
    let started = Instant::now();
    let mut cloud = read_cloud(path).with_context(|| format!("reading {}", path.display()))?;
    let read_ms = started.elapsed().as_secs_f64() * 1e3;
    out!("file        {}", path.display())?;
    out!("points      {} (read in {read_ms:.1} ms)", cloud.len())?;
    let (kept, dropped) = ReturnFilter::default().apply(cloud);
    cloud = kept;
    out!("non-finite  {} dropped", dropped.non_finite)?;
    if dropped.no_return > 0 {
        out!(
            "no-return   {} dropped (zeros or within 0.1 m)",
            dropped.no_return
        )?;
    }
    out!(
        "channels    ring: {}, intensity: {}, time: {}",
        cloud.ring().is_some(),
        cloud.intensity().is_some(),
        cloud.time().is_some()
    )?;
    if let Some(ring) = cloud.ring() {
        let max = ring.iter().copied().max().unwrap_or(0);
        out!("rings       {}", u32::from(max) + 1)?;
    }
    let Some(bounds) = cloud.bounds() else {
        bail!("{} has no finite points", path.display());
    };
    let e = bounds.extent();
    out!(
        "bounds      x [{:.2}, {:.2}]  y [{:.2}, {:.2}]  z [{:.2}, {:.2}] m",
        bounds.min.x,
        bounds.max.x,
        bounds.min.y,
        bounds.max.y,
        bounds.min.z,
        bounds.max.z
    )?;
    out!("extent      {:.2} x {:.2} x {:.2} m", e.x, e.y, e.z)?;
    let mut ranges: Vec<f32> = cloud.points().iter().map(|p| p.coords.norm()).collect();
    ranges.sort_by(f32::total_cmp);
    let pct = |q: f64| quantile(&ranges, q).unwrap_or(f32::NAN);
    out!(
        "range       min {:.2}  median {:.2}  p99 {:.2}  max {:.2} m",
        pct(0.0),
        pct(0.5),
        pct(0.99),
        pct(1.0)
    )?;
    for voxel in [0.05f32, 0.10, 0.25] {
        let t = Instant::now();
        let down = cloud.voxel_downsample(voxel)?;
        out!(
            "voxel {voxel:.2} m  {} points ({:.1} %) in {:.2} ms",
            down.len(),
            100.0 * down.len() as f64 / cloud.len() as f64,
            t.elapsed().as_secs_f64() * 1e3
        )?;
    }
    Ok(())
}
