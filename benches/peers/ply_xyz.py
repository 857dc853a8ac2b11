"""Binary little-endian PLY vertices (float x y z first) for the peer scripts."""

import numpy as np


def read_ply_xyz(path):
    """The x, y, z of every vertex, as float64 (n, 3)."""
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
    return data[:, :3].astype(np.float64)


def write_ply_xyz(path, points):
    """Points (n, 3) as float32 x, y, z vertices."""
    with open(path, "wb") as f:
        f.write(f"ply\nformat binary_little_endian 1.0\nelement vertex {len(points)}\n"
                "property float x\nproperty float y\nproperty float z\nend_header\n".encode())
        f.write(points.astype("<f4").tobytes())
