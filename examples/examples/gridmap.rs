//! Turn a map cloud into an occupancy grid: writes the ROS map (YAML + PGM) and a PNG picture,
//! and prints cells, occupied cells and milliseconds.
//!
//! `cargo run --release --example gridmap -- MAP_CLOUD --lidar-height H [--resolution R] [--inflate M] --out DIR`
//!
//! For example, on the bundled garage scan (sensor frame, so the LiDAR is at height 0):
//! `cargo run --release --example gridmap -- slam-core/tests/data/hdl32e_garage_1503604882.703390000.pcd --lidar-height 0 --resolution 0.05 --out /tmp/garage`

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Parser;
use gridmap::{
    OccupancyGridBuilder, OccupancyGridConfig, UnknownCells, inflate, write_png, write_ros_map,
};
use slam_core::io::read_cloud;
use spot_nav_examples::out;

/// Turn a map cloud into an occupancy grid (ROS map and PNG picture).
///
/// Writes the ROS map (`map.yaml` + PGM) and a PNG picture (the obstacles inflated for planning
/// drawn over it) to DIR, and prints the cell counts and times.
#[derive(Debug, Parser)]
#[command(name = "gridmap")]
struct Args {
    /// The map cloud: PCD, PLY or KITTI `.bin` (by extension).
    #[arg(value_name = "MAP_CLOUD")]
    cloud: PathBuf,
    /// Height of the LiDAR above the floor in the cloud's frame (metres; 0 for a scan in its
    /// sensor frame): the slice around it becomes the grid.
    #[arg(long, value_name = "H", allow_negative_numbers = true)]
    lidar_height: f64,
    /// Cell size (metres).
    #[arg(
        long,
        value_name = "R",
        allow_negative_numbers = true,
        default_value_t = 0.10
    )]
    resolution: f64,
    /// Inflation radius of the obstacles in the picture (metres).
    #[arg(
        long = "inflate",
        value_name = "M",
        allow_negative_numbers = true,
        default_value_t = 0.25
    )]
    inflate: f64,
    /// Folder for `map.yaml`, its PGM and `map.png` (created when missing).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

fn main() -> ExitCode {
    spot_nav_examples::run(|| grid(&Args::parse()))
}

fn grid(args: &Args) -> Result<()> {
    let (out, resolution, radius) = (&args.out, args.resolution, args.inflate);
    let mut cloud =
        read_cloud(&args.cloud).with_context(|| format!("reading {}", args.cloud.display()))?;
    let dropped = cloud.remove_non_finite();
    let t = Instant::now();
    let builder = OccupancyGridBuilder::new(OccupancyGridConfig {
        resolution,
        ..OccupancyGridConfig::default()
    })?;
    let grid = builder.build(&cloud, args.lidar_height)?;
    let build_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let inflated = inflate(&grid.to_planning_grid(UnknownCells::Free), radius)?;
    let inflate_ms = t.elapsed().as_secs_f64() * 1e3;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let pgm = write_ros_map(&grid, out.join("map.yaml"))?;
    write_png(out.join("map.png"), &grid, Some(&inflated), &[], &[])?;
    let (free, occupied, unknown) = grid.counts();
    out!(
        "cloud      {} points ({dropped} non-finite dropped)",
        cloud.len()
    )?;
    out!(
        "grid       {} x {} = {} cells at {resolution} m",
        grid.width(),
        grid.height(),
        grid.width() as usize * grid.height() as usize
    )?;
    out!(
        "cells      {occupied} occupied, {free} free, {unknown} unknown; {} blocked after {radius} m inflation",
        inflated.count_blocked()
    )?;
    out!("time       build {build_ms:.2} ms, inflate {inflate_ms:.2} ms")?;
    out!(
        "wrote      {}, {}, {}",
        out.join("map.yaml").display(),
        pgm.display(),
        out.join("map.png").display()
    )?;
    Ok(())
}
