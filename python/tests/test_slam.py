"""Slam against ground truth: a synthetic room scanned from known poses (oracle: the poses the
scans were made from), LiDAR-only and with odometry."""

import math

import numpy as np
import pytest

import spot_nav
from conftest import pose, pose_error, transform


def room(rng, n=60000):
    """A 20 m x 12 m room, 3 m tall, with pillars and boxes: points on every surface."""
    pts = []
    for _ in range(n // 6):
        x, y, z = rng.random() * 20, rng.random() * 12, rng.random() * 3
        pts += [(x, 0, z), (x, 12, z), (0, y, z), (20, y, z), (x, y, 0), (x, y, 3)]
    for cx, cy in [(5, 4), (12, 8), (15, 3), (8, 9)]:
        a = rng.random(1500) * 2 * math.pi
        z = rng.random(1500) * 3
        pts += list(zip(cx + 0.3 * np.cos(a), cy + 0.3 * np.sin(a), z))
    for bx, by in [(3, 9), (17, 10)]:
        u, v = rng.random(1500), rng.random(1500)
        pts += list(zip(bx + u, np.full(1500, by), v))
        pts += list(zip(np.full(1500, bx), by + u, v))
    return np.array(pts)


def scans(world, truth, rng, max_range=12.0, keep=0.3):
    """Each pose's view: points in range (a random subset, as a LiDAR samples differently each
    time), in the sensor frame."""
    for t in truth:
        local = transform(np.linalg.inv(t), world)
        d = np.linalg.norm(local, axis=1)
        mask = (d < max_range) & (rng.random(len(local)) < keep)
        yield local[mask].astype(np.float32)


def trajectory(n=40):
    return [pose(4 + 0.3 * i, 6 + math.sin(i / 6.0), 1.0, 0, 0, 0.3 * math.sin(i / 8.0)) for i in range(n)]


@pytest.mark.parametrize("with_odometry", [False, True])
def test_slam_follows_the_known_trajectory(with_odometry):
    rng = np.random.default_rng(3)
    world = room(rng)
    truth = trajectory()
    slam = spot_nav.Slam(keyframe_distance=0.5)
    returned = []
    for i, cloud in enumerate(scans(world, truth, rng)):
        odom = truth[i] if with_odometry else None
        p = slam.register_frame(cloud, stamp=0.1 * i, odometry=odom)
        assert p is not None, slam.last_outcome
        returned.append(p)
    poses = slam.poses
    assert poses.shape == (len(truth), 4, 4)
    assert np.allclose(poses[-1], returned[-1])
    # The map frame is the odometry's frame when there is odometry, else the first scan's.
    first = np.eye(4) if with_odometry else truth[0]
    for t, p in zip(truth, poses):
        dt, dr = pose_error(np.linalg.inv(first) @ t, p)
        assert dt < 0.05 and dr < 0.5, (dt, dr)
    assert len(slam.keyframes) >= 10
    assert slam.stamps[-1] == pytest.approx(0.1 * (len(truth) - 1))
    report = slam.report()
    assert report["scans"] == len(truth) and report["keyframes"] == len(slam.keyframes)
    m = slam.map()
    assert m.dtype == np.float32 and m.shape[1] == 3 and len(m) > 1000
    assert isinstance(slam.loops, list)


def test_slam_skips_bad_input_and_refuses_bad_settings():
    slam = spot_nav.Slam()
    assert slam.register_frame(np.zeros((3, 3)), stamp=0.0) is None
    assert slam.last_outcome.startswith("skipped")
    with pytest.raises(spot_nav.InvalidInputError, match="unknown setting"):
        spot_nav.Slam(keyframe_dist=1.0)
    with pytest.raises(spot_nav.InvalidInputError):
        spot_nav.Slam(keyframe_distance=-1.0)
    with pytest.raises(spot_nav.InvalidInputError, match="odometry"):
        spot_nav.Slam(odometry="kiss")


def test_slam_closes_a_loop_between_places_it_revisits():
    """A lap around the room back past the start: loops join keyframes that truly lie within
    the search radius of each other, and every pose stays on the truth."""
    rng = np.random.default_rng(5)
    world = room(rng)
    n = 80
    truth = [pose(10 + 6 * math.cos(2 * math.pi * i / n), 6 + 3.5 * math.sin(2 * math.pi * i / n),
                  1.0, 0, 0, 2 * math.pi * i / n + math.pi / 2) for i in range(n + 6)]
    slam = spot_nav.Slam(keyframe_distance=0.5, local_map_keyframes=10, loop_search_radius=2.0)
    for i, cloud in enumerate(scans(world, truth, rng)):
        slam.register_frame(cloud, stamp=0.1 * i)
    loops = slam.loops
    assert loops and slam.report()["loops_closed"] == len(loops)
    # Each keyframe's true pose: the scan whose estimated pose it is.
    index = {tuple(np.round(p[:3, 3], 6)): i for i, p in enumerate(slam.poses)}
    true_kf = [truth[index[tuple(np.round(k[:3, 3], 6))]] for k in slam.keyframes]
    for a, b in loops:
        assert b - a >= 5
        assert np.linalg.norm(true_kf[a][:3, 3] - true_kf[b][:3, 3]) < 2.0
    for t, p in zip(truth, slam.poses):
        dt, dr = pose_error(np.linalg.inv(truth[0]) @ t, p)
        assert dt < 0.05 and dr < 0.5, (dt, dr)


def test_point_times_are_read_from_arrays_and_sequences_alike():
    # The same moving sensor's scans with per-point times (seconds into each sweep): as a
    # float64 array, a float32 array and a list they give the same poses; a wrong length or a
    # 2-D array is refused by name.
    rng = np.random.default_rng(5)
    world = room(rng)
    truth = trajectory(12)
    clouds = list(scans(world, truth, rng))
    times = [np.linspace(0.0, 0.1, len(c)) for c in clouds]
    runs = []
    for form in (lambda t: t, lambda t: t.astype(np.float32), lambda t: t.astype(np.float32).tolist()):
        slam = spot_nav.Slam(keyframe_distance=0.5)
        for i, (cloud, t) in enumerate(zip(clouds, times)):
            assert slam.register_frame(cloud, stamp=0.5 * i, point_times=form(t)) is not None
        runs.append(slam.poses)
    assert np.array_equal(runs[0], runs[1]) and np.array_equal(runs[1], runs[2])
    slam = spot_nav.Slam()
    with pytest.raises(spot_nav.CloudError, match="time channel"):
        slam.register_frame(clouds[0], stamp=0.0, point_times=times[0][:-1])
    with pytest.raises(spot_nav.InvalidInputError, match="point_times"):
        slam.register_frame(clouds[0], stamp=0.0, point_times=np.zeros((len(clouds[0]), 2)))
