"""KISS-ICP 1.3.0 beside spot-nav's `slam --no-odometry` on one folder of scans, both against the
same ground truth with the same code (`evaluate` below, one Python function for both).

Run through kiss_icp.sh, which runs our example first and installs kiss-icp==1.3.0 from PyPI in
a venv. This script runs KISS-ICP (its Python API, `KissICP(KISSConfig)`, `register_frame(points,
timestamps)` per scan, its defaults unless --max-range / --voxel-size / --threads say otherwise;
only `register_frame` is timed, not reading the files), evaluates both trajectories and prints
them side by side.

Usage:
  python kiss_icp_peer.py SCANS_DIR GROUND_TRUTH OURS_DIR [--max-range M] [--voxel-size M]
                     [--threads N] [--calibration tx,ty,tz,qx,qy,qz,qw] [--write-tum PATH]
  python kiss_icp_peer.py --selftest GOLDEN_DIR   (evaluate() against evo's figures, see below)

SCANS_DIR: PCD or PLY scans, one a file; names that are numbers are stamps (seconds), else the
scans are 10 Hz from 0 in name order (as spot-nav reads such a folder). GROUND_TRUTH: TUM (8
numbers a line) or KITTI poses (12, one a scan), of the body (= the LiDAR without
--calibration). OURS_DIR: what `slam --out` wrote (trajectory.tum, summary.json).
"""

import argparse
import json
import struct
import sys
import time
from pathlib import Path

import numpy as np

TIME_FIELDS = ("t", "time", "timestamp", "timestamps", "stamps")
KITTI_LENGTHS = (100.0, 200.0, 300.0, 400.0, 500.0, 600.0, 700.0, 800.0)


# ---------------------------------------------------------------- reading scans

def _lzf_decompress(data, size):
    """PCL's binary_compressed blocks (LZF)."""
    out = bytearray()
    i = 0
    while i < len(data):
        ctrl = data[i]
        i += 1
        if ctrl < 32:
            out += data[i:i + ctrl + 1]
            i += ctrl + 1
        else:
            length = ctrl >> 5
            ref = len(out) - ((ctrl & 0x1F) << 8) - 1
            if length == 7:
                length += data[i]
                i += 1
            ref -= data[i]
            i += 1
            for _ in range(length + 2):
                out.append(out[ref])
                ref += 1
    if len(out) != size:
        raise ValueError(f"LZF block gave {len(out)} bytes, {size} expected")
    return bytes(out)


def _numpy_type(kind, size):
    return {("F", 4): "f4", ("F", 8): "f8", ("U", 1): "u1", ("U", 2): "u2", ("U", 4): "u4",
            ("U", 8): "u8", ("I", 1): "i1", ("I", 2): "i2", ("I", 4): "i4",
            ("I", 8): "i8"}[(kind, size)]


def read_pcd(path):
    """x, y, z (n, 3 float64) and the per-point times (n, or empty) of a PCD file."""
    raw = Path(path).read_bytes()
    header, offset = {}, 0
    while True:
        end = raw.index(b"\n", offset)
        line = raw[offset:end].decode("ascii").strip()
        offset = end + 1
        if not line or line.startswith("#"):
            continue
        key, *values = line.split()
        header[key.upper()] = values
        if key.upper() == "DATA":
            break
    names, sizes = header["FIELDS"], [int(s) for s in header["SIZE"]]
    kinds = header["TYPE"]
    counts = [int(c) for c in header.get("COUNT", ["1"] * len(names))]
    n = int(header["POINTS"][0])
    dtype = np.dtype([(f"{name}_{k}", _numpy_type(kind, size), (count,))
                      for k, (name, kind, size, count) in enumerate(zip(names, kinds, sizes,
                                                                        counts))])
    data = header["DATA"][0]
    if data == "ascii":
        table = np.loadtxt(raw[offset:].decode("ascii").splitlines(), ndmin=2)
        columns, k = {}, 0
        for name, count in zip(names, counts):
            columns.setdefault(name, table[:, k])
            k += count
    elif data == "binary":
        records = np.frombuffer(raw, dtype=dtype, count=n, offset=offset)
        columns = {}
        for k, name in enumerate(names):
            columns.setdefault(name, records[f"{name}_{k}"][:, 0])
    elif data == "binary_compressed":
        compressed, size = struct.unpack_from("<II", raw, offset)
        block = _lzf_decompress(raw[offset + 8:offset + 8 + compressed], size)
        columns, start = {}, 0
        for name, kind, width, count in zip(names, kinds, sizes, counts):
            length = n * width * count
            values = np.frombuffer(block[start:start + length], dtype=_numpy_type(kind, width))
            columns.setdefault(name, values.reshape(n, count)[:, 0])
            start += length
    else:
        raise ValueError(f"{path}: DATA {data} is not read")
    return _points_and_times(path, columns)


def read_ply(path):
    """x, y, z (n, 3 float64) and the per-point times (n, or empty) of a PLY file's vertices."""
    raw = Path(path).read_bytes()
    end = raw.index(b"end_header") + len(b"end_header")
    end = raw.index(b"\n", end) + 1
    lines = raw[:end].decode("ascii").splitlines()
    fmt, n, props, in_vertex = None, 0, [], False
    types = {"float": "f4", "float32": "f4", "double": "f8", "float64": "f8", "uchar": "u1",
             "uint8": "u1", "char": "i1", "int8": "i1", "ushort": "u2", "uint16": "u2",
             "short": "i2", "int16": "i2", "uint": "u4", "uint32": "u4", "int": "i4",
             "int32": "i4"}
    for line in lines:
        words = line.split()
        if words[:1] == ["format"]:
            fmt = words[1]
        elif words[:1] == ["element"]:
            in_vertex = words[1] == "vertex"
            if in_vertex:
                n = int(words[2])
        elif words[:1] == ["property"] and in_vertex:
            if words[1] == "list":
                raise ValueError(f"{path}: list properties in vertices are not read")
            props.append((words[2], types[words[1]]))
    if fmt == "ascii":
        table = np.loadtxt(raw[end:].decode("ascii").splitlines()[:n], ndmin=2)
        columns = {name: table[:, k] for k, (name, _) in enumerate(props)}
    else:
        order = "<" if fmt == "binary_little_endian" else ">"
        dtype = np.dtype([(name, order + kind) for name, kind in props])
        records = np.frombuffer(raw, dtype=dtype, count=n, offset=end)
        columns = {name: records[name] for name, _ in props}
    return _points_and_times(path, columns)


def _points_and_times(path, columns):
    if not all(axis in columns for axis in "xyz"):
        raise ValueError(f"{path}: no x, y, z fields")
    points = np.stack([columns[a].astype(np.float64) for a in "xyz"], axis=1)
    field = next((f for f in TIME_FIELDS if f in columns), None)
    times = columns[field].astype(np.float64) if field else np.array([])
    return points, times


def scan_files(folder):
    """The folder's scans in order, with their stamps (names that are numbers, else 10 Hz)."""
    files = [p for p in Path(folder).iterdir()
             if p.is_file() and p.suffix.lower() in (".pcd", ".ply")]
    if not files:
        raise ValueError(f"{folder}: no .pcd or .ply file")
    try:
        stamped = sorted((float(p.stem), p) for p in files)
        stamps = [s for s, _ in stamped]
        if all(b > a for a, b in zip(stamps, stamps[1:])):
            return [p for _, p in stamped], np.array(stamps)
    except ValueError:
        pass
    files.sort()
    return files, 0.1 * np.arange(len(files))


# ---------------------------------------------------------------- trajectories

def quaternion_matrix(qx, qy, qz, qw):
    q = np.array([qw, qx, qy, qz], dtype=float)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def pose(values):
    """A 4x4 pose from tx ty tz qx qy qz qw."""
    p = np.eye(4)
    p[:3, :3] = quaternion_matrix(*values[3:7])
    p[:3, 3] = values[:3]
    return p


def read_trajectory(path, scan_stamps=None):
    """(stamps, poses) of a TUM file, or of KITTI poses stamped with `scan_stamps`."""
    rows = []
    for number, line in enumerate(Path(path).read_text().splitlines(), 1):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        try:
            rows.append([float(v) for v in line.split()])
        except ValueError as e:
            raise ValueError(f"{path}: line {number}: {e}") from None
        if len(rows[-1]) != len(rows[0]) or len(rows[0]) not in (8, 12):
            raise ValueError(f"{path}: line {number}: {len(rows[-1])} numbers; TUM has 8, "
                             "KITTI poses 12")
    if not rows:
        raise ValueError(f"{path}: no pose")
    if len(rows[0]) == 8:
        return np.array([r[0] for r in rows]), [pose(r[1:]) for r in rows]
    if scan_stamps is None or len(scan_stamps) != len(rows):
        raise ValueError(f"{path}: {len(rows)} KITTI poses for "
                         f"{'no' if scan_stamps is None else len(scan_stamps)} scans")
    poses = []
    for r in rows:
        p = np.eye(4)
        p[:3, :] = np.array(r).reshape(3, 4)
        poses.append(p)
    return np.array(scan_stamps), poses


def write_tum(path, stamps, poses):
    with open(path, "w") as f:
        f.write("# timestamp tx ty tz qx qy qz qw\n")
        for s, p in zip(stamps, poses):
            r = p[:3, :3]
            w = np.sqrt(max(0.0, 1 + np.trace(r))) / 2
            x = np.copysign(np.sqrt(max(0.0, 1 + r[0, 0] - r[1, 1] - r[2, 2])) / 2, r[2, 1] - r[1, 2])
            y = np.copysign(np.sqrt(max(0.0, 1 - r[0, 0] + r[1, 1] - r[2, 2])) / 2, r[0, 2] - r[2, 0])
            z = np.copysign(np.sqrt(max(0.0, 1 - r[0, 0] - r[1, 1] + r[2, 2])) / 2, r[1, 0] - r[0, 1])
            f.write(" ".join(repr(float(v)) for v in [s, *p[:3, 3], x, y, z, w]) + "\n")


# ---------------------------------------------------------------- evaluation

def associate(est_stamps, ref_stamps, max_dt=0.01):
    """(estimate, reference) index pairs: the nearest reference stamp within max_dt of each
    estimate stamp, each reference used once (evo's nearest-time matching)."""
    pairs, used = [], set()
    for i, s in enumerate(est_stamps):
        j = int(np.argmin(np.abs(ref_stamps - s)))
        if abs(ref_stamps[j] - s) <= max_dt and j not in used:
            pairs.append((i, j))
            used.add(j)
    return pairs


def umeyama(source, target):
    """The rigid transform (4x4) taking source points (n, 3) onto target's, least squares."""
    ms, mt = source.mean(axis=0), target.mean(axis=0)
    u, _, vt = np.linalg.svd((target - mt).T @ (source - ms))
    s = np.eye(3)
    if np.linalg.det(u) * np.linalg.det(vt) < 0:
        s[2, 2] = -1
    r = u @ s @ vt
    t = np.eye(4)
    t[:3, :3], t[:3, 3] = r, mt - r @ ms
    return t


def angle(r):
    return float(np.arccos(np.clip((np.trace(r) - 1) / 2, -1.0, 1.0)))


def kitti_rpe(est, ref):
    """KITTI's devkit segment error: lengths 100-800 m (scaled down by the largest power of ten
    that fits a shorter path), segments from every 10th pose, each ending at the first pose more
    than its length further along the reference path. (% , deg per 100 m, lengths, segments)."""
    dist = np.concatenate([[0.0], np.cumsum([np.linalg.norm(ref[k][:3, 3] - ref[k - 1][:3, 3])
                                             for k in range(1, len(ref))])])
    divisor = 1.0
    while KITTI_LENGTHS[0] / divisor >= dist[-1]:
        divisor *= 10.0
        if divisor > 1e5:
            return None
    errors, lengths = [], []
    for length in (l / divisor for l in KITTI_LENGTHS):
        for first in range(0, len(ref), 10):
            last = next((k for k in range(first, len(ref)) if dist[k] > dist[first] + length), None)
            if last is None:
                break
            e = np.linalg.inv(np.linalg.inv(est[first]) @ est[last]) @ (
                np.linalg.inv(ref[first]) @ ref[last])
            errors.append((np.linalg.norm(e[:3, 3]) / length, angle(e[:3, :3]) / length))
            if length not in lengths:
                lengths.append(length)
    if not errors:
        return None
    errors = np.array(errors)
    return (100 * errors[:, 0].mean(), 100 * np.degrees(errors[:, 1].mean()), lengths,
            len(errors))


def evaluate(est_stamps, est_poses, ref_stamps, ref_poses):
    """Every figure of an estimate against the reference, as spot-nav's eval computes them."""
    pairs = associate(est_stamps, ref_stamps)
    if len(pairs) < 3:
        raise ValueError(f"only {len(pairs)} poses matched by stamp (3 needed)")
    est = [est_poses[i] for i, _ in pairs]
    ref = [ref_poses[j] for _, j in pairs]
    e_xyz = np.array([p[:3, 3] for p in est])
    r_xyz = np.array([p[:3, 3] for p in ref])
    align = umeyama(e_xyz, r_xyz)
    residuals = np.linalg.norm((align[:3, :3] @ e_xyz.T).T + align[:3, 3] - r_xyz, axis=1)
    path = float(np.sum(np.linalg.norm(np.diff(r_xyz, axis=0), axis=1)))
    # First poses aligned: the estimate moved so that its first pose is the truth's.
    start = ref[0] @ np.linalg.inv(est[0])
    end = start @ est[-1]
    end_error = float(np.linalg.norm(end[:3, 3] - ref[-1][:3, 3]))
    steps = [np.degrees(angle((np.linalg.inv(np.linalg.inv(est[k]) @ est[k + 1])
                               @ (np.linalg.inv(ref[k]) @ ref[k + 1]))[:3, :3]))
             for k in range(len(est) - 1)]
    return {
        "pairs": len(pairs),
        "ate": float(np.sqrt(np.mean(residuals ** 2))),
        "ate_mean": float(np.mean(residuals)),
        "ate_max": float(np.max(residuals)),
        "path": path,
        "end_point": end_error,
        "end_point_percent": 100 * end_error / path if path > 0 else None,
        "height": float(end[2, 3] - ref[-1][2, 3]),
        "rpe": kitti_rpe(est, ref),
        "steps": np.array(steps),
    }


# ---------------------------------------------------------------- the comparison

def run_kiss(files, stamps, args):
    from kiss_icp.config import load_config
    from kiss_icp.kiss_icp import KissICP
    config = load_config(None)
    if args.max_range is not None:
        config.data.max_range = args.max_range
        if args.voxel_size is None:
            config.mapping.voxel_size = args.max_range / 100.0
    if args.voxel_size is not None:
        config.mapping.voxel_size = args.voxel_size
    if args.threads is not None:
        config.registration.max_num_threads = args.threads
    odometry = KissICP(config=config)
    poses, times = [], []
    for path in files:
        points, point_times = (read_pcd if path.suffix.lower() == ".pcd" else read_ply)(path)
        start = time.perf_counter_ns()
        odometry.register_frame(points, point_times)
        times.append((time.perf_counter_ns() - start) * 1e-6)
        poses.append(odometry.last_pose.copy())
    return poses, np.array(times), config


def calibration_pose(text):
    if text is None:
        return np.eye(4)
    return pose([float(v) for v in text.split(",")])


def figure(value, digits=3, unit=""):
    return "n/a" if value is None else f"{value:.{digits}f}{unit}"


def describe(e):
    rpe = e["rpe"]
    if rpe is None:
        rpe_text = "none (the truth moved too little for any segment)"
    else:
        lengths = (f"{rpe[2][0]:g}-{rpe[2][-1]:g} m" if len(rpe[2]) > 1 else f"{rpe[2][0]:g} m")
        rpe_text = f"{rpe[0]:.3f} % ({lengths}, {rpe[3]} segments)"
    return {
        "end-point drift": f"{e['end_point']:.3f} m, {figure(e['end_point_percent'])} % of "
                           f"{e['path']:.1f} m",
        "ATE (RMSE, SE(3)-aligned)": f"{e['ate']:.4f} m over {e['pairs']} poses",
        "RPE per 100 m (KITTI)": rpe_text,
        "height drift": f"{e['height']:+.3f} m",
        "steps > 2 / > 5 deg": f"{int(np.sum(e['steps'] > 2))} / {int(np.sum(e['steps'] > 5))} "
                               f"of {len(e['steps'])} (max {np.max(e['steps'], initial=0):.2f} deg)",
    }


def compare(args):
    files, stamps = scan_files(args.scans)
    ref_stamps, ref_poses = read_trajectory(args.ground_truth, stamps)
    ours_dir = Path(args.ours)
    summary = json.loads((ours_dir / "summary.json").read_text())
    our_stamps, our_poses = read_trajectory(ours_dir / "trajectory.tum")
    kiss_poses, kiss_ms, config = run_kiss(files, stamps, args)
    # KISS-ICP's poses are the LiDAR's; the truth and ours are the body's.
    lidar_t_body = np.linalg.inv(calibration_pose(args.calibration))
    kiss_body = [p @ lidar_t_body for p in kiss_poses]
    if args.write_tum:
        write_tum(args.write_tum, stamps, kiss_body)
    ours, kiss = evaluate(our_stamps, our_poses, ref_stamps, ref_poses), evaluate(
        stamps, kiss_body, ref_stamps, ref_poses)
    t = summary["time"]
    engine_mean, engine_p99 = t["scan_ms_mean"], t["scan_ms_p99"]
    kiss_mean, kiss_p99 = float(np.mean(kiss_ms)), float(np.quantile(kiss_ms, 0.99,
                                                                      method="nearest"))
    rows_ours, rows_kiss = describe(ours), describe(kiss)
    rows_ours["mean / p99 ms a scan"] = f"{engine_mean:.2f} / {engine_p99:.2f} (engine)"
    rows_kiss["mean / p99 ms a scan"] = f"{kiss_mean:.2f} / {kiss_p99:.2f} (register_frame)"
    print(f"scans       {len(files)} in {args.scans}; ground truth {args.ground_truth} "
          f"({len(ref_poses)} poses)")
    print(f"KISS-ICP    1.3.0, max_range {config.data.max_range} m, voxel_size "
          f"{config.mapping.voxel_size} m, deskew {config.data.deskew}, min_range "
          f"{config.data.min_range} m, max_num_threads {config.registration.max_num_threads} "
          "(0: all cores)")
    width = max(len(k) for k in rows_ours) + 2
    print(f"{'':{width}}{'ours (slam --no-odometry)':<58}KISS-ICP")
    for key in rows_ours:
        print(f"{key:<{width}}{rows_ours[key]:<58}{rows_kiss[key]}")
    ratio = engine_mean / kiss_mean
    print(f"ours / KISS-ICP mean time a scan: {ratio:.3f} (the engine: the whole LiDAR-only "
          "front end)")
    # The same code on both; our own Rust evaluation (summary.json) as a check of this one.
    a = summary.get("accuracy") or {}
    if a:
        print(f"check       our Rust eval on our trajectory: ATE {a['ate_m']:.4f} m, end point "
              f"{a['end_point_error_m']:.3f} m, height {a['height_drift_m']:+.3f} m, RPE "
              f"{figure(a['rpe_percent'])} %, steps > 2 / > 5 deg {a['steps_over_2_deg']} / "
              f"{a['steps_over_5_deg']} (this script's figures above)")


# ---------------------------------------------------------------- self test

# evo 1.38.1 and the KITTI devkit (through KISS-ICP) on spot-adapter/tests/data/evo, as its
# README records them.
GOLDEN = {"pairs": 565, "ate": 2.334440560218639, "ate_mean": 2.04081752465752,
          "ate_max": 4.591366684701789, "path": 360.2575219110453,
          "steps_rmse": 0.32676077959942423, "steps_max": 7.018302228558682,
          "over_2": 2, "over_5": 1, "kitti": 2.474599838256836}


def selftest(folder):
    ref = read_trajectory(Path(folder) / "ground_truth.tum")
    est = read_trajectory(Path(folder) / "estimate.tum")
    e = evaluate(est[0], est[1], ref[0], ref[1])
    got = {"pairs": e["pairs"], "ate": e["ate"], "ate_mean": e["ate_mean"],
           "ate_max": e["ate_max"], "path": e["path"],
           "steps_rmse": float(np.sqrt(np.mean(e["steps"] ** 2))),
           "steps_max": float(np.max(e["steps"])), "over_2": int(np.sum(e["steps"] > 2)),
           "over_5": int(np.sum(e["steps"] > 5)), "kitti": e["rpe"][0]}
    bad = {k: (got[k], v) for k, v in GOLDEN.items()
           if abs(got[k] - v) > (2.5e-6 if k == "kitti" else 1e-9)}
    if bad:
        sys.exit(f"kiss_icp_peer.py's evaluation differs from evo's golden figures: {bad}")
    print("evaluation  matches evo's and the KITTI devkit's golden figures "
          "(spot-adapter/tests/data/evo)")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--selftest", metavar="GOLDEN_DIR")
    parser.add_argument("scans", nargs="?")
    parser.add_argument("ground_truth", nargs="?")
    parser.add_argument("ours", nargs="?")
    parser.add_argument("--max-range", type=float)
    parser.add_argument("--voxel-size", type=float)
    parser.add_argument("--threads", type=int)
    parser.add_argument("--calibration")
    parser.add_argument("--write-tum", metavar="PATH", help="write KISS-ICP's body poses here")
    args = parser.parse_args()
    if args.selftest:
        selftest(args.selftest)
        return
    if not (args.scans and args.ground_truth and args.ours):
        parser.error("SCANS_DIR GROUND_TRUTH OURS_DIR are needed")
    compare(args)


if __name__ == "__main__":
    main()
