"""Shared helpers: the repository's bundled data and small geometry."""

import pathlib

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def read_ply_xyz(path):
    """x, y, z of every vertex of a binary little-endian PLY whose properties are float32."""
    with open(path, "rb") as f:
        n, props = 0, []
        while True:
            line = f.readline().decode().strip()
            if line.startswith("element vertex"):
                n = int(line.split()[-1])
            elif line.startswith("property"):
                props.append(line.split()[-1])
            elif line == "end_header":
                break
        data = np.frombuffer(f.read(n * 4 * len(props)), dtype=np.float32).reshape(n, len(props))
    return np.ascontiguousarray(data[:, :3])


def pose(x, y, z, roll, pitch, yaw):
    """4 x 4 from translation and roll, pitch, yaw (R = Rz Ry Rx)."""
    cr, sr, cp, sp, cy, sy = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch), np.cos(yaw), np.sin(yaw)
    r = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]]) @ np.array(
        [[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]]) @ np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    t = np.eye(4)
    t[:3, :3] = r
    t[:3, 3] = [x, y, z]
    return t


def transform(t, points):
    return points @ t[:3, :3].T + t[:3, 3]


def pose_error(a, b):
    """(translation m, rotation deg) of a^-1 b."""
    e = np.linalg.inv(a) @ b
    angle = np.degrees(np.arccos(np.clip((np.trace(e[:3, :3]) - 1) / 2, -1, 1)))
    return np.linalg.norm(e[:3, 3]), angle


@pytest.fixture(scope="session")
def hdl32e_pair():
    """small_gicp's HDL-32E pair and its reference target_T_source."""
    source = read_ply_xyz(ROOT / "registration/tests/data/source.ply")
    target = read_ply_xyz(ROOT / "slam-core/tests/data/hdl32e_pair_target.ply")
    reference = np.loadtxt(ROOT / "registration/tests/data/T_target_source.txt")
    return source, target, reference
