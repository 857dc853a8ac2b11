"""Peer timing for the registration bench: small_gicp's single-thread point-to-plane ICP on the
HDL-32E pair at 0.25 m voxels (preparation and alignment together, best and median of N runs,
default 20), and its error against the reference pose.

Run through small_gicp_registration.sh, which installs small_gicp 1.0.1 from PyPI into a virtual
environment.
"""

import sys
import time

import numpy as np
import small_gicp

from ply_xyz import read_ply_xyz


source_path, target_path, reference_path = sys.argv[1:4]
runs = int(sys.argv[4]) if len(sys.argv) > 4 else 20
source = read_ply_xyz(source_path)
target = read_ply_xyz(target_path)
reference = np.loadtxt(reference_path)

times = []
# One untimed run first: the first call pays for page faults and lazy set-up.
result = small_gicp.align(
    target, source, registration_type="PLANE_ICP", downsampling_resolution=0.25,
    max_correspondence_distance=1.0, num_threads=1,
)
for _ in range(runs):
    start = time.perf_counter()
    result = small_gicp.align(
        target, source, registration_type="PLANE_ICP", downsampling_resolution=0.25,
        max_correspondence_distance=1.0, num_threads=1,
    )
    times.append(time.perf_counter() - start)
times.sort()
best, median = times[0], times[len(times) // 2]
error = np.linalg.inv(reference) @ result.T_target_source
angle = np.degrees(np.arccos(np.clip((np.trace(error[:3, :3]) - 1) / 2, -1, 1)))
print(f"small_gicp PLANE_ICP single thread, prepare + align: best {best * 1e3:.1f} ms, "
      f"median {median * 1e3:.1f} ms of {runs} runs; "
      f"error {np.linalg.norm(error[:3, 3]):.4f} m {angle:.4f} deg, converged {result.converged}")
