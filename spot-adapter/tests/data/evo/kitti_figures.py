"""The KITTI devkit's sequence error (mean translation error over 100-800 m segments from every
10th pose, in %) of the synced pose pairs evo_figures.py saved, through KISS-ICP's port of the
devkit (kiss_icp.metrics.sequence_error; it returns float32 and converts radians to degrees with
180 / 3.14, so only its translation figure is a golden answer).

Usage (a venv with kiss-icp==1.3.0): python kitti_figures.py SYNCED.npz
"""

import sys

import numpy as np
from kiss_icp.metrics import sequence_error

pairs = np.load(sys.argv[1])
translation_percent, rotation_deg_per_100m = sequence_error(pairs["reference"], pairs["estimate"])
print(f"kitti translation {float(translation_percent)!r} %")
print(f"kitti rotation {float(rotation_deg_per_100m)!r} (degrees per metre, converted with 180 / 3.14)")
