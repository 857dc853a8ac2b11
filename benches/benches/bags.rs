//! Reading a ROS 2 bag (MCAP, zstd chunks) against the SLAM it feeds: the time to read and
//! decode one scan's messages (cloud, odometry, tf) against the engine's time for that scan; the
//! time reading adds to the engine's when the bag is read ahead on a thread of its own
//! (`ReadAhead`, as the `slam` example reads); one cloud message's decoding alone; and the peak
//! memory of reading a bag against one twice as long (each read in a child process).
//!
//! The bag holds the first scans of a simulated lap (seed 1), written with the `mcap` crate
//! (zstd chunks, and once uncompressed as `ros2 bag record` writes by default) and a CDR encoder
//! below. `cargo bench -p spot-nav-benches --bench bags`

use std::borrow::Borrow;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use criterion::{BenchmarkId, Criterion, Throughput};
use slam_core::Pose3;
use spot_adapter::pipelines::{point_to_plane_slam, slam_config};
use spot_adapter::record::{
    Bag, BagConfig, PointCloud2, PointCloud2Config, PointCloud2Decoder, ReadAhead, Wire,
};
use spot_adapter::robot::Sample;
use spot_adapter::sim::{SimulatedSpot, SimulationConfig};

/// Scans of the short bag; the long one has twice as many.
const SHORT: usize = 60;
/// Environment variable that makes the bench a child reading one bag and reporting its peak.
const CHILD: &str = "SPOT_NAV_BAG_MEMORY_CHILD";

/// Stop the bench with `e` on stderr.
fn fail(e: &dyn std::fmt::Display) -> ! {
    eprintln!("bags bench: {e}");
    std::process::exit(1)
}

/// Little-endian CDR, aligned from after the 4-byte encapsulation header.
struct Cdr(Vec<u8>);

impl Cdr {
    fn new() -> Self {
        Self(vec![0, 1, 0, 0])
    }
    fn align(&mut self, n: usize) {
        while !(self.0.len() - 4).is_multiple_of(n) {
            self.0.push(0);
        }
    }
    fn u8(&mut self, v: u8) {
        self.0.push(v);
    }
    fn u32(&mut self, v: u32) {
        self.align(4);
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f64(&mut self, v: f64) {
        self.align(8);
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn string(&mut self, s: &str) {
        self.u32(s.len() as u32 + 1);
        self.0.extend_from_slice(s.as_bytes());
        self.0.push(0);
    }
    fn header(&mut self, stamp: f64, frame: &str) {
        let sec = stamp.floor();
        self.u32(sec as u32);
        self.u32(((stamp - sec) * 1e9).round() as u32);
        self.string(frame);
    }
    fn pose(&mut self, p: &Pose3) {
        let t = p.translation.vector;
        let q = p.rotation;
        for v in [t.x, t.y, t.z, q.i, q.j, q.k, q.w] {
            self.f64(v);
        }
    }
}

fn cloud_message(s: &Sample) -> Vec<u8> {
    let mut w = Cdr::new();
    w.header(s.stamp, "velodyne");
    let c = &s.cloud;
    w.u32(1);
    w.u32(c.len() as u32);
    let fields = [
        ("x", 0, 7),
        ("y", 4, 7),
        ("z", 8, 7),
        ("ring", 12, 4),
        ("time", 16, 7),
    ];
    w.u32(fields.len() as u32);
    for (name, offset, datatype) in fields {
        w.string(name);
        w.u32(offset);
        w.u8(datatype);
        w.u32(1);
    }
    w.u8(0);
    w.u32(20);
    w.u32(20 * c.len() as u32);
    w.u32(20 * c.len() as u32);
    let ring = c.ring().unwrap_or(&[]);
    let time = c.time().unwrap_or(&[]);
    for (i, p) in c.points().iter().enumerate() {
        for v in [p.x, p.y, p.z] {
            w.0.extend_from_slice(&v.to_le_bytes());
        }
        w.0.extend_from_slice(&ring.get(i).copied().unwrap_or(0).to_le_bytes());
        w.0.extend_from_slice(&[0, 0]);
        w.0.extend_from_slice(&time.get(i).copied().unwrap_or(0.0).to_le_bytes());
    }
    w.u8(0);
    w.0
}

fn odometry_message(s: &Sample) -> Vec<u8> {
    let mut w = Cdr::new();
    w.header(s.stamp, "odom");
    w.string("base_link");
    w.pose(&s.odom_t_body);
    for _ in 0..(36 + 6 + 36) {
        w.f64(0.0);
    }
    w.0
}

fn tf_message(stamp: f64, parent: &str, child: &str, pose: &Pose3) -> Vec<u8> {
    let mut w = Cdr::new();
    w.u32(1);
    w.header(stamp, parent);
    w.string(child);
    w.pose(pose);
    w.0
}

/// A bag of the first `scans` scans of the lap, its chunks compressed with `compression`.
fn write_bag(
    path: &Path,
    scans: usize,
    compression: Option<mcap::Compression>,
) -> mcap::McapResult<()> {
    let sim =
        SimulatedSpot::corridor_loop(&SimulationConfig::with_seed(1)).unwrap_or_else(|e| fail(&e));
    let body_t_lidar = sim.body_t_lidar();
    let mut out = mcap::WriteOptions::new()
        .compression(compression)
        .create(BufWriter::new(File::create(path)?))?;
    let none = BTreeMap::new();
    let channel = |out: &mut mcap::Writer<_>, topic: &str, ty: &str| -> mcap::McapResult<u16> {
        let schema = out.add_schema(ty, "ros2msg", b"")?;
        out.add_channel(schema, topic, "cdr", &none)
    };
    let clouds = channel(&mut out, "/points", "sensor_msgs/msg/PointCloud2")?;
    let odom = channel(&mut out, "/odom", "nav_msgs/msg/Odometry")?;
    let tf_static = channel(&mut out, "/tf_static", "tf2_msgs/msg/TFMessage")?;
    let write = |out: &mut mcap::Writer<_>, id, stamp: f64, data: &[u8]| {
        let t = (stamp * 1e9) as u64;
        let header = mcap::records::MessageHeader {
            channel_id: id,
            sequence: 0,
            log_time: t,
            publish_time: t,
        };
        out.write_to_known_channel(&header, data)
    };
    write(
        &mut out,
        tf_static,
        0.0,
        &tf_message(0.0, "base_link", "velodyne", &body_t_lidar),
    )?;
    for s in sim.take(scans) {
        write(&mut out, odom, s.stamp, &odometry_message(&s))?;
        write(&mut out, clouds, s.stamp, &cloud_message(&s))?;
    }
    out.finish()?;
    Ok(())
}

/// The engine run on `samples`; how many there were.
fn slam_on<S: Borrow<Sample>>(samples: impl Iterator<Item = S>) -> usize {
    let mut slam = point_to_plane_slam(slam_config()).unwrap_or_else(|e| fail(&e));
    let mut n = 0;
    for s in samples {
        slam.process(&s.borrow().scan_input());
        n += 1;
    }
    n
}

fn open(path: &Path) -> Bag {
    Bag::open(path, &BagConfig::default()).unwrap_or_else(|e| fail(&e))
}

/// Peak resident memory of this process (kB), from /proc.
fn peak_kb() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("VmHWM:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        })
        .unwrap_or(0)
}

/// The child's peak after reading every sample of the bag at `path`.
fn child_peak(path: &Path) -> u64 {
    let exe = std::env::current_exe().unwrap_or_else(|e| fail(&e));
    let out = Command::new(exe)
        .env(CHILD, path)
        .output()
        .unwrap_or_else(|e| fail(&e));
    String::from_utf8_lossy(&out.stdout)
        .trim()
        .parse()
        .unwrap_or_else(|_| fail(&String::from_utf8_lossy(&out.stderr)))
}

/// Reading against SLAM, per scan: reading alone (the zstd bag `bag`, the uncompressed one at
/// `plain`), SLAM on `samples` in memory, and SLAM fed by `bag` read ahead on a thread of its
/// own (what the `slam` example does). Runs alternate and medians of 9 are taken, of the
/// difference per pair of runs for the read-ahead, as the machine's speed drifts between runs.
fn read_against_slam(bag: &Bag, plain: &Path, samples: &[Sample]) {
    let per_scan = |f: &mut dyn FnMut() -> usize| {
        let started = Instant::now();
        let n = f();
        started.elapsed().as_secs_f64() * 1e3 / n as f64
    };
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let plain_bag = open(plain);
    let (mut read, mut read_plain, mut slam, mut added) = (vec![], vec![], vec![], vec![]);
    for _ in 0..9 {
        read_plain.push(per_scan(&mut || {
            plain_bag.samples().unwrap_or_else(|e| fail(&e)).count()
        }));
        read.push(per_scan(&mut || {
            bag.samples().unwrap_or_else(|e| fail(&e)).count()
        }));
        let in_memory = per_scan(&mut || slam_on(samples.iter()));
        let ahead = per_scan(&mut || {
            let source = ReadAhead::new(bag.samples().unwrap_or_else(|e| fail(&e)), 4);
            slam_on(source.map(|s| s.unwrap_or_else(|e| fail(&e))))
        });
        slam.push(in_memory);
        added.push(ahead - in_memory);
    }
    let (read_ms, slam_ms, added_ms) = (median(read), median(slam), median(added));
    let plain_ms = median(read_plain);
    println!(
        "bags/read_vs_slam: reading {read_ms:.2} ms per scan (zstd), {plain_ms:.2} ms (uncompressed), SLAM {slam_ms:.2} ms per scan: reading is {:.1} % (zstd), {:.1} % (uncompressed) of SLAM",
        100.0 * read_ms / slam_ms,
        100.0 * plain_ms / slam_ms
    );
    println!(
        "bags/read_ahead: SLAM fed by the bag read ahead takes {added_ms:+.2} ms per scan more than on samples in memory ({:+.1} % of SLAM; median of 9 paired runs)",
        100.0 * added_ms / slam_ms
    );
}

fn main() {
    if let Some(path) = std::env::var_os(CHILD) {
        let bag = open(Path::new(&path));
        for sample in bag.samples().unwrap_or_else(|e| fail(&e)) {
            sample.unwrap_or_else(|e| fail(&e));
        }
        println!("{}", peak_kb());
        return;
    }
    let dir = std::env::temp_dir().join(format!("spot-nav-bag-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| fail(&e));
    let short: PathBuf = dir.join("short.mcap");
    let long: PathBuf = dir.join("long.mcap");
    let plain: PathBuf = dir.join("uncompressed.mcap");
    let zstd = Some(mcap::Compression::Zstd);
    write_bag(&short, SHORT, zstd).unwrap_or_else(|e| fail(&e));
    write_bag(&long, 2 * SHORT, zstd).unwrap_or_else(|e| fail(&e));
    write_bag(&plain, SHORT, None).unwrap_or_else(|e| fail(&e));

    let (a, b) = (child_peak(&short), child_peak(&long));
    let mb = |p: &Path| std::fs::metadata(p).map_or(0.0, |m| m.len() as f64 / 1e6);
    println!(
        "bags/peak_memory: {SHORT} scans ({:.1} MB file) {:.1} MB peak, {} scans ({:.1} MB file) {:.1} MB peak: ratio {:.3}",
        mb(&short),
        a as f64 / 1e3,
        2 * SHORT,
        mb(&long),
        b as f64 / 1e3,
        b as f64 / a as f64
    );

    let bag = open(&short);
    let samples: Vec<Sample> = bag
        .samples()
        .unwrap_or_else(|e| fail(&e))
        .map(|s| s.unwrap_or_else(|e| fail(&e)))
        .collect();
    read_against_slam(&bag, &plain, &samples);

    let mut c = Criterion::default().configure_from_args();
    let mut group = c.benchmark_group("bags");
    group.sample_size(10);
    group.throughput(Throughput::Elements(SHORT as u64));
    group.bench_with_input(
        BenchmarkId::new("read_mcap_zstd", SHORT),
        &short,
        |b, path| {
            let bag = open(path);
            b.iter(|| bag.samples().unwrap_or_else(|e| fail(&e)).count());
        },
    );
    group.bench_with_input(
        BenchmarkId::new("read_mcap_uncompressed", SHORT),
        &plain,
        |b, path| {
            let bag = open(path);
            b.iter(|| bag.samples().unwrap_or_else(|e| fail(&e)).count());
        },
    );
    // One scan's cloud message parsed and decoded, the part of reading that is ours.
    let message = cloud_message(&samples[SHORT / 2]);
    group.throughput(Throughput::Elements(1));
    group.bench_with_input(
        BenchmarkId::new("decode_point_cloud2", samples[SHORT / 2].cloud.len()),
        &message,
        |b, message| {
            let mut decoder = PointCloud2Decoder::new(PointCloud2Config::default());
            b.iter(|| {
                let msg = PointCloud2::parse(message, Wire::Cdr).unwrap_or_else(|e| fail(&e));
                decoder
                    .decode(&msg)
                    .unwrap_or_else(|e| fail(&e))
                    .cloud
                    .len()
            });
        },
    );
    group.throughput(Throughput::Elements(SHORT as u64));
    group.bench_with_input(BenchmarkId::new("slam", SHORT), &samples, |b, samples| {
        b.iter(|| slam_on(samples.iter()));
    });
    group.bench_with_input(
        BenchmarkId::new("slam_read_ahead_zstd", SHORT),
        &short,
        |b, path| {
            let bag = open(path);
            b.iter(|| {
                let source = ReadAhead::new(bag.samples().unwrap_or_else(|e| fail(&e)), 4);
                slam_on(source.map(|s| s.unwrap_or_else(|e| fail(&e))))
            });
        },
    );
    group.finish();
    c.final_summary();
    let _ = std::fs::remove_dir_all(&dir);
}
