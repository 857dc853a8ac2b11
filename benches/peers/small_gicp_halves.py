"""Accuracy against exact ground truth, beside small_gicp: a real HDL-32E scan split into two random
halves (the same xorshift coin flips as registration/tests/integration/common), one half moved by a known
transform, registered back by small_gicp's single-thread PLANE_ICP and by ours (the `register`
example), both at 0.25 m voxels with pairs within 1 m (the settings of the speed comparison).

Usage: python small_gicp_halves.py TARGET_PLY REGISTER_BINARY WORK_DIR
"""

import subprocess
import sys

import numpy as np
import small_gicp

from ply_xyz import read_ply_xyz, write_ply_xyz

MASK = (1 << 64) - 1


def pose(x, y, z, roll, pitch, yaw):
    """nalgebra's from_euler_angles: Rz(yaw) Ry(pitch) Rx(roll)."""
    cr, sr, cp, sp, cy, sy = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch), np.cos(yaw), np.sin(yaw)
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    t = np.eye(4)
    t[:3, :3] = rz @ ry @ rx
    t[:3, 3] = [x, y, z]
    return t


def error(truth, estimate):
    e = np.linalg.inv(truth) @ estimate
    r = e[:3, :3]
    s = 0.5 * np.linalg.norm([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    return np.degrees(np.arctan2(s, (np.trace(r) - 1) / 2)), np.linalg.norm(e[:3, 3])


def halves(scan, seed, truth):
    s = seed
    a, b = [], []
    for p in scan:
        s ^= (s << 13) & MASK
        s ^= s >> 7
        s ^= (s << 17) & MASK
        (a if s & 1 else b).append(p)
    b = np.array(b)
    moved = (np.linalg.inv(truth) @ np.c_[b, np.ones(len(b))].T).T[:, :3]
    return moved, np.array(a)


target_path, register, work = sys.argv[1:4]
scan = read_ply_xyz(target_path)
truths = [
    pose(0.4, -0.25, 0.1, 0.03, -0.05, np.radians(10)),
    pose(-0.3, 0.35, -0.05, -0.04, 0.02, np.radians(-8)),
    pose(0.1, 0.45, 0.0, 0.08, 0.05, np.radians(4)),
]
seeds = [0x1234_5678_9ABC_DEF1, 0xDEAD_BEEF_1234_5677, 0x0F0F_1234_AAAA_5551]
print("| transform | split | small_gicp | ours |")
print("|---|---|---|---|")
for ti, truth in enumerate(truths):
    for seed in seeds:
        source, target = halves(scan, seed, truth)
        # Both sides read the same f32 points.
        write_ply_xyz(f"{work}/source.ply", source)
        write_ply_xyz(f"{work}/target.ply", target)
        np.savetxt(f"{work}/truth.txt", truth)
        source = read_ply_xyz(f"{work}/source.ply")
        target = read_ply_xyz(f"{work}/target.ply")
        result = small_gicp.align(
            target, source, registration_type="PLANE_ICP", downsampling_resolution=0.25,
            max_correspondence_distance=1.0, num_threads=1,
        )
        rot, trans = error(truth, result.T_target_source)
        out = subprocess.run(
            [register, f"{work}/source.ply", f"{work}/target.ply", "--method", "p2plane",
             "--voxel", "0.25", "--reference", f"{work}/truth.txt"],
            check=True, capture_output=True, text=True,
        ).stdout
        line = next(l for l in out.splitlines() if l.startswith("vs reference"))
        ours_rot, ours_cm = float(line.split()[2]), float(line.split()[4])
        print(f"| {ti} | {seed:x} | {rot:.3f}° {trans * 100:.2f} cm | {ours_rot:.3f}° {ours_cm:.2f} cm |")
