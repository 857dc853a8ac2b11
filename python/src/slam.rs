//! `Slam`: the Graph-SLAM engine fed scan by scan, as spot-adapter's pipelines set it up.

use std::sync::{Mutex, MutexGuard};

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use slam_core::{GraphSlamConfig, PointCloud, Pose3, ScanInput, ScanOutcome, SkipReason};
use spot_adapter::pipelines::{
    LoamSlam, PointToPlaneSlam, loam_slam, point_to_plane_slam, scan_context_places, slam_config,
};

use crate::arrays::{cloud_from, cloud_to, pose_from, pose_to, poses_to, times_from};
use crate::config::Settings;
use crate::error::{ToPyErr, invalid};

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Slam>()?;
    Ok(())
}

/// The engine with either odometry backend.
enum Engine {
    PointToPlane(Box<PointToPlaneSlam>),
    Loam(Box<LoamSlam>),
}

/// Run `$body` with `$s` bound to the engine, whichever backend it has.
macro_rules! with_engine {
    ($engine:expr, $s:ident => $body:expr) => {
        match $engine {
            Engine::PointToPlane($s) => $body,
            Engine::Loam($s) => $body,
        }
    };
}

/// Graph-SLAM: register each scan against a local map of keyframes, close loops, optimise.
///
/// `Slam(odometry="point_to_plane" | "loam", body_T_lidar=None, place_recognition=False,
/// **config)`; config keywords are fields of the Rust `GraphSlamConfig` (metres, radians).
#[pyclass(module = "spot_nav")]
pub(crate) struct Slam {
    /// In a mutex: a pyclass must be `Sync`, and the place recognizer is only `Send`.
    engine: Mutex<Engine>,
    body_t_lidar: Pose3,
    /// The stamp given to a scan fed without one: the last stamp plus 0.1 s.
    last_stamp: Option<f64>,
    last_outcome: Option<ScanOutcome>,
}

fn slam_settings(dict: Option<&Bound<'_, PyDict>>) -> PyResult<GraphSlamConfig> {
    let mut s = Settings::new(dict, "Slam")?;
    let mut c = slam_config();
    s.take("keyframe_distance", &mut c.keyframe_distance)?;
    s.take("keyframe_rotation", &mut c.keyframe_rotation)?;
    s.take("local_map_keyframes", &mut c.local_map_keyframes)?;
    s.take("revisit_radius", &mut c.revisit_radius)?;
    s.take("revisit_min_inlier_ratio", &mut c.revisit_min_inlier_ratio)?;
    s.take("revisit_max_match_drop", &mut c.revisit_max_match_drop)?;
    s.take("loop_search_radius", &mut c.loop_search_radius)?;
    s.take("loop_neighbours", &mut c.loop_neighbours)?;
    s.take(
        "loop_max_mean_squared_error",
        &mut c.loop_max_mean_squared_error,
    )?;
    s.take("loop_min_keyframe_gap", &mut c.loop_min_keyframe_gap)?;
    s.take("loop_max_refine_shift", &mut c.loop_max_refine_shift)?;
    s.take("loop_max_drift_rate", &mut c.loop_max_drift_rate)?;
    s.take(
        "loop_max_height_drift_rate",
        &mut c.loop_max_height_drift_rate,
    )?;
    s.take("map_voxel_size", &mut c.map_voxel_size)?;
    s.take("keyframe_scan_spacing", &mut c.keyframe_scan_spacing)?;
    s.take("dense_scan_points", &mut c.dense_scan_points)?;
    s.take("min_scan_points", &mut c.min_scan_points)?;
    s.take("odometry_gravity", &mut c.odometry_gravity)?;
    s.take("deskew", &mut c.deskew)?;
    s.take("sweep_motion", &mut c.sweep_motion)?;
    s.take("inline_loop_closure", &mut c.inline_loop_closure)?;
    s.finish()?;
    Ok(c)
}

fn skip_name(reason: SkipReason) -> &'static str {
    match reason {
        SkipReason::OutOfOrderStamp => "skipped: out-of-order stamp",
        SkipReason::NonFiniteOdometry => "skipped: non-finite odometry",
        SkipReason::TooFewPoints => "skipped: too few points",
        SkipReason::PreparationFailed => "skipped: preparation failed",
        SkipReason::AwaitingVelocity => "skipped: awaiting velocity",
        SkipReason::NonFinitePose => "skipped: non-finite pose",
        _ => "skipped",
    }
}

impl Slam {
    /// The engine (a panic inside a previous call cannot leave it half-updated in a way that
    /// matters more than the panic itself, so a poisoned lock is taken as it is).
    fn engine(&self) -> MutexGuard<'_, Engine> {
        self.engine
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

#[pymethods]
impl Slam {
    #[new]
    #[pyo3(signature = (odometry = "point_to_plane", body_T_lidar = None, place_recognition = false, **config))]
    #[allow(non_snake_case)]
    fn new(
        odometry: &str,
        body_T_lidar: Option<&Bound<'_, PyAny>>,
        place_recognition: bool,
        config: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let c = slam_settings(config)?;
        let mut engine = match odometry {
            "point_to_plane" => {
                Engine::PointToPlane(Box::new(point_to_plane_slam(c).map_err(|e| e.to_py())?))
            }
            "loam" => Engine::Loam(Box::new(loam_slam(c).map_err(|e| e.to_py())?)),
            other => {
                return Err(invalid(format!(
                    "unknown odometry {other:?}: use \"point_to_plane\" or \"loam\""
                )));
            }
        };
        if place_recognition {
            engine = match engine {
                Engine::PointToPlane(s) => {
                    Engine::PointToPlane(Box::new(s.with_place_recognizer(scan_context_places())))
                }
                Engine::Loam(s) => {
                    Engine::Loam(Box::new(s.with_place_recognizer(scan_context_places())))
                }
            };
        }
        let body_t_lidar = match body_T_lidar {
            Some(p) if !p.is_none() => pose_from(p, "body_T_lidar")?,
            _ => Pose3::identity(),
        };
        Ok(Self {
            engine: Mutex::new(engine),
            body_t_lidar,
            last_stamp: None,
            last_outcome: None,
        })
    }

    /// Feed one scan (`N x 3`, LiDAR frame) and return its pose `map_T_lidar` (4 x 4), or `None`
    /// when the engine skipped it (`last_outcome` says why). The map frame is the odometry's
    /// frame when scans come with odometry, else the first scan's LiDAR frame.
    ///
    /// `stamp`: seconds, increasing (default: the last plus 0.1 s). `point_times`: per-point
    /// seconds relative to the stamp, for deskewing (a 1-D float32 or float64 array, read in
    /// place, or a sequence of numbers). `odometry`: the robot's `odom_T_body`
    /// (4 x 4) at the stamp; without it the engine predicts from its own velocity.
    #[pyo3(signature = (points, stamp = None, point_times = None, odometry = None))]
    fn register_frame<'py>(
        &mut self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        stamp: Option<f64>,
        point_times: Option<&Bound<'py, PyAny>>,
        odometry: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Option<Bound<'py, numpy::PyArray2<f64>>>> {
        let mut cloud: PointCloud = cloud_from(points, "points")?;
        if let Some(t) = point_times.filter(|t| !t.is_none()) {
            let times = times_from(t, "point_times")?;
            cloud = cloud.with_time(times).map_err(|e| e.to_py())?;
        }
        let odom_t_body = match odometry {
            Some(o) if !o.is_none() => Some(pose_from(o, "odometry")?),
            _ => None,
        };
        let stamp = stamp.unwrap_or_else(|| self.last_stamp.map_or(0.0, |s| s + 0.1));
        self.last_stamp = Some(stamp);
        let body_t_lidar = self.body_t_lidar;
        let mut guard = self.engine();
        let engine = &mut *guard;
        let (outcome, pose) = py.detach(|| {
            let input = ScanInput {
                stamp,
                odom_t_body,
                body_t_lidar,
                cloud: &cloud,
                gyro_orientation: None,
            };
            with_engine!(engine, s => {
                let outcome = s.process(&input);
                (outcome, s.current_lidar_pose())
            })
        });
        drop(guard);
        self.last_outcome = Some(outcome);
        Ok(match outcome {
            ScanOutcome::Skipped(_) => None,
            _ => pose.map(|p| pose_to(py, &p)),
        })
    }

    /// What happened to the last scan: "keyframe", "tracked" or "skipped: <reason>".
    #[getter]
    fn last_outcome(&self) -> Option<&'static str> {
        self.last_outcome.map(|o| match o {
            ScanOutcome::Keyframe { .. } => "keyframe",
            ScanOutcome::Tracked { .. } => "tracked",
            ScanOutcome::Skipped(r) => skip_name(r),
        })
    }

    /// Every accepted scan's `map_T_lidar`, `N x 4 x 4` (loop closures correct them too).
    #[getter]
    fn poses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let t = with_engine!(&*self.engine(), s => s.scan_trajectory());
        poses_to(py, t.into_iter().map(|p| p.pose))
    }

    /// The stamps of `poses`, seconds.
    #[getter]
    fn stamps(&self) -> Vec<f64> {
        with_engine!(&*self.engine(), s => s.scan_trajectory())
            .into_iter()
            .map(|p| p.stamp)
            .collect()
    }

    /// The keyframes' optimised `map_T_lidar`, `K x 4 x 4`.
    #[getter]
    fn keyframes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let t = with_engine!(&*self.engine(), s => s.keyframe_trajectory());
        poses_to(py, t.into_iter().map(|p| p.pose))
    }

    /// Loop-closure edges of the pose graph as `(older, newer)` keyframe indices.
    #[getter]
    fn loops<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let pairs: Vec<(usize, usize)> = with_engine!(&*self.engine(), s => s
            .loop_edges()
            .iter()
            .filter_map(|&k| s.graph().edges().get(k))
            .map(|e| (e.from.min(e.to), e.from.max(e.to)))
            .collect());
        PyList::new(py, pairs)
    }

    /// The engine's running totals as a dict (scans, keyframes, loops closed, skips, timings).
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let r = with_engine!(&*self.engine(), s => s.report().clone());
        let d = PyDict::new(py);
        d.set_item("scans", r.scans)?;
        d.set_item("keyframes", r.keyframes)?;
        d.set_item("whole_scans", r.whole_scans)?;
        d.set_item("revisits", r.revisits)?;
        d.set_item("loops_attempted", r.loops_attempted)?;
        d.set_item("loops_closed", r.loops_closed)?;
        d.set_item("loops_weighted_out", r.loops_weighted_out)?;
        d.set_item("fallbacks", r.fallbacks())?;
        d.set_item("odometry_faults", r.odometry_faults)?;
        d.set_item(
            "skipped",
            r.skipped_out_of_order
                + r.skipped_non_finite_odometry
                + r.skipped_too_few_points
                + r.skipped_preparation
                + r.skipped_awaiting_velocity
                + r.skipped_non_finite_pose,
        )?;
        d.set_item("mean_scan_ms", r.mean_scan_ms())?;
        d.set_item("max_scan_ms", r.max_scan_ms())?;
        Ok(d)
    }

    /// The map: every keyframe's cloud at its optimised pose, thinned to `voxel_size` metres
    /// (default: the engine's `map_voxel_size`), as an `N x 3` float32 array.
    #[pyo3(signature = (voxel_size = None))]
    fn map<'py>(&self, py: Python<'py>, voxel_size: Option<f32>) -> PyResult<Bound<'py, PyAny>> {
        let mut guard = self.engine();
        // `&mut`: the closure then needs the engine `Send`, not `Sync` (its caches are cells).
        let engine = &mut *guard;
        let cloud = py
            .detach(|| {
                with_engine!(engine, s => {
                    let v = voxel_size.unwrap_or(s.config().map_voxel_size);
                    s.map(v)
                })
            })
            .map_err(|e| e.to_py())?;
        cloud_to(py, &cloud)
    }

    fn __repr__(&self) -> String {
        let engine = self.engine();
        let (kind, r) = match &*engine {
            Engine::PointToPlane(s) => ("point_to_plane", s.report()),
            Engine::Loam(s) => ("loam", s.report()),
        };
        format!(
            "Slam(odometry={kind:?}, scans={}, keyframes={}, loops_closed={})",
            r.scans, r.keyframes, r.loops_closed
        )
    }
}
