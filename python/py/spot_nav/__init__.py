"""spot_nav: spot-nav's Rust backends from Python, NumPy arrays in and out.

- Registration: :func:`align` (point-to-plane or point-to-point ICP, LOAM) -> :class:`Alignment`.
- SLAM: :class:`Slam`, fed scan by scan (optional stamps, per-point times and odometry).
- Pose graphs: :func:`read_g2o`, :func:`read_toro`, :func:`optimize` (LM, GN, GNC),
  :func:`write_g2o`.
- Planning: :func:`plan` (JPS+, JPS, A*, Dijkstra) on a boolean grid, :func:`line_of_sight`,
  :func:`filter_path`, :func:`occupancy_grid` from a cloud, :func:`inflate`.

Clouds are ``N x 3`` float32 or float64 arrays, poses ``4 x 4`` float64 arrays (``a_T_b`` maps
points in frame b into frame a), grids ``H x W`` bool arrays indexed ``grid[y, x]`` (True:
blocked) with cells given as ``(x, y)``. Long calls release the GIL. Errors derive from
:class:`SpotNavError`.
"""

from ._native import (
    Alignment,
    CloudError,
    GraphFileError,
    GridMapError,
    InvalidInputError,
    OccupancyGrid,
    OptimizationError,
    OptimizeReport,
    Path,
    PlanningError,
    PoseGraph,
    RegistrationError,
    Slam,
    SpotNavError,
    __version__,
    align,
    filter_path,
    inflate,
    line_of_sight,
    occupancy_grid,
    optimize,
    plan,
    read_g2o,
    read_toro,
    write_g2o,
)

__all__ = [
    "Alignment",
    "CloudError",
    "GraphFileError",
    "GridMapError",
    "InvalidInputError",
    "OccupancyGrid",
    "OptimizationError",
    "OptimizeReport",
    "Path",
    "PlanningError",
    "PoseGraph",
    "RegistrationError",
    "Slam",
    "SpotNavError",
    "__version__",
    "align",
    "filter_path",
    "inflate",
    "line_of_sight",
    "occupancy_grid",
    "optimize",
    "plan",
    "read_g2o",
    "read_toro",
    "write_g2o",
]
