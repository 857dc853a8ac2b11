"""Writes ground_truth.tum and estimate.tum, the trajectory pair whose figures evo and KISS-ICP's
KITTI metric computed for the golden test (see README.md). Deterministic: numpy's PCG64, seed 30.

The truth: 600 poses 0.1 s apart, a wandering 3D walk of about 367 m (turns, a ramp up and back
down). The estimate: the truth's steps with a 0.3 % scale error, a yaw drift of 0.02 degrees a
step, small random step noise, a 3-degree and a 7-degree rotation spike on two steps, all in a
frame of its own (an arbitrary rigid transform), its stamps jittered by up to 3 ms and every
17th pose dropped.

Usage: python3 make_pair.py  (writes the two files beside itself)
"""

from pathlib import Path

import numpy as np


def rot(axis, angle):
    """Rotation matrix about a unit axis (Rodrigues)."""
    axis = np.asarray(axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def pose(r, t):
    p = np.eye(4)
    p[:3, :3] = r
    p[:3, 3] = t
    return p


def quaternion_xyzw(r):
    """Unit quaternion (x, y, z, w) of a rotation matrix, w >= 0."""
    w = np.sqrt(max(0.0, 1 + r[0, 0] + r[1, 1] + r[2, 2])) / 2
    x = np.sqrt(max(0.0, 1 + r[0, 0] - r[1, 1] - r[2, 2])) / 2
    y = np.sqrt(max(0.0, 1 - r[0, 0] + r[1, 1] - r[2, 2])) / 2
    z = np.sqrt(max(0.0, 1 - r[0, 0] - r[1, 1] + r[2, 2])) / 2
    x = np.copysign(x, r[2, 1] - r[1, 2])
    y = np.copysign(y, r[0, 2] - r[2, 0])
    z = np.copysign(z, r[1, 0] - r[0, 1])
    q = np.array([x, y, z, w])
    return q / np.linalg.norm(q)


def write_tum(path, stamps, poses):
    with open(path, "w") as f:
        f.write("# timestamp tx ty tz qx qy qz qw\n")
        for s, p in zip(stamps, poses):
            q = quaternion_xyzw(p[:3, :3])
            t = p[:3, 3]
            f.write(" ".join(f"{v:.9f}" for v in [s, *t, *q]) + "\n")


def main():
    rng = np.random.Generator(np.random.PCG64(30))
    n = 600
    # Steps of the truth in the body frame: forward 0.6 m, a heading that turns in phases, a
    # pitch that climbs a ramp from step 150 to 250 and comes down from 350 to 450.
    steps = []
    for i in range(n - 1):
        yaw = 0.05 * np.sin(i / 37.0) + (0.12 if 300 <= i < 326 else 0.0)
        pitch = 0.004 if 150 <= i < 160 else (-0.004 if 240 <= i < 250 else 0.0)
        pitch += -0.004 if 350 <= i < 360 else (0.004 if 440 <= i < 450 else 0.0)
        r = rot([0, 0, 1], yaw) @ rot([0, 1, 0], pitch)
        steps.append(pose(r, [0.6 + 0.05 * np.sin(i / 11.0), 0.01 * np.cos(i / 7.0), 0.0]))
    truth = [pose(rot([0, 0, 1], 0.4), [2.0, -1.0, 0.3])]
    for s in steps:
        truth.append(truth[-1] @ s)
    # The estimate's steps: scale, yaw drift, noise, two spikes.
    est = [pose(rot([1, 2, 3], 0.9), [10.0, 20.0, -3.0])]
    for i, s in enumerate(steps):
        e = s.copy()
        e[:3, 3] *= 1.003
        noise = rot(rng.normal(size=3), abs(rng.normal(0.0, np.radians(0.05))))
        e[:3, :3] = rot([0, 0, 1], np.radians(0.02)) @ noise @ e[:3, :3]
        e[:3, 3] += rng.normal(0.0, 0.004, size=3)
        if i == 200:
            e[:3, :3] = rot([0, 1, 0], np.radians(3.0)) @ e[:3, :3]
        if i == 420:
            e[:3, :3] = rot([1, 0, 0], np.radians(7.0)) @ e[:3, :3]
        est.append(est[-1] @ e)
    stamps = 1000.0 + 0.1 * np.arange(n)
    keep = [i for i in range(n) if i % 17 != 16]
    est_stamps = stamps[keep] + rng.uniform(-0.003, 0.003, size=len(keep))
    here = Path(__file__).parent
    write_tum(here / "ground_truth.tum", stamps, truth)
    write_tum(here / "estimate.tum", est_stamps, [est[i] for i in keep])


if __name__ == "__main__":
    main()
