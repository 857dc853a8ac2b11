//! The target side the two ICP backends share: a target prepared from a cloud, or a voxel map
//! updated in place, with PCA normals when the backend's step pairs against planes.

use nalgebra::Point3;
use slam_core::{PointCloud, Pose3, RegistrationError};

use crate::config::IcpConfig;
use crate::icp::IcpStep;
use crate::target::{PreparedTarget, finite_points, merge_sources};

/// The normal estimation `(neighbours, min planarity)` a backend stepping with `S` needs.
fn target_normals<S: IcpStep>(config: &IcpConfig) -> Option<(usize, f64)> {
    S::TARGET_NORMALS.then_some((config.normal_neighbours, config.min_planarity))
}

/// A target of `cloud`'s finite points (voxel-filtered) for a backend stepping with `S`, its
/// normals computed now when [`IcpConfig::normals_up_front`] asks so.
pub(crate) fn prepare_target<S: IcpStep>(
    config: &IcpConfig,
    cloud: &PointCloud,
) -> Result<PreparedTarget, RegistrationError> {
    config.validate()?;
    let target = PreparedTarget::new(
        finite_points(cloud, config.target_voxel),
        target_normals::<S>(config),
        config.min_correspondences,
    )?;
    if S::TARGET_NORMALS && config.normals_up_front {
        target.index()?.compute_all_normals();
    }
    Ok(target)
}

/// [`prepare_target`] of the prepared sources moved by their poses (a local map).
pub(crate) fn target_from_sources<S: IcpStep>(
    config: &IcpConfig,
    parts: &[(&Vec<Point3<f64>>, Pose3)],
) -> Result<PreparedTarget, RegistrationError> {
    prepare_target::<S>(config, &merge_sources(parts))
}

/// An empty map of per-voxel sums updated in place, for a valid configuration with an
/// [`IcpConfig::target_voxel`] above zero.
pub(crate) fn empty_map<S: IcpStep>(config: &IcpConfig) -> Option<PreparedTarget> {
    let c = config;
    (c.target_voxel > 0.0 && c.validate().is_ok()).then(|| {
        PreparedTarget::window(
            c.target_voxel,
            target_normals::<S>(c),
            S::TARGET_NORMALS && c.normals_up_front,
            c.min_correspondences,
        )
    })
}

/// [`IcpConfig::source_voxel`] when above zero.
pub(crate) fn source_voxel(config: &IcpConfig) -> Option<f32> {
    (config.source_voxel > 0.0).then_some(config.source_voxel)
}

/// Points as their coordinates in little-endian f64, x, y, z in turn.
pub(crate) fn points_to_bytes(points: &[Point3<f64>]) -> Vec<u8> {
    points
        .iter()
        .flat_map(|p| [p.x, p.y, p.z])
        .flat_map(f64::to_le_bytes)
        .collect()
}

/// The points [`points_to_bytes`] wrote; `None` for bytes that are not whole points.
pub(crate) fn points_from_bytes(bytes: &[u8]) -> Option<Vec<Point3<f64>>> {
    if !bytes.len().is_multiple_of(24) {
        return None;
    }
    let value = |b: &[u8]| f64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]);
    Some(
        bytes
            .chunks_exact(24)
            .map(|c| Point3::new(value(&c[..8]), value(&c[8..16]), value(&c[16..])))
            .collect(),
    )
}
