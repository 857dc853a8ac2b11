"""Peer for the robust pose-graph bench: GTSAM's graduated non-convexity (GncOptimizer, truncated
least squares over Levenberg-Marquardt) on the corrupted graphs that spot-nav's
`posegraph_robust` bench writes.

Run through gtsam_gnc.sh, which installs GTSAM from PyPI into a virtual environment and writes
the graphs. Each argument is `CLEAN:CORRUPTED:WRONG`: the original g2o file, the same graph with
WRONG wrong loop closures appended as its last edges, and their count. Per argument and weight
tolerance (GTSAM's default 1e-4, and 1e-8), prints the mean position error against GTSAM's own
LM optimum of the clean file (metres), wrong loops kept and true loops lost (weight >= 0.5 and
< 0.5), GNC's iterations and the best of three wall times (one run when a run takes over 5 s).
The settings match spot-nav's defaults: odometry (consecutive ids) and the prior on the first
pose are known inliers, the inlier threshold is the 0.99 chi-square quantile.
"""

import sys
import time

import gtsam
import numpy as np


def load(path):
    is3d = any(line.startswith("VERTEX_SE3") for line in open(path))
    graph, initial = gtsam.readG2o(path, is3d)
    if is3d:
        noise = gtsam.noiseModel.Diagonal.Sigmas([1e-6] * 6)
        graph.add(gtsam.PriorFactorPose3(0, initial.atPose3(0), noise))
    else:
        noise = gtsam.noiseModel.Diagonal.Sigmas([1e-6] * 3)
        graph.add(gtsam.PriorFactorPose2(0, initial.atPose2(0), noise))
    return is3d, graph, initial


def positions(values, is3d, keys):
    if is3d:
        return np.array([values.atPose3(k).translation() for k in keys])
    return np.array([[values.atPose2(k).x(), values.atPose2(k).y()] for k in keys])


clean_optima = {}


def clean_optimum(path):
    if path not in clean_optima:
        is3d, graph, initial = load(path)
        result = gtsam.LevenbergMarquardtOptimizer(
            graph, initial, gtsam.LevenbergMarquardtParams()
        ).optimize()
        keys = sorted(initial.keys())
        clean_optima[path] = (keys, positions(result, is3d, keys))
    return clean_optima[path]


def gnc(path, wrong, weights_tol):
    is3d, graph, initial = load(path)
    edges = graph.size() - 1
    known = []
    for i in range(edges):
        k = graph.at(i).keys()
        if abs(int(k[0]) - int(k[1])) == 1:
            known.append(i)
    known.append(edges)  # the prior
    best = float("inf")
    for _ in range(3):
        params = gtsam.GncLMParams()
        params.setLossType(gtsam.GncLossType.TLS)
        params.setKnownInliers(known)
        params.setWeightsTol(weights_tol)
        start = time.perf_counter()
        optimizer = gtsam.GncLMOptimizer(graph, initial, params)
        optimizer.setInlierCostThresholdsAtProbability(0.99)
        result = optimizer.optimize()
        seconds = time.perf_counter() - start
        best = min(best, seconds)
        if seconds > 5.0:
            break
    weights = np.asarray(optimizer.getWeights())
    first_wrong = edges - wrong
    is_loop = np.array(
        [
            abs(int(graph.at(i).keys()[0]) - int(graph.at(i).keys()[1])) > 1
            for i in range(first_wrong)
        ]
    )
    true_lost = int(np.sum((weights[:first_wrong] < 0.5) & is_loop))
    wrong_kept = int(np.sum(weights[first_wrong:edges] >= 0.5))
    return is3d, result, best, wrong_kept, true_lost, int(is_loop.sum())


for arg in sys.argv[1:]:
    clean, corrupted, wrong = arg.split(":")
    wrong = int(wrong)
    keys, reference = clean_optimum(clean)
    for tol in (1e-4, 1e-8):
        is3d, result, seconds, kept, lost, loops = gnc(corrupted, wrong, tol)
        error = np.linalg.norm(positions(result, is3d, keys) - reference, axis=1).mean()
        print(
            f"{corrupted}\tweights_tol={tol:g}\terror_m={error:.6f}\twrong_kept={kept}/{wrong}"
            f"\ttrue_lost={lost}/{loops}\tms={seconds * 1e3:.1f}",
            flush=True,
        )
