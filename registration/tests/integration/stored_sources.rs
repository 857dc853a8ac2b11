//! A keyframe's prepared points written for an engine's keyframe store and read back.

use nalgebra::Point3;
use registration::{PointToPlaneIcp, PointToPointIcp};
use slam_core::{MapRegistrator, PointCloud, Registrator};

/// The ICP backends' prepared points come back bit for bit (the oracle: the points written),
/// bytes that are not whole points are refused, and LOAM keeps its features in memory.
#[test]
fn prepared_points_come_back_bit_for_bit() {
    let cloud = PointCloud::from_points(
        (0..500)
            .map(|i| {
                let t = i as f32 * 0.173;
                Point3::new(t.sin() * 7.0, t.cos() * 3.0 + 1e-4 * t, (0.37 * t).sin())
            })
            .collect(),
    );
    let plane = PointToPlaneIcp::default();
    let point = PointToPointIcp::default();
    let bits = |points: &[Point3<f64>]| -> Vec<u64> {
        points
            .iter()
            .flat_map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
            .collect()
    };
    let source = plane.keyframe_source(plane.prepare_source(&cloud).unwrap());
    assert!(!source.is_empty());
    let bytes = plane.stored_source(&source).unwrap();
    assert_eq!(bytes.len(), 24 * source.len());
    assert_eq!(bits(&plane.restored_source(&bytes).unwrap()), bits(&source));
    let coarse = point.keyframe_source(point.prepare_source(&cloud).unwrap());
    let back = point
        .restored_source(&point.stored_source(&coarse).unwrap())
        .unwrap();
    assert_eq!(bits(&back), bits(&coarse));
    assert!(plane.restored_source(&bytes[..bytes.len() - 1]).is_none());
    assert_eq!(plane.restored_source(&[]).unwrap().len(), 0);
    let loam = registration::LoamRegistrator::default();
    let features = loam.prepare_source(&cloud);
    if let Ok(features) = features {
        assert!(loam.stored_source(&features).is_none());
    }
    assert!(loam.restored_source(&bytes).is_none());
}
