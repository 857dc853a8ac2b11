//! A prepared target: points in a k-d tree, with PCA normals for point-to-plane.

use std::cell::OnceCell;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use nalgebra::{Matrix3, Point3, Vector3};
use slam_core::{PointCloud, Pose3, RegistrationError};

use crate::config::IcpConfig;
use crate::neighbour_cache::{Candidate, NearestSearch};
use crate::sym3::symmetric_eigen3;

/// Target points, their k-d tree and (optionally) unit normals.
pub struct PreparedTarget {
    pub(crate) points: Vec<Point3<f64>>,
    /// In f32: half the memory traffic of f64 per query; targets span far less than the
    /// kilometres where f32 would lose millimetres.
    pub(crate) tree: ImmutableKdTree<f32, 3>,
    normals: Option<NormalCache>,
}

/// PCA normals of the target points, computed once each on first use.
struct NormalCache {
    k: std::num::NonZero<usize>,
    cells: Vec<OnceCell<Vector3<f64>>>,
}

impl std::fmt::Debug for PreparedTarget {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PreparedTarget")
            .field("points", &self.points.len())
            .finish_non_exhaustive()
    }
}

/// Finite points of `cloud` as f64, voxel-filtered when `voxel > 0`.
pub(crate) fn finite_points(cloud: &PointCloud, voxel: f32) -> Vec<Point3<f64>> {
    if voxel > 0.0 {
        // Points only (the channels would be averaged for nothing); the downsampling skips
        // non-finite points itself.
        let c = PointCloud::from_points(cloud.points().to_vec());
        if let Ok(down) = c.voxel_downsample(voxel) {
            return down.points().iter().map(|p| p.cast::<f64>()).collect();
        }
    }
    cloud
        .points()
        .iter()
        .filter(|p| p.iter().all(|v| v.is_finite()))
        .map(|p| p.cast::<f64>())
        .collect()
}

impl PreparedTarget {
    /// Build the tree (and normals from `normal_neighbours` nearest points when asked).
    pub(crate) fn new(
        points: Vec<Point3<f64>>,
        normal_neighbours: Option<usize>,
        min_points: usize,
    ) -> Result<Self, RegistrationError> {
        if points.len() < min_points {
            return Err(RegistrationError::TooFewPoints {
                what: "target",
                points: points.len(),
                required: min_points,
            });
        }
        #[allow(clippy::cast_possible_truncation)]
        let coords: Vec<[f32; 3]> = points
            .iter()
            .map(|p| [p.x as f32, p.y as f32, p.z as f32])
            .collect();
        let tree = ImmutableKdTree::new_from_slice(&coords)
            .map_err(|e| RegistrationError::Degenerate(format!("k-d tree: {e:?}")))?;
        // Normals are computed on first use: an alignment touches only the target points that
        // are some source point's nearest neighbour, a fraction of a local map's points.
        let normals = normal_neighbours.map(|k| NormalCache {
            k: std::num::NonZero::new(k.max(3)).unwrap_or(std::num::NonZero::<usize>::MIN),
            cells: (0..points.len()).map(|_| OnceCell::new()).collect(),
        });
        Ok(Self {
            points,
            tree,
            normals,
        })
    }

    /// The unit normal of target point `i` (PCA of its nearest neighbours), when the target was
    /// prepared with normals.
    pub(crate) fn normal(&self, i: usize) -> Option<Vector3<f64>> {
        let cache = self.normals.as_ref()?;
        Some(*cache.cells[i].get_or_init(|| {
            let p = self.points[i];
            #[allow(clippy::cast_possible_truncation)]
            let nn = self
                .tree
                .query(&[p.x as f32, p.y as f32, p.z as f32])
                .nearest_n::<SquaredEuclidean<f32>>(cache.k)
                .execute();
            let pts: Vec<Vector3<f64>> = nn
                .iter()
                .map(|r| self.points[r.item as usize].coords)
                .collect();
            let mean = pts.iter().sum::<Vector3<f64>>() / pts.len() as f64;
            let cov = pts.iter().fold(Matrix3::zeros(), |m, q| {
                m + (q - mean) * (q - mean).transpose()
            });
            // Eigenvalues ascending: the first vector is the normal.
            symmetric_eigen3(&cov).vectors.column(0).into_owned()
        }))
    }
}

impl PreparedTarget {
    /// The index of the target point nearest to `q` within `max_distance`.
    #[allow(clippy::cast_possible_truncation)]
    pub(crate) fn nearest_one(&self, q: &Point3<f64>, max_distance: f64) -> Option<usize> {
        let nn = self
            .tree
            .query(&[q.x as f32, q.y as f32, q.z as f32])
            .nearest_one::<SquaredEuclidean<f32>>()
            .execute();
        (f64::from(nn.distance) <= max_distance * max_distance).then_some(nn.item as usize)
    }
}

impl NearestSearch for PreparedTarget {
    #[allow(clippy::cast_possible_truncation)]
    fn nearest_into(&self, q: &Point3<f64>, n: usize, max_distance: f64, out: &mut Vec<Candidate>) {
        out.clear();
        let Some(n) = std::num::NonZero::new(n) else {
            return;
        };
        let nn = self
            .tree
            .query(&[q.x as f32, q.y as f32, q.z as f32])
            .nearest_n::<SquaredEuclidean<f32>>(n)
            .within::<SquaredEuclidean<f32>>((max_distance * max_distance) as f32)
            .execute();
        out.extend(nn.iter().map(|r| {
            let p = self.points[r.item as usize];
            Candidate {
                d2: r.distance,
                p: [p.x as f32, p.y as f32, p.z as f32],
                id: r.item,
            }
        }));
    }
}

impl PreparedTarget {
    /// Number of target points.
    #[must_use]
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the target has no points.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
}

/// The source points of `cloud` for `config` (finite, voxel-filtered), at least
/// `min_correspondences` of them.
pub(crate) fn prepare_source_points(
    config: &IcpConfig,
    cloud: &PointCloud,
) -> Result<Vec<Point3<f64>>, RegistrationError> {
    config.validate()?;
    let pts = finite_points(cloud, config.source_voxel);
    if pts.len() < config.min_correspondences {
        return Err(RegistrationError::TooFewPoints {
            what: "source",
            points: pts.len(),
            required: config.min_correspondences,
        });
    }
    Ok(pts)
}

/// Prepared sources moved by their poses, as one cloud (a local map).
pub(crate) fn merge_sources(parts: &[(&Vec<Point3<f64>>, Pose3)]) -> PointCloud {
    let pts: Vec<Point3<f32>> = parts
        .iter()
        .flat_map(|(s, pose)| s.iter().map(move |p| (pose * p).cast::<f32>()))
        .collect();
    PointCloud::from_points(pts)
}
