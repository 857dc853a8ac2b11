"""The golden figures of ground_truth.tum / estimate.tum to full precision, through evo's own API
(the same functions evo_ape and evo_rpe call), and the synced pose pairs for the KITTI check.

Usage (a venv with evo==1.38.1): python evo_figures.py [SYNCED.npz]
"""

import copy
import sys
from pathlib import Path

import numpy as np
from evo.core import metrics, sync
from evo.core.units import Unit
from evo.tools import file_interface

here = Path(__file__).parent
ref = file_interface.read_tum_trajectory_file(here / "ground_truth.tum")
est = file_interface.read_tum_trajectory_file(here / "estimate.tum")
ref, est = sync.associate_trajectories(ref, est, max_diff=0.01)
aligned = copy.deepcopy(est)
aligned.align(ref, correct_scale=False)
ape = metrics.APE(metrics.PoseRelation.translation_part)
ape.process_data((ref, aligned))
print(f"pairs {ref.num_poses}")
print(f"reference path length {ref.path_length!r} m")
for name, value in ape.get_all_statistics().items():
    print(f"ape {name} {float(value)!r}")
rpe = metrics.RPE(metrics.PoseRelation.rotation_angle_deg, delta=1, delta_unit=Unit.frames,
                  all_pairs=False)
rpe.process_data((ref, est))
for name, value in rpe.get_all_statistics().items():
    print(f"rpe_rot_deg {name} {float(value)!r}")
print(f"rpe_rot_deg steps {len(rpe.error)}")
print(f"rpe_rot_deg over 2 deg {int(np.sum(rpe.error > 2.0))}")
print(f"rpe_rot_deg over 5 deg {int(np.sum(rpe.error > 5.0))}")
if len(sys.argv) > 1:
    np.savez(sys.argv[1], reference=np.array(ref.poses_se3), estimate=np.array(est.poses_se3))
