//! `align` and its result, `Alignment`.

use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use registration::{
    IcpConfig, IcpKernel, LidarLayout, LoamConfig, LoamRegistrator, PointToPlaneIcp,
    PointToPointIcp,
};
use slam_core::{PointCloud, Pose3, Registrator};

use crate::arrays::{cloud_from, matrix6_to, pose_from, pose_to};
use crate::config::Settings;
use crate::error::{ToPyErr, invalid};

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Alignment>()?;
    m.add_function(wrap_pyfunction!(align, m)?)?;
    Ok(())
}

/// The result of `align`: `target_T_source` and how the registration went.
#[pyclass(frozen, module = "spot_nav")]
pub(crate) struct Alignment {
    inner: slam_core::Alignment,
}

#[pymethods]
impl Alignment {
    /// `target_T_source` as a 4 x 4 float64 array: maps source points onto the target.
    #[getter]
    fn transform<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        pose_to(py, &self.inner.pose)
    }

    /// Whether the last update moved less than the tolerances before the iteration cap.
    #[getter]
    fn converged(&self) -> bool {
        self.inner.converged
    }

    /// Iterations run.
    #[getter]
    fn iterations(&self) -> usize {
        self.inner.iterations
    }

    /// Correspondences used in the last iteration.
    #[getter]
    fn inliers(&self) -> usize {
        self.inner.inliers
    }

    /// Inliers over the source points used.
    #[getter]
    fn inlier_ratio(&self) -> f64 {
        self.inner.inlier_ratio
    }

    /// Root mean square residual of the inliers, metres.
    #[getter]
    fn rmse(&self) -> f64 {
        self.inner.rmse
    }

    /// The 6 x 6 information `J^T W J` of the pose, tangent order `[translation; rotation]`.
    #[getter]
    fn information<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix6_to(py, &self.inner.information)
    }

    /// Smallest over largest eigenvalue of the information: near 0 in a degenerate scene.
    #[getter]
    fn min_eigenvalue_ratio(&self) -> f64 {
        self.inner.min_eigenvalue_ratio
    }

    fn __repr__(&self) -> String {
        let t = self.inner.pose.translation.vector;
        format!(
            "Alignment(translation=[{:.4}, {:.4}, {:.4}], angle_deg={:.4}, converged={}, iterations={}, inliers={}, rmse={:.4})",
            t.x,
            t.y,
            t.z,
            self.inner.pose.rotation.angle().to_degrees(),
            if self.inner.converged {
                "True"
            } else {
                "False"
            },
            self.inner.iterations,
            self.inner.inliers,
            self.inner.rmse
        )
    }
}

/// Register `source` onto `target`.
///
/// `method` is "point_to_plane" (default), "point_to_point" or "loam"; `initial` the guess of
/// `target_T_source` (4 x 4, identity by default). Settings as keywords, named as the fields of
/// the Rust `IcpConfig` (ICP) or `LoamConfig` (LOAM); see the stubs for the list.
#[pyfunction]
#[pyo3(signature = (source, target, method = "point_to_plane", initial = None, **config))]
fn align(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    target: &Bound<'_, PyAny>,
    method: &str,
    initial: Option<&Bound<'_, PyAny>>,
    config: Option<&Bound<'_, PyDict>>,
) -> PyResult<Alignment> {
    let source = cloud_from(source, "source")?;
    let target = cloud_from(target, "target")?;
    let initial = match initial {
        Some(i) if !i.is_none() => pose_from(i, "initial")?,
        _ => Pose3::identity(),
    };
    let result = match method {
        "point_to_plane" => {
            let icp = PointToPlaneIcp {
                config: icp_config(config, "align(method='point_to_plane')")?,
            };
            py.detach(|| run(&icp, &source, &target, &initial))
        }
        "point_to_point" => {
            let icp = PointToPointIcp {
                config: icp_config(config, "align(method='point_to_point')")?,
            };
            py.detach(|| run(&icp, &source, &target, &initial))
        }
        "loam" => {
            let loam = LoamRegistrator {
                config: loam_config(config, "align(method='loam')")?,
            };
            py.detach(|| run(&loam, &source, &target, &initial))
        }
        other => {
            return Err(invalid(format!(
                "unknown method {other:?}: use \"point_to_plane\", \"point_to_point\" or \"loam\""
            )));
        }
    };
    result
        .map(|inner| Alignment { inner })
        .map_err(|e| e.to_py())
}

fn run<R: Registrator>(
    r: &R,
    source: &PointCloud,
    target: &PointCloud,
    initial: &Pose3,
) -> Result<slam_core::Alignment, slam_core::RegistrationError> {
    let s = r.prepare_source(source)?;
    let t = r.prepare_target(target)?;
    r.align(&s, &t, initial)
}

/// `IcpConfig` from keywords: its fields, with the kernel as `kernel="huber" | "tukey" | "none"`
/// and `kernel_threshold` (metres).
pub(crate) fn icp_config(
    dict: Option<&Bound<'_, PyDict>>,
    what: &'static str,
) -> PyResult<IcpConfig> {
    let mut s = Settings::new(dict, what)?;
    let mut c = IcpConfig::default();
    s.take("source_voxel", &mut c.source_voxel)?;
    s.take("target_voxel", &mut c.target_voxel)?;
    s.take(
        "max_correspondence_distance",
        &mut c.max_correspondence_distance,
    )?;
    s.take("max_iterations", &mut c.max_iterations)?;
    s.take("translation_tolerance", &mut c.translation_tolerance)?;
    s.take("rotation_tolerance", &mut c.rotation_tolerance)?;
    s.take("normal_neighbours", &mut c.normal_neighbours)?;
    s.take("min_correspondences", &mut c.min_correspondences)?;
    s.take("pair_target_points", &mut c.pair_target_points)?;
    s.take("coarse_stride", &mut c.coarse_stride)?;
    s.take("normals_up_front", &mut c.normals_up_front)?;
    s.take("degeneracy_threshold", &mut c.degeneracy_threshold)?;
    s.take("min_planarity", &mut c.min_planarity)?;
    s.take("max_source_points", &mut c.max_source_points)?;
    let (mut name, mut k) = match c.kernel {
        IcpKernel::None => ("none".to_owned(), 0.0),
        IcpKernel::Huber { k } => ("huber".to_owned(), k),
        IcpKernel::Tukey { k } => ("tukey".to_owned(), k),
    };
    s.take("kernel", &mut name)?;
    s.take("kernel_threshold", &mut k)?;
    c.kernel = match name.as_str() {
        "none" => IcpKernel::None,
        "huber" => IcpKernel::Huber { k },
        "tukey" => IcpKernel::Tukey { k },
        other => {
            return Err(invalid(format!(
                "{what}: unknown kernel {other:?}: use \"huber\", \"tukey\" or \"none\""
            )));
        }
    };
    s.finish()?;
    c.validate().map_err(|e| e.to_py())?;
    Ok(c)
}

/// `LoamConfig` from keywords: its fields and the feature extraction's (`layout` as
/// "vlp16" | "hdl32e" | "os1_128" or `(rings, lowest_elevation_deg, highest_elevation_deg)`).
fn loam_config(dict: Option<&Bound<'_, PyDict>>, what: &'static str) -> PyResult<LoamConfig> {
    let mut s = Settings::new(dict, what)?;
    let mut c = LoamConfig::default();
    s.take("local_map_edge_voxel", &mut c.local_map_edge_voxel)?;
    s.take("local_map_plane_voxel", &mut c.local_map_plane_voxel)?;
    s.take("source_edge_voxel", &mut c.source_edge_voxel)?;
    s.take("source_plane_voxel", &mut c.source_plane_voxel)?;
    s.take("search_cell", &mut c.search_cell)?;
    s.take("neighbours", &mut c.neighbours)?;
    s.take("max_neighbour_distance", &mut c.max_neighbour_distance)?;
    s.take("line_eigenvalue_ratio", &mut c.line_eigenvalue_ratio)?;
    s.take("plane_fit_tolerance", &mut c.plane_fit_tolerance)?;
    s.take("tukey_threshold", &mut c.tukey_threshold)?;
    s.take("initial_tukey_threshold", &mut c.initial_tukey_threshold)?;
    s.take("rematch_motion", &mut c.rematch_motion)?;
    s.take("max_iterations", &mut c.max_iterations)?;
    s.take("translation_tolerance", &mut c.translation_tolerance)?;
    s.take("rotation_tolerance", &mut c.rotation_tolerance)?;
    s.take("min_correspondences", &mut c.min_correspondences)?;
    let f = &mut c.features;
    s.take("feature_neighbours", &mut f.neighbours)?;
    s.take("sectors", &mut f.sectors)?;
    s.take("max_edges_per_sector", &mut f.max_edges_per_sector)?;
    s.take("max_planes_per_sector", &mut f.max_planes_per_sector)?;
    s.take("edge_min_roughness", &mut f.edge_min_roughness)?;
    s.take("edge_min_sharpness", &mut f.edge_min_sharpness)?;
    s.take("plane_max_roughness", &mut f.plane_max_roughness)?;
    s.take("min_range", &mut f.min_range)?;
    s.take("max_range", &mut f.max_range)?;
    if let Some(layout) = s.take_raw("layout")? {
        f.layout = lidar_layout(&layout, what)?;
    }
    s.finish()?;
    Ok(c)
}

fn lidar_layout(v: &Bound<'_, PyAny>, what: &str) -> PyResult<LidarLayout> {
    if let Ok(name) = v.extract::<String>() {
        return match name.as_str() {
            "vlp16" => Ok(LidarLayout::VLP16),
            "hdl32e" => Ok(LidarLayout::HDL32E),
            "os1_128" => Ok(LidarLayout::OS1_128),
            other => Err(invalid(format!(
                "{what}: unknown layout {other:?}: use \"vlp16\", \"hdl32e\", \"os1_128\" or (rings, lowest_elevation_deg, highest_elevation_deg)"
            ))),
        };
    }
    let (rings, lowest_elevation_deg, highest_elevation_deg) = v
        .extract::<(u16, f64, f64)>()
        .map_err(|_| invalid(format!("{what}: layout must be a name or (rings, lowest_elevation_deg, highest_elevation_deg)")))?;
    let layout = LidarLayout {
        rings,
        lowest_elevation_deg,
        highest_elevation_deg,
    };
    layout.validate().map_err(|e| e.to_py())?;
    Ok(layout)
}
