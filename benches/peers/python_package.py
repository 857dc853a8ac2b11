"""spot_nav beside small_gicp and KISS-ICP, all three from Python in one process on the same
NumPy arrays (run through python_package.sh, which installs them).

1. Registration, the HDL-32E pair at 0.25 m voxels, point-to-plane ICP: spot_nav.align (its
   defaults: correspondence searches on the machine's cores) and small_gicp.align (PLANE_ICP,
   1 thread as in small_gicp_registration.sh, and 2 threads); preparation and alignment
   together, in turns (ROUNDS rounds of RUNS runs, best and median); errors against small_gicp's
   reference pose and against exact ground truth (two random halves of the target scan, one
   moved by a known transform).
2. SLAM, a folder of scans (LiDAR-only): spot_nav.Slam.register_frame and KISS-ICP's
   register_frame on the same arrays, mean and p99 ms a scan and the ratio; the end pose of
   each. On the static garage sequence (the default) the truth is no motion at all.
"""

import argparse
import os
import pathlib
import sys
import time

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from kiss_icp_peer import read_pcd, read_ply  # noqa: E402
from ply_xyz import read_ply_xyz  # noqa: E402

import small_gicp  # noqa: E402
import spot_nav  # noqa: E402


def pose_error(a, b):
    e = np.linalg.inv(a) @ b
    angle = np.degrees(np.arccos(np.clip((np.trace(e[:3, :3]) - 1) / 2, -1, 1)))
    return np.linalg.norm(e[:3, 3]), angle


def rigid(x, y, z, yaw):
    t = np.eye(4)
    c, s = np.cos(yaw), np.sin(yaw)
    t[:2, :2] = [[c, -s], [s, c]]
    t[:3, 3] = [x, y, z]
    return t


def timed(f):
    start = time.perf_counter()
    out = f()
    return time.perf_counter() - start, out


def registration(args):
    source = read_ply_xyz(args.source)
    target = read_ply_xyz(args.target)
    reference = np.loadtxt(args.reference)
    runners = {
        "spot_nav": lambda s, t: spot_nav.align(s, t).transform,
        "small_gicp 1 thread": lambda s, t: small_gicp.align(
            t, s, registration_type="PLANE_ICP", downsampling_resolution=0.25,
            max_correspondence_distance=1.0, num_threads=1).T_target_source,
        "small_gicp 2 threads": lambda s, t: small_gicp.align(
            t, s, registration_type="PLANE_ICP", downsampling_resolution=0.25,
            max_correspondence_distance=1.0, num_threads=2).T_target_source,
    }
    times = {k: [] for k in runners}
    results = {}
    for name, run in runners.items():  # an untimed run each: page faults, lazy set-up
        results[name] = run(source, target)
    for _ in range(args.rounds):
        for name, run in runners.items():
            for _ in range(args.runs):
                dt, results[name] = timed(lambda: run(source, target))
                times[name].append(dt)
    rng = np.random.default_rng(1)
    mask = rng.random(len(target)) < 0.5
    truth = rigid(0.3, -0.2, 0.05, 0.1)
    half = (target[mask] - truth[:3, 3]) @ truth[:3, :3]  # truth^-1 applied
    print(f"== registration: HDL-32E pair ({len(source)} and {len(target)} points), point-to-plane, "
          f"{args.rounds} rounds x {args.runs} runs in turns; spot_nav's pool has "
          f"{os.environ.get('RAYON_NUM_THREADS', os.cpu_count())} threads")
    ours_best = min(times["spot_nav"])
    ours_median = float(np.median(times["spot_nav"]))
    for name in runners:
        best, median = min(times[name]), float(np.median(times[name]))
        t, r = pose_error(reference, results[name])
        ht, hr = pose_error(truth, runners[name](half, target[~mask]))
        ratio = "" if name == "spot_nav" else (
            f"; spot_nav / this: best {ours_best / best:.2f}, median {ours_median / median:.2f}")
        print(f"{name:22s} best {best * 1e3:6.1f} ms, median {median * 1e3:6.1f} ms; "
              f"vs reference {t:.4f} m {r:.3f} deg; halves vs truth {ht * 1e3:.2f} mm {hr:.4f} deg"
              f"{ratio}")


def read_scan(path):
    """x, y, z (n, 3 float64) and the per-point times (n float64, or empty) of a scan file."""
    points, times = (read_pcd if path.suffix.lower() == ".pcd" else read_ply)(path)
    return np.ascontiguousarray(points, dtype=np.float64), np.asarray(times, dtype=np.float64)


def slam(args):
    folder = pathlib.Path(args.scans)
    if not folder.is_dir():
        print(f"== SLAM: skipped, no scans folder at {folder} (set SPOT_NAV_DATA or pass one)")
        return
    files = sorted(p for p in folder.iterdir() if p.suffix.lower() in (".pcd", ".ply"))
    scans = [read_scan(p) for p in files]
    stamps = [float(p.stem) for p in files]
    from kiss_icp.config import load_config
    from kiss_icp.kiss_icp import KissICP
    ours_ms, kiss_ms, engine_ms = [], [], []
    # Scans with per-point times (a skewed sweep) are deskewed by both: ours gets them as
    # `point_times`, KISS-ICP as its timestamps; without them neither deskews.
    timed_scans = sum(1 for _, times in scans if len(times))
    for _ in range(args.rounds):
        ours = spot_nav.Slam()
        kiss = KissICP(config=load_config(None))
        for stamp, (points, times) in zip(stamps, scans):
            point_times = times.astype(np.float32) if len(times) else None
            dt, _ = timed(lambda: ours.register_frame(
                points, stamp=stamp - stamps[0], point_times=point_times))
            ours_ms.append(dt * 1e3)
            dt, _ = timed(lambda: kiss.register_frame(points, times))
            kiss_ms.append(dt * 1e3)
        engine_ms.append(ours.report()["mean_scan_ms"])
    ours_end = ours.poses[-1] if len(ours.poses) else np.eye(4)
    kiss_end = kiss.last_pose
    print(f"== SLAM, LiDAR-only: {len(scans)} scans of {folder.name} ({timed_scans} of them with "
          f"per-point times, which both deskew with), {args.rounds} rounds in turns (KISS-ICP: its "
          f"defaults, register_frame alone)")
    for name, ms, end in [("spot_nav Slam", ours_ms, ours_end), ("KISS-ICP", kiss_ms, kiss_end)]:
        t, r = pose_error(np.eye(4), end)
        print(f"{name:14s} mean {np.mean(ms):6.2f} ms, p99 {np.percentile(ms, 99):6.2f} ms a scan; "
              f"end pose {t * 100:.2f} cm {r:.3f} deg from the start")
    print(f"spot_nav / KISS-ICP, mean ms a scan: {np.mean(ours_ms) / np.mean(kiss_ms):.2f} "
          f"(the engine's own mean inside register_frame: {np.mean(engine_ms):.2f} ms; the rest is "
          f"reading the array and the binding)")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--source", required=True)
    p.add_argument("--target", required=True)
    p.add_argument("--reference", required=True)
    p.add_argument("--scans", default="")
    p.add_argument("--rounds", type=int, default=int(os.environ.get("ROUNDS", 5)))
    p.add_argument("--runs", type=int, default=4)
    args = p.parse_args()
    print(f"spot_nav {spot_nav.__version__}, small_gicp, kiss_icp; numpy {np.__version__}; "
          f"{os.cpu_count()} cores")
    registration(args)
    slam(args)


if __name__ == "__main__":
    main()
