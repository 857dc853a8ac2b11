"""Type stubs of the extension module (spot_nav._native); spot_nav re-exports every name."""

from os import PathLike
from typing import Literal, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

Cloud = Union[npt.NDArray[np.float32], npt.NDArray[np.float64]]
"""``N x 3`` points, float32 or float64, any strides."""
Matrix4 = npt.ArrayLike
"""A ``4 x 4`` rigid transform (rotation block orthonormal, last row ``[0, 0, 0, 1]``)."""
Cell = tuple[int, int]
"""``(x, y)``: column and row of ``grid[y, x]``."""
StrPath = Union[str, PathLike[str]]

class SpotNavError(Exception):
    """Base of every error spot_nav raises."""

class InvalidInputError(SpotNavError):
    """An argument of the wrong shape, type or range, or an unknown or invalid setting."""

class RegistrationError(SpotNavError):
    """A registration failed: too few points or correspondences, a degenerate fit."""

class OptimizationError(SpotNavError):
    """A pose-graph optimisation failed: no fixed node, a factorisation failure, bad values."""

class GraphFileError(SpotNavError):
    """A g2o or TORO file could not be read or written."""

class PlanningError(SpotNavError):
    """A start or goal off the grid or on a blocked cell, or a grid too large for a planner."""

class GridMapError(SpotNavError):
    """An occupancy grid could not be built (empty slice, too many cells, bad points)."""

class CloudError(SpotNavError):
    """A cloud operation failed (for example an invalid voxel size)."""

class Alignment:
    """The result of :func:`align`."""

    @property
    def transform(self) -> npt.NDArray[np.float64]:
        """``target_T_source``, 4 x 4: maps source points onto the target."""
    @property
    def converged(self) -> bool:
        """Whether the last update moved less than the tolerances before the iteration cap."""
    @property
    def iterations(self) -> int: ...
    @property
    def inliers(self) -> int:
        """Correspondences used in the last iteration."""
    @property
    def inlier_ratio(self) -> float: ...
    @property
    def rmse(self) -> float:
        """Root mean square residual of the inliers, metres."""
    @property
    def information(self) -> npt.NDArray[np.float64]:
        """6 x 6 information ``J^T W J``, tangent order ``[translation; rotation]``."""
    @property
    def min_eigenvalue_ratio(self) -> float:
        """Smallest over largest eigenvalue of the information: near 0 in a degenerate scene."""

def align(
    source: Cloud,
    target: Cloud,
    method: Literal["point_to_plane", "point_to_point", "loam"] = "point_to_plane",
    initial: Optional[Matrix4] = None,
    *,
    # ICP (IcpConfig): metres, radians.
    source_voxel: float = 0.25,
    target_voxel: float = 0.25,
    max_correspondence_distance: float = 1.0,
    max_iterations: int = 50,
    translation_tolerance: float = 1e-4,
    rotation_tolerance: float = 1e-4,
    normal_neighbours: int = 10,
    kernel: Literal["huber", "tukey", "none"] = "huber",
    kernel_threshold: float = 0.1,
    min_correspondences: int = 20,
    pair_target_points: int = 2,
    coarse_stride: int = 4,
    normals_up_front: bool = False,
    degeneracy_threshold: float = 0.0,
    min_planarity: float = 0.0,
    max_source_points: int = 0,
    # LOAM (LoamConfig and its feature extraction).
    layout: Union[Literal["vlp16", "hdl32e", "os1_128"], tuple[int, float, float]] = "vlp16",
    local_map_edge_voxel: float = 0.05,
    local_map_plane_voxel: float = 0.1,
    source_edge_voxel: float = 0.0,
    source_plane_voxel: float = 0.0,
    search_cell: float = 0.4,
    neighbours: int = 5,
    max_neighbour_distance: float = 1.0,
    line_eigenvalue_ratio: float = 10.0,
    plane_fit_tolerance: float = 0.1,
    tukey_threshold: float = 0.05,
    initial_tukey_threshold: float = 0.25,
    rematch_motion: float = 0.01,
    feature_neighbours: int = ...,
    sectors: int = ...,
    max_edges_per_sector: int = ...,
    max_planes_per_sector: int = ...,
    edge_min_roughness: float = ...,
    edge_min_sharpness: float = ...,
    plane_max_roughness: float = ...,
    min_range: float = ...,
    max_range: float = ...,
) -> Alignment:
    """Register ``source`` onto ``target``; settings apply to the chosen method only (an ICP
    setting given to LOAM, or the reverse, is an :class:`InvalidInputError`)."""

class Slam:
    """Graph-SLAM: each scan registered against a local map of keyframes, loops closed and the
    graph optimised (GNC over LM), as spot-adapter's pipelines set it up."""

    def __init__(
        self,
        odometry: Literal["point_to_plane", "loam"] = "point_to_plane",
        body_T_lidar: Optional[Matrix4] = None,
        place_recognition: bool = False,
        *,
        keyframe_distance: float = ...,
        keyframe_rotation: float = ...,
        local_map_keyframes: int = ...,
        revisit_radius: float = ...,
        revisit_min_inlier_ratio: float = ...,
        revisit_max_match_drop: float = ...,
        loop_search_radius: float = ...,
        loop_neighbours: int = ...,
        loop_max_mean_squared_error: float = 0.04,
        loop_min_keyframe_gap: int = ...,
        loop_max_refine_shift: float = ...,
        loop_max_drift_rate: float = ...,
        loop_max_height_drift_rate: float = ...,
        map_voxel_size: float = ...,
        keyframe_scan_spacing: float = ...,
        dense_scan_points: int = ...,
        min_scan_points: int = ...,
        odometry_gravity: bool = ...,
        deskew: bool = ...,
        sweep_motion: bool = ...,
        inline_loop_closure: bool = ...,
    ) -> None: ...
    def register_frame(
        self,
        points: Cloud,
        stamp: Optional[float] = None,
        point_times: Optional[Union[npt.NDArray[np.floating], Sequence[float]]] = None,
        odometry: Optional[Matrix4] = None,
    ) -> Optional[npt.NDArray[np.float64]]:
        """Feed one scan (LiDAR frame); its ``map_T_lidar`` or None when skipped. The map frame
        is the odometry's with odometry, else the first scan's."""
    @property
    def last_outcome(self) -> Optional[str]:
        """"keyframe", "tracked" or "skipped: <reason>"."""
    @property
    def poses(self) -> npt.NDArray[np.float64]:
        """Every accepted scan's ``map_T_lidar``, ``N x 4 x 4``."""
    @property
    def stamps(self) -> list[float]: ...
    @property
    def keyframes(self) -> npt.NDArray[np.float64]:
        """Keyframes' optimised ``map_T_lidar``, ``K x 4 x 4``."""
    @property
    def loops(self) -> list[tuple[int, int]]:
        """Loop-closure edges as (older, newer) keyframe indices."""
    def report(self) -> dict[str, Union[int, float]]: ...
    def map(self, voxel_size: Optional[float] = None) -> npt.NDArray[np.float32]:
        """Every keyframe cloud at its optimised pose, voxel-thinned, ``N x 3``."""

class PoseGraph:
    """A pose graph read from a file: SE(2) (``dimension == 2``) or SE(3)."""

    @property
    def dimension(self) -> Literal[2, 3]: ...
    @property
    def node_count(self) -> int: ...
    @property
    def edge_count(self) -> int: ...
    @property
    def ids(self) -> list[int]: ...
    @property
    def edges(self) -> list[tuple[int, int]]:
        """(from_id, to_id) per edge, in the order of :attr:`OptimizeReport.weights`."""
    @property
    def poses(self) -> npt.NDArray[np.float64]:
        """``N x 4 x 4`` (SE(3)) or ``N x 3`` rows of ``x, y, theta`` (SE(2))."""
    def fix(self, id: int) -> None:
        """Hold node ``id`` fixed while optimising."""
    def cost(self) -> float:
        """``sum e^T Omega e`` with the log-map error."""
    def chi2(self) -> float:
        """The cost in g2o's error convention."""

class OptimizeReport:
    iterations: int
    initial_cost: float
    final_cost: float
    stop_reason: str
    """"cost_converged", "step_converged", "max_iterations", "damping_exhausted" or
    "nothing_to_do"."""
    weights: Optional[list[float]]
    """GNC: each edge's final weight (0: rejected); None for LM and GN."""
    rejected: int

def read_g2o(path: StrPath) -> PoseGraph: ...
def read_toro(path: StrPath) -> PoseGraph: ...
def write_g2o(graph: PoseGraph, path: StrPath) -> None: ...
def optimize(
    graph: PoseGraph,
    method: Literal["lm", "gn", "gnc"] = "lm",
    *,
    max_iterations: int = 100,
    relative_cost_tolerance: float = 1e-6,
    step_tolerance: float = 1e-10,
    error_model: Literal["log_map", "g2o"] = "log_map",
    loss: Literal["tls", "geman_mcclure"] = "tls",
    known_inliers: Literal["consecutive_ids", "without_kernel"] = "consecutive_ids",
    inlier_probability: Optional[float] = None,
) -> OptimizeReport:
    """Optimise ``graph`` in place (it needs a fixed node: ``FIX`` or :meth:`PoseGraph.fix`)."""

class Path:
    """A shortest 8-connected path (diagonal sqrt(2), no corner cutting)."""

    @property
    def length(self) -> float:
        """In cells."""
    @property
    def cells(self) -> npt.NDArray[np.int64]:
        """Every cell, ``K x 2`` rows of ``(x, y)``."""
    @property
    def waypoints(self) -> npt.NDArray[np.int64]:
        """The planner's own waypoints (jump points), ``K x 2``."""
    @property
    def expanded(self) -> int: ...
    def __len__(self) -> int: ...

def plan(
    grid: npt.NDArray[np.bool_],
    start: Cell,
    goal: Cell,
    planner: Literal["jps_plus", "jps", "astar", "dijkstra"] = "jps_plus",
) -> Optional[Path]:
    """A shortest path on ``grid`` (``H x W``, True: blocked), or None when unreachable."""

def line_of_sight(grid: npt.NDArray[np.bool_], a: Cell, b: Cell) -> bool: ...
def filter_path(
    grid: npt.NDArray[np.bool_], path: Path
) -> tuple[npt.NDArray[np.int64], float]:
    """The waypoints a straight collision-free segment cannot skip, and their length."""

class OccupancyGrid:
    @property
    def occupied(self) -> npt.NDArray[np.bool_]:
        """``H x W``, True where the slice had enough points."""
    @property
    def origin(self) -> tuple[float, float]: ...
    @property
    def resolution(self) -> float: ...
    def cell_at(self, point: tuple[float, float]) -> Optional[Cell]: ...
    def cell_center(self, cell_xy: Cell) -> tuple[float, float]: ...

def occupancy_grid(
    cloud: Cloud,
    lidar_height: float = 0.0,
    *,
    resolution: float = 0.1,
    slice_below: float = 0.2,
    slice_above: float = 0.2,
    min_points: int = 1,
    margin: float = 0.5,
) -> OccupancyGrid: ...
def inflate(grid: npt.NDArray[np.bool_], radius: float) -> npt.NDArray[np.bool_]:
    """Every cell within ``radius`` cells of a blocked one blocked."""
