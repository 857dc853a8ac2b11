//! Turn a map cloud into an occupancy grid: writes the ROS map (YAML + PGM) and a PNG picture,
//! and prints cells, occupied cells and milliseconds.
//!
//! `cargo run --release --example gridmap -- MAP_CLOUD --lidar-height H [--resolution R] [--inflate M] --out DIR`
//!
//! For example, on the bundled garage scan (sensor frame, so the LiDAR is at height 0):
//! `cargo run --release --example gridmap -- slam-core/tests/data/hdl32e_garage_1503604882.703390000.pcd --lidar-height 0 --resolution 0.05 --out /tmp/garage`

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use gridmap::{
    OccupancyGridBuilder, OccupancyGridConfig, UnknownCells, inflate, write_png, write_ros_map,
};
use slam_core::PointCloud;
use slam_core::io::{read_kitti_bin, read_pcd, read_ply};

const USAGE: &str =
    "usage: gridmap MAP_CLOUD --lidar-height H [--resolution R] [--inflate M] --out DIR";

fn read_any(path: &Path) -> Result<PointCloud> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    Ok(match ext.as_str() {
        "pcd" => read_pcd(path)?,
        "ply" => read_ply(path)?,
        "bin" => read_kitti_bin(path)?,
        other => bail!("unknown cloud extension {other:?} (pcd, ply or bin)"),
    })
}

fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    let (mut cloud_path, mut height, mut out) = (None, None, None);
    let (mut resolution, mut radius) = (0.10f64, 0.25f64);
    while let Some(a) = args.next() {
        let mut value = |name: &str| {
            args.next()
                .with_context(|| format!("{name} needs a value; {USAGE}"))
        };
        match a.as_str() {
            "--lidar-height" => height = Some(value("--lidar-height")?.parse::<f64>()?),
            "--resolution" => resolution = value("--resolution")?.parse()?,
            "--inflate" => radius = value("--inflate")?.parse()?,
            "--out" => out = Some(PathBuf::from(value("--out")?)),
            "-h" | "--help" => {
                println!("{USAGE}");
                return Ok(());
            }
            _ if cloud_path.is_none() => cloud_path = Some(PathBuf::from(a)),
            _ => bail!("unexpected argument {a:?}; {USAGE}"),
        }
    }
    let (Some(cloud_path), Some(height), Some(out)) = (cloud_path, height, out) else {
        bail!("{USAGE}")
    };
    let mut cloud =
        read_any(&cloud_path).with_context(|| format!("reading {}", cloud_path.display()))?;
    let dropped = cloud.remove_non_finite();
    let t = Instant::now();
    let builder = OccupancyGridBuilder::new(OccupancyGridConfig {
        resolution,
        ..OccupancyGridConfig::default()
    })?;
    let grid = builder.build(&cloud, height)?;
    let build_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let inflated = inflate(&grid.to_planning_grid(UnknownCells::Free), radius);
    let inflate_ms = t.elapsed().as_secs_f64() * 1e3;
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let pgm = write_ros_map(&grid, out.join("map.yaml"))?;
    write_png(out.join("map.png"), &grid, Some(&inflated), &[], &[])?;
    let (free, occupied, unknown) = grid.counts();
    println!(
        "cloud      {} points ({dropped} non-finite dropped)",
        cloud.len()
    );
    println!(
        "grid       {} x {} = {} cells at {resolution} m",
        grid.width(),
        grid.height(),
        grid.width() as usize * grid.height() as usize
    );
    println!(
        "cells      {occupied} occupied, {free} free, {unknown} unknown; {} blocked after {radius} m inflation",
        inflated.count_blocked()
    );
    println!("time       build {build_ms:.2} ms, inflate {inflate_ms:.2} ms");
    println!(
        "wrote      {}, {}, {}",
        out.join("map.yaml").display(),
        pgm.display(),
        out.join("map.png").display()
    );
    Ok(())
}
