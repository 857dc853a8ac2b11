//! LOAM's correspondences: a source edge point paired with the line through its nearest target
//! edge points, a planar point with the plane through its nearest planar points (a patch's
//! PCA), and the Tukey-weighted normal equations of those pairs.

use nalgebra::{Matrix3, Matrix6, Point3, Vector3, Vector6};
use slam_core::Pose3;

use crate::kernel::IcpKernel;
use crate::loam::{LoamConfig, LoamTarget};
use crate::loam_features::LoamFeatures;
use crate::neighbour_cache::{Candidate, NeighbourCache, Neighbours};
use crate::sym3::{Eigen3, symmetric_eigen3};
use crate::voxel_hash_map::VoxelHashMap;

/// Mean and eigen-decomposition of a patch's covariance (eigenvalues ascending).
pub(crate) fn patch_pca(patch: &[Point3<f64>]) -> (Vector3<f64>, Eigen3) {
    let n = patch.len() as f64;
    let mean = patch.iter().map(|p| p.coords).sum::<Vector3<f64>>() / n;
    let cov = patch.iter().fold(Matrix3::zeros(), |m, p| {
        let d = p.coords - mean;
        m + d * d.transpose()
    }) / n;
    (mean, symmetric_eigen3(&cov))
}

/// A line (two residual directions across it) or a plane (one: its normal) through `c`. The
/// residual of direction `n` at a point `x` is `n . (x - c)`.
#[derive(Clone, Copy)]
pub(crate) struct Fit {
    normals: [Vector3<f64>; 2],
    len: usize,
    c: Vector3<f64>,
}

impl Fit {
    /// The line through a patch whose largest covariance eigenvalue exceeds the middle one
    /// `ratio` times.
    fn line(patch: &[Point3<f64>], ratio: f64) -> Option<Self> {
        let (c, eig) = patch_pca(patch);
        (eig.values[2] > ratio * eig.values[1]).then(|| Self {
            normals: [
                eig.vectors.column(0).into_owned(),
                eig.vectors.column(1).into_owned(),
            ],
            len: 2,
            c,
        })
    }

    /// The plane through a patch that spans two dimensions and whose points all lie within
    /// `tolerance` of it.
    fn plane(patch: &[Point3<f64>], tolerance: f64) -> Option<Self> {
        let (c, eig) = patch_pca(patch);
        // A patch spread along a line (one scan line) fixes no plane.
        if eig.values[1] < 0.01 * eig.values[2] {
            return None;
        }
        let n = eig.vectors.column(0).into_owned();
        if patch
            .iter()
            .any(|q| n.dot(&(q.coords - c)).abs() > tolerance)
        {
            return None;
        }
        Some(Self {
            normals: [n, Vector3::zeros()],
            len: 1,
            c,
        })
    }
}

/// A source point and the line or plane it is matched to.
pub(crate) struct Correspondence {
    source: Point3<f64>,
    fit: Fit,
}

impl Correspondence {
    /// The moved point, its residuals and its distance to the line or plane.
    fn at(&self, pose: &Pose3) -> (Point3<f64>, [f64; 2], f64) {
        let p = pose * self.source;
        let f = &self.fit;
        let d = p.coords - f.c;
        let r = [f.normals[0].dot(&d), f.normals[1].dot(&d)];
        let distance = if f.len == 2 {
            r[0].hypot(r[1])
        } else {
            r[0].abs()
        };
        (p, r, distance)
    }
}

pub(crate) struct Matcher<'a> {
    config: &'a LoamConfig,
    target: &'a LoamTarget,
    /// Slots: the source's edges, then its planar points.
    cache: NeighbourCache,
    /// The fit of each slot's latest neighbours, reused while they stay the same.
    fits: Vec<Option<Fit>>,
    found: Vec<Candidate>,
    patch: Vec<Point3<f64>>,
}

impl<'a> Matcher<'a> {
    pub(crate) fn new(
        config: &'a LoamConfig,
        target: &'a LoamTarget,
        source: &LoamFeatures,
    ) -> Self {
        let slots = source.edges.len() + source.planes.len();
        Self {
            config,
            target,
            // Twice the neighbours asked for: the margin that lets later matchings reuse them.
            cache: NeighbourCache::new(
                slots,
                config.neighbours,
                2 * config.neighbours,
                config.max_neighbour_distance,
            ),
            fits: vec![None; slots],
            found: Vec::with_capacity(config.neighbours),
            patch: Vec::with_capacity(config.neighbours),
        }
    }

    /// The line (`edge`) or plane through the target points of `map` nearest the moved source
    /// point `p`, when there are enough of them within reach and they fit one.
    fn fit(&mut self, slot: usize, map: &VoxelHashMap, p: &Point3<f64>, edge: bool) -> Option<Fit> {
        let c = self.config;
        let answer = self.cache.nearest(slot, map, p, &mut self.found);
        if answer == Neighbours::Unchanged {
            return self.fits[slot];
        }
        self.patch.clear();
        self.patch.extend(
            self.found
                .iter()
                .map(|c| Point3::new(f64::from(c.p[0]), f64::from(c.p[1]), f64::from(c.p[2]))),
        );
        let fit = match answer {
            Neighbours::TooFew => None,
            _ if edge => Fit::line(&self.patch, c.line_eigenvalue_ratio),
            _ => Fit::plane(&self.patch, c.plane_fit_tolerance),
        };
        self.fits[slot] = fit;
        fit
    }

    pub(crate) fn all(
        &mut self,
        source: &LoamFeatures,
        pose: &Pose3,
        out: &mut Vec<Correspondence>,
    ) {
        out.clear();
        let target = self.target;
        let mut slot = 0;
        for (points, map, edge) in [
            (&source.edges, target.edges(), true),
            (&source.planes, target.planes(), false),
        ] {
            for &s in points {
                if let Some(fit) = self.fit(slot, map, &(pose * s), edge) {
                    out.push(Correspondence { source: s, fit });
                }
                slot += 1;
            }
        }
    }
}

/// `J^T W J` and `J^T W e` of the correspondences at `pose` under Tukey threshold `k`, with the
/// number of correspondences of non-zero weight and their summed squared distances.
pub(crate) fn normal_equations(
    pairs: &[Correspondence],
    pose: &Pose3,
    k: f64,
) -> (Matrix6<f64>, Vector6<f64>, usize, f64) {
    let kernel = IcpKernel::Tukey { k };
    let mut h = Matrix6::zeros();
    let mut b = Vector6::zeros();
    let (mut used, mut sq) = (0, 0.0);
    for c in pairs {
        let (p, r, distance) = c.at(pose);
        let w = kernel.weight(distance);
        if w == 0.0 {
            continue;
        }
        used += 1;
        sq += distance * distance;
        for (n, r) in c.fit.normals[..c.fit.len].iter().zip(r) {
            // `[n; p x n]`: the row's Jacobian for a left perturbation.
            let x = p.coords.cross(n);
            let j = Vector6::new(n.x, n.y, n.z, x.x, x.y, x.z);
            h += j * j.transpose() * w;
            b += j * (r * w);
        }
    }
    (h, b, used, sq)
}
