//! Planning on boolean grids: `plan`, `line_of_sight`, `filter_path`, and occupancy grids built
//! from a cloud (`occupancy_grid`, `inflate`).
//!
//! Grids are `H x W` boolean arrays indexed `grid[y, x]`, true where blocked; cells are `(x, y)`
//! (column, row), as in the Rust crates and Moving AI's files.

use numpy::{PyArray2, PyArrayMethods, PyReadonlyArray2};
use pathfind::{AStar, Dijkstra, JumpPointSearch, JumpPointSearchPlus};
use pyo3::prelude::*;
use slam_core::{BitGrid, Cell, GridPath, PlanError, Planner};

use crate::arrays::cloud_from;
use crate::error::{invalid, py_result};

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Path>()?;
    m.add_class::<OccupancyGrid>()?;
    m.add_function(wrap_pyfunction!(plan, m)?)?;
    m.add_function(wrap_pyfunction!(line_of_sight, m)?)?;
    m.add_function(wrap_pyfunction!(filter_path, m)?)?;
    m.add_function(wrap_pyfunction!(occupancy_grid, m)?)?;
    m.add_function(wrap_pyfunction!(inflate, m)?)?;
    Ok(())
}

/// A `BitGrid` from an `H x W` boolean array (true: blocked).
fn bit_grid(grid: &Bound<'_, PyAny>) -> PyResult<BitGrid> {
    let a = grid.extract::<PyReadonlyArray2<'_, bool>>().map_err(|_| {
        invalid("grid must be a 2-D numpy array of dtype bool (True: blocked), indexed grid[y, x]")
    })?;
    let view = a.as_array();
    let (h, w) = view.dim();
    let (Ok(w32), Ok(h32)) = (u32::try_from(w), u32::try_from(h)) else {
        return Err(invalid(format!("grid of {h} x {w} cells is too large")));
    };
    py_result(BitGrid::from_fn(w32, h32, |x, y| {
        view[[y as usize, x as usize]]
    }))
}

/// A grid as an `H x W` boolean array (true: blocked).
fn grid_to<'py>(py: Python<'py>, grid: &BitGrid) -> Bound<'py, PyArray2<bool>> {
    let (w, h) = (grid.width(), grid.height());
    let a = PyArray2::<bool>::zeros(py, [h as usize, w as usize], false);
    {
        let mut rw = a.readwrite();
        let mut view = rw.as_array_mut();
        for y in 0..h {
            for x in 0..w {
                view[[y as usize, x as usize]] = grid.is_blocked(Cell::new(x, y));
            }
        }
    }
    a
}

fn cell(c: (u32, u32)) -> Cell {
    Cell::new(c.0, c.1)
}

/// A shortest 8-connected path (diagonal steps cost sqrt(2), no corner cutting).
#[pyclass(frozen, module = "spot_nav")]
pub(crate) struct Path {
    inner: GridPath,
}

#[pymethods]
impl Path {
    /// Length in cells (multiply by the resolution for metres).
    #[getter]
    fn length(&self) -> f64 {
        self.inner.length
    }

    /// Every cell from start to goal, `(x, y)` per row of a `K x 2` int64 array.
    #[getter]
    fn cells<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        cells_to(py, &self.inner.expand())
    }

    /// The planner's own waypoints (jump points for JPS and JPS+: straight runs between them).
    #[getter]
    fn waypoints<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        cells_to(py, &self.inner.cells)
    }

    /// Nodes the search expanded.
    #[getter]
    fn expanded(&self) -> usize {
        self.inner.expanded
    }

    fn __len__(&self) -> usize {
        self.inner.expand().len()
    }

    fn __repr__(&self) -> String {
        format!(
            "Path(length={:.4}, waypoints={}, expanded={})",
            self.inner.length,
            self.inner.cells.len(),
            self.inner.expanded
        )
    }
}

fn cells_to<'py>(py: Python<'py>, cells: &[Cell]) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<i64> = cells
        .iter()
        .flat_map(|c| [i64::from(c.x), i64::from(c.y)])
        .collect();
    Ok(numpy::PyArray1::from_vec(py, flat)
        .reshape([cells.len(), 2])?
        .into_any())
}

/// A shortest path from `start` to `goal` (cells `(x, y)`) on `grid` (`H x W` bool, true:
/// blocked), or `None` when the goal cannot be reached.
///
/// `planner`: "jps_plus" (default), "jps", "astar" or "dijkstra": all return optimal lengths.
#[pyfunction]
#[pyo3(signature = (grid, start, goal, planner = "jps_plus"))]
fn plan(
    py: Python<'_>,
    grid: &Bound<'_, PyAny>,
    start: (u32, u32),
    goal: (u32, u32),
    planner: &str,
) -> PyResult<Option<Path>> {
    let grid = bit_grid(grid)?;
    let (start, goal) = (cell(start), cell(goal));
    let result: PyResult<Result<Option<GridPath>, PlanError>> = match planner {
        "jps_plus" => py
            .detach(|| {
                let mut p = JumpPointSearchPlus::new(&grid).map_err(|e| e.to_string())?;
                Ok(p.plan(start, goal))
            })
            .map_err(|e: String| crate::error::PlanningError::new_err(e)),
        "jps" => Ok(py.detach(|| JumpPointSearch::new(&grid).plan(start, goal))),
        "astar" => Ok(py.detach(|| AStar::new(&grid).plan(start, goal))),
        "dijkstra" => Ok(py.detach(|| Dijkstra::new(&grid).plan(start, goal))),
        other => Err(invalid(format!(
            "unknown planner {other:?}: use \"jps_plus\", \"jps\", \"astar\" or \"dijkstra\""
        ))),
    };
    Ok(py_result(result?)?.map(|inner| Path { inner }))
}

/// Whether the straight segment between the centres of cells `a` and `b` touches only free
/// cells (every cell the segment passes through, corners included).
#[pyfunction]
fn line_of_sight(grid: &Bound<'_, PyAny>, a: (u32, u32), b: (u32, u32)) -> PyResult<bool> {
    let grid = bit_grid(grid)?;
    Ok(pathfind::line_of_sight(&grid, cell(a), cell(b)))
}

/// The thesis' path filter: the waypoints of `path` that a straight collision-free segment
/// cannot skip. Returns `(waypoints as K x 2 (x, y), length in cells)`.
#[pyfunction]
fn filter_path<'py>(
    py: Python<'py>,
    grid: &Bound<'py, PyAny>,
    path: &Bound<'py, Path>,
) -> PyResult<(Bound<'py, PyAny>, f64)> {
    let grid = bit_grid(grid)?;
    let p = path.get();
    let f = py.detach(|| pathfind::filter_path(&grid, &p.inner));
    Ok((cells_to(py, &f.waypoints)?, f.length))
}

/// An occupancy grid built from a cloud: `occupied[y, x]`, and where it lies in the world.
#[pyclass(frozen, module = "spot_nav")]
pub(crate) struct OccupancyGrid {
    inner: gridmap::OccupancyGrid,
}

#[pymethods]
impl OccupancyGrid {
    /// `H x W` bool array, true where the slice had enough points.
    #[getter]
    fn occupied<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<bool>> {
        grid_to(py, self.inner.occupied())
    }

    /// World `(x, y)` of the outer corner of cell (0, 0), metres.
    #[getter]
    fn origin(&self) -> (f64, f64) {
        let o = self.inner.geometry().origin;
        (o.x, o.y)
    }

    /// Cell side, metres.
    #[getter]
    fn resolution(&self) -> f64 {
        self.inner.geometry().resolution
    }

    /// The cell `(x, y)` holding world point `(px, py)`, or `None` off the grid.
    fn cell_at(&self, point: (f64, f64)) -> Option<(u32, u32)> {
        self.inner
            .occupied()
            .cell_at([point.0, point.1].into())
            .map(|c| (c.x, c.y))
    }

    /// The world position of the centre of cell `(x, y)`.
    fn cell_center(&self, cell_xy: (u32, u32)) -> (f64, f64) {
        let c = self.inner.geometry().cell_center(cell(cell_xy));
        (c.x, c.y)
    }

    fn __repr__(&self) -> String {
        let o = self.inner.geometry().origin;
        format!(
            "OccupancyGrid(width={}, height={}, resolution={}, origin=({:.3}, {:.3}))",
            self.inner.width(),
            self.inner.height(),
            self.inner.geometry().resolution,
            o.x,
            o.y
        )
    }
}

/// The occupancy grid of a map cloud (`N x 3`, world frame): the slice from `slice_below` under
/// to `slice_above` over `lidar_height`, binned into cells of `resolution` metres; a cell is
/// occupied when at least `min_points` points fall in it.
#[pyfunction]
// One Python keyword a setting.
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (cloud, lidar_height = 0.0, *, resolution = 0.1, slice_below = 0.2, slice_above = 0.2, min_points = 1, margin = 0.5))]
fn occupancy_grid(
    py: Python<'_>,
    cloud: &Bound<'_, PyAny>,
    lidar_height: f64,
    resolution: f64,
    slice_below: f64,
    slice_above: f64,
    min_points: u32,
    margin: f64,
) -> PyResult<OccupancyGrid> {
    let cloud = cloud_from(cloud, "cloud")?;
    let config = gridmap::OccupancyGridConfig {
        resolution,
        slice_below,
        slice_above,
        min_points,
        margin,
        ..gridmap::OccupancyGridConfig::default()
    };
    let builder = py_result(gridmap::OccupancyGridBuilder::new(config))?;
    let inner = py_result(py.detach(|| builder.build(&cloud, lidar_height)))?;
    Ok(OccupancyGrid { inner })
}

/// `grid` with every cell within `radius` cells of a blocked one blocked (an exact disc).
#[pyfunction]
fn inflate<'py>(
    py: Python<'py>,
    grid: &Bound<'py, PyAny>,
    radius: f64,
) -> PyResult<Bound<'py, PyArray2<bool>>> {
    let grid = bit_grid(grid)?;
    let out = py_result(py.detach(|| gridmap::inflate(&grid, radius)))?;
    Ok(grid_to(py, &out))
}
