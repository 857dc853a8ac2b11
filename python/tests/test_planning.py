"""plan() against a brute-force Dijkstra in Python and Moving AI's published optimal lengths;
line_of_sight against a dense sampling of the segment; occupancy grids from synthetic clouds."""

import heapq
import math

import numpy as np
import pytest

import spot_nav
from conftest import ROOT

PLANNERS = ["jps_plus", "jps", "astar", "dijkstra"]


def brute_dijkstra(grid, start, goal):
    """8-connected, diagonal sqrt(2), no corner cutting (both side cells free)."""
    h, w = grid.shape
    dist = {start: 0.0}
    queue = [(0.0, start)]
    while queue:
        d, (x, y) = heapq.heappop(queue)
        if (x, y) == goal:
            return d
        if d > dist[(x, y)]:
            continue
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                if dx == dy == 0:
                    continue
                nx, ny = x + dx, y + dy
                if not (0 <= nx < w and 0 <= ny < h) or grid[ny, nx]:
                    continue
                if dx and dy and (grid[y, nx] or grid[ny, x]):
                    continue
                nd = d + (math.sqrt(2) if dx and dy else 1.0)
                if nd < dist.get((nx, ny), math.inf):
                    dist[(nx, ny)] = nd
                    heapq.heappush(queue, (nd, (nx, ny)))
    return None


@pytest.mark.parametrize("seed", range(12))
def test_planners_match_brute_force(seed):
    rng = np.random.default_rng(seed)
    h, w = rng.integers(8, 30, size=2)
    grid = rng.random((h, w)) < 0.3
    free = np.argwhere(~grid)
    for _ in range(5):
        (sy, sx), (gy, gx) = free[rng.choice(len(free), 2)]
        want = brute_dijkstra(grid, (sx, sy), (gx, gy))
        for planner in PLANNERS:
            p = spot_nav.plan(grid, (int(sx), int(sy)), (int(gx), int(gy)), planner=planner)
            if want is None:
                assert p is None, planner
                continue
            assert p is not None and abs(p.length - want) < 1e-9, (planner, p, want)
            cells = p.cells
            assert tuple(cells[0]) == (sx, sy) and tuple(cells[-1]) == (gx, gy)
            assert not grid[cells[:, 1], cells[:, 0]].any()
            steps = np.abs(np.diff(cells, axis=0))
            assert steps.max() <= 1
            assert abs(np.sum(np.where(steps.sum(1) == 2, math.sqrt(2), 1.0)) - want) < 1e-9


def read_movingai(name):
    rows = (ROOT / "pathfind/tests/data" / name).read_text().splitlines()
    h = int(rows[1].split()[1])
    body = rows[4:4 + h]
    grid = np.array([[c not in ".GS" for c in row] for row in body])
    scen = []
    for line in (ROOT / "pathfind/tests/data" / (name + ".scen")).read_text().splitlines()[1:]:
        f = line.split("\t")
        scen.append(((int(f[4]), int(f[5])), (int(f[6]), int(f[7])), float(f[8])))
    return grid, scen


@pytest.mark.parametrize("planner", PLANNERS)
def test_moving_ai_published_optimal_lengths(planner):
    grid, scen = read_movingai("arena.map")
    for start, goal, optimal in scen:
        p = spot_nav.plan(grid, start, goal, planner=planner)
        assert p is not None and abs(p.length - optimal) < 1e-4, (start, goal)  # .scen rounds


def test_line_of_sight_and_filter():
    grid = np.zeros((20, 30), dtype=bool)
    grid[0:15, 12] = True  # a wall with a gap at the top
    assert spot_nav.line_of_sight(grid, (2, 2), (10, 14))
    assert not spot_nav.line_of_sight(grid, (2, 2), (25, 2))
    # Oracle: a segment that samples densely through a blocked cell has no line of sight.
    rng = np.random.default_rng(1)
    free = np.argwhere(~grid)
    for _ in range(200):
        (ay, ax), (by, bx) = free[rng.choice(len(free), 2)]
        t = np.linspace(0, 1, 2000)
        xs = np.floor(ax + 0.5 + t * (bx - ax)).astype(int)
        ys = np.floor(ay + 0.5 + t * (by - ay)).astype(int)
        if grid[ys, xs].any():
            assert not spot_nav.line_of_sight(grid, (int(ax), int(ay)), (int(bx), int(by)))
    path = spot_nav.plan(grid, (2, 2), (25, 2))
    waypoints, length = spot_nav.filter_path(grid, path)
    assert tuple(waypoints[0]) == (2, 2) and tuple(waypoints[-1]) == (25, 2)
    assert len(waypoints) < len(path.cells)
    assert length <= path.length + 1e-9
    for a, b in zip(waypoints[:-1], waypoints[1:]):
        assert spot_nav.line_of_sight(grid, tuple(map(int, a)), tuple(map(int, b)))


def test_unreachable_and_errors():
    grid = np.zeros((10, 20), dtype=bool)
    grid[:, 10] = True
    for planner in PLANNERS:
        assert spot_nav.plan(grid, (2, 2), (17, 2), planner=planner) is None
    with pytest.raises(spot_nav.PlanningError, match="blocked"):
        spot_nav.plan(grid, (10, 2), (17, 2))
    with pytest.raises(spot_nav.PlanningError):
        spot_nav.plan(grid, (2, 2), (40, 2))
    with pytest.raises(spot_nav.InvalidInputError, match="bool"):
        spot_nav.plan(grid.astype(np.uint8), (2, 2), (17, 2))
    with pytest.raises(spot_nav.InvalidInputError, match="unknown planner"):
        spot_nav.plan(grid, (2, 2), (17, 2), planner="theta")


def test_occupancy_grid_from_a_cloud():
    # A 4 m wall along y = 2 m at the LiDAR's height, and a floor that the slice leaves out.
    wall = np.c_[np.arange(400) * 0.01, np.full(400, 2.0), np.full(400, 0.5)]
    floor = np.c_[np.random.default_rng(0).random((2000, 2)) * 4, np.full(2000, -0.3)]
    g = spot_nav.occupancy_grid(np.vstack([wall, floor]), lidar_height=0.5, resolution=0.1)
    occ = g.occupied
    x, y = g.cell_at((1.0, 2.0))
    assert occ[y, x]
    cx, cy = g.cell_center((x, y))
    assert abs(cx - 1.05) < 0.051 and abs(cy - 2.0) < 0.051
    assert occ.sum() == occ[y].sum()  # only the wall's row
    inflated = spot_nav.inflate(occ, 2.0)
    assert inflated[y - 2, x] and not inflated[y - 3, x]
    with pytest.raises(spot_nav.GridMapError):
        spot_nav.occupancy_grid(floor, lidar_height=0.5)
