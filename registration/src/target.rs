//! A prepared target: points in a k-d tree, with PCA normals for point-to-plane.

use std::cell::{OnceCell, RefCell};
use std::sync::OnceLock;

use rayon::prelude::*;

use kiddo::kd_tree::ConstructionError;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use nalgebra::{Matrix3, Point3, Vector3};
use slam_core::{Degeneracy, PointCloud, Pose3, RegistrationError};

use crate::config::IcpConfig;
use crate::matcher::Matcher;
use crate::neighbour_cache::{Candidate, NearestSearch};
use crate::sym3::symmetric_eigen3;
use crate::voxel_window::{KeptNormal, Snapshot, VoxelWindow};

/// A prepared target: its points indexed for queries, or, for a local map updated in place
/// ([`MapRegistrator::empty_map`](slam_core::MapRegistrator::empty_map)), the voxel window
/// they come from, indexed again on the first query after each change.
pub struct PreparedTarget {
    index: OnceCell<Result<TargetIndex, RegistrationError>>,
    window: Option<Box<Window>>,
    /// The neighbours the last alignment against this target found, for the next alignment of
    /// the same source points (a sweep's motion found right after the scan's registration).
    last_matcher: RefCell<Vec<MatcherMemo>>,
    /// An in-place map's index being built on a thread of its own for the window as it is now
    /// ([`Self::index_ahead`]): claimed by the next query, or dropped unclaimed when the window
    /// changes first.
    pending: RefCell<Option<std::thread::JoinHandle<WindowIndex>>>,
}

/// An in-place map's index with the voxels it was built from (`None` when it could not be
/// built).
type WindowIndex = (Result<TargetIndex, RegistrationError>, Option<BuiltFrom>);

/// The index of a window's `snapshot`: its centroids' k-d tree with the normals kept from
/// earlier indexes set (and every other one computed with `normals_up_front`), with what it was
/// built from. A function of the snapshot alone, so that it is the same on whichever thread
/// and at whichever time it runs.
fn window_index(
    snapshot: Snapshot,
    normals: Option<(usize, f64)>,
    normals_up_front: bool,
    min_points: usize,
) -> WindowIndex {
    let index = match TargetIndex::new(snapshot.centroids, normals, min_points) {
        Ok(index) => index,
        Err(e) => return (Err(e), None),
    };
    for (i, kept) in snapshot.kept.iter().enumerate() {
        if let Some(k) = kept {
            index.set_normal(i, k.normal);
        }
    }
    if normals_up_front {
        index.compute_all_normals();
    }
    let built = BuiltFrom {
        slots: snapshot.slots,
        counts: snapshot.counts,
        kept: snapshot.kept,
    };
    (Ok(index), Some(built))
}

/// Neighbour caches kept for later alignments: a scan's few points (the wide stages', a
/// recheck's first pass) and its many (the fine stage's, the sweep's) alternate.
const KEPT_MATCHERS: usize = 2;

/// An alignment's neighbour cache with what it is valid for.
struct MatcherMemo {
    /// The source points, in order, whose slots it holds.
    points: Vec<Point3<f64>>,
    /// The neighbours a pair reads.
    pair_points: usize,
    matcher: Matcher,
}

/// A window of placed sources and how its index is built.
struct Window {
    voxels: VoxelWindow,
    normals: Option<(usize, f64)>,
    normals_up_front: bool,
    min_points: usize,
    /// What the current index's points are, slot by slot, so that the normals it computes can
    /// be kept in their voxels for the next index.
    built: OnceCell<BuiltFrom>,
}

/// The voxels an index of a window was built from, in its slot order.
struct BuiltFrom {
    slots: Vec<u32>,
    counts: Vec<u32>,
    kept: Vec<Option<KeptNormal>>,
}

/// Target points, their k-d tree and (optionally) unit normals.
pub(crate) struct TargetIndex {
    pub(crate) points: Vec<Point3<f64>>,
    /// In f32: half the memory traffic of f64 per query; targets span far less than the
    /// kilometres where f32 would lose millimetres.
    pub(crate) tree: ImmutableKdTree<f32, 3>,
    normals: Option<NormalCache>,
}

/// PCA normals of the target points, computed once each on first use.
struct NormalCache {
    k: std::num::NonZero<usize>,
    /// `IcpConfig::min_planarity`.
    min_planarity: f64,
    /// `None`: the neighbourhood is not plane-like enough. Filled from several threads at once
    /// during a correspondence search.
    cells: Vec<OnceLock<Option<Vector3<f64>>>>,
}

impl std::fmt::Debug for PreparedTarget {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let points = match (self.index.get(), &self.window) {
            (Some(Ok(index)), _) => index.points.len(),
            (_, Some(w)) => w.voxels.len(),
            _ => 0,
        };
        f.debug_struct("PreparedTarget")
            .field("points", &points)
            .field("in_place", &self.window.is_some())
            .finish_non_exhaustive()
    }
}

impl PreparedTarget {
    /// A target of `points` (see [`TargetIndex::new`]).
    pub(crate) fn new(
        points: Vec<Point3<f64>>,
        normals: Option<(usize, f64)>,
        min_points: usize,
    ) -> Result<Self, RegistrationError> {
        let index = TargetIndex::new(points, normals, min_points)?;
        Ok(Self {
            index: OnceCell::from(Ok(index)),
            window: None,
            last_matcher: RefCell::new(Vec::new()),
            pending: RefCell::new(None),
        })
    }

    /// An empty local map of voxel centroids (`voxel` metres, finite and positive) that
    /// sources are added to and removed from in place.
    pub(crate) fn window(
        voxel: f32,
        normals: Option<(usize, f64)>,
        normals_up_front: bool,
        min_points: usize,
    ) -> Self {
        Self {
            index: OnceCell::new(),
            last_matcher: RefCell::new(Vec::new()),
            pending: RefCell::new(None),
            window: Some(Box::new(Window {
                voxels: VoxelWindow::new(voxel),
                normals,
                normals_up_front,
                min_points,
                built: OnceCell::new(),
            })),
        }
    }

    /// Keeps in the window's voxels the normals the current index computed or reused, for the
    /// next index: a keyframe entering or leaving the window moves a centroid by millimetres,
    /// and recomputing every normal an alignment touches cost more than the alignment itself
    /// (see [`crate::voxel_window::MAX_NORMAL_REUSE`] for how long one is kept).
    fn keep_normals(&mut self) {
        // An index built ahead for a window that changed before any query was never used: as
        // if it had not been built (the thread finishes alone and its result is dropped).
        self.pending.get_mut().take();
        let Some(w) = self.window.as_mut() else {
            return;
        };
        let (Some(Ok(index)), Some(built)) = (self.index.take(), w.built.take()) else {
            return;
        };
        for (i, &slot) in built.slots.iter().enumerate() {
            let Some(&normal) = index.computed_normal(i) else {
                continue;
            };
            let kept = match built.kept[i] {
                Some(k) => KeptNormal {
                    reused: k.reused + 1,
                    ..k
                },
                None => KeptNormal {
                    normal,
                    count: built.counts[i],
                    reused: 0,
                },
            };
            w.voxels.keep_normal(slot, kept);
        }
    }

    /// Adds `source` moved by `pose` under `key` to an in-place map (replacing what `key`
    /// held); a target prepared whole is left as it is.
    pub(crate) fn add_part(&mut self, key: u32, source: &[Point3<f64>], pose: &Pose3) {
        self.keep_normals();
        if let Some(w) = self.window.as_mut() {
            w.voxels.add(key, source, pose);
            self.index = OnceCell::new();
            self.last_matcher = RefCell::new(Vec::new());
        }
    }

    /// Removes what `key` added to an in-place map.
    pub(crate) fn remove_part(&mut self, key: u32) {
        self.keep_normals();
        if let Some(w) = self.window.as_mut() {
            w.voxels.remove(key);
            self.index = OnceCell::new();
            self.last_matcher = RefCell::new(Vec::new());
        }
    }

    /// The indexed points, built now when an in-place map changed since the last query.
    ///
    /// # Errors
    /// Too few points, or points that do not span a plane (see [`TargetIndex::new`]).
    pub(crate) fn index(&self) -> Result<&TargetIndex, RegistrationError> {
        self.index
            .get_or_init(|| {
                let Some(w) = self.window.as_ref() else {
                    // A target prepared whole is built when prepared.
                    return Err(RegistrationError::TooFewPoints {
                        what: "target",
                        points: 0,
                        required: 1,
                    });
                };
                let ahead = self.pending.borrow_mut().take();
                // A thread that could not finish (it cannot panic on any window) leaves the
                // index to be built here.
                let (index, built) = ahead.and_then(|h| h.join().ok()).unwrap_or_else(|| {
                    window_index(
                        w.voxels.snapshot(),
                        w.normals,
                        w.normals_up_front,
                        w.min_points,
                    )
                });
                if let Some(built) = built {
                    // Set only here, right after the index it describes is built.
                    let _ = w.built.set(built);
                }
                index
            })
            .as_ref()
            .map_err(Clone::clone)
    }
}

impl PreparedTarget {
    /// Builds the index (when an in-place map changed since the last one) on a thread of its
    /// own while `beside` runs on this one ([`Self::index_ahead`], then claimed). The index is
    /// the one the first query would build; an error stays for that query to report.
    pub(crate) fn index_beside(&mut self, beside: &mut (dyn FnMut() + Send)) {
        // Nothing to start when built already (the map did not change since) or under way.
        self.index_ahead();
        beside();
        // Claimed (or, without a thread, built here).
        let _ = self.index();
    }

    /// Starts building the index of an in-place map that changed since its last one on a
    /// thread of its own, and returns at once: the next query (or [`Self::index_beside`])
    /// claims it, waiting for it if need be. The index is the one that query would build (its
    /// window's snapshot, taken now, is all it reads); a change to the window before then
    /// drops it unused. Nothing to do for a target prepared whole, an index built already or
    /// one under way; without a thread the query builds it as before.
    pub(crate) fn index_ahead(&mut self) {
        if self.index.get().is_some() || self.pending.get_mut().is_some() {
            return;
        }
        let Some(w) = self.window.as_ref() else {
            return;
        };
        let snapshot = w.voxels.snapshot();
        let (normals, up_front, min_points) = (w.normals, w.normals_up_front, w.min_points);
        if let Ok(handle) = std::thread::Builder::new()
            .name("local-map-index".into())
            .spawn(move || window_index(snapshot, normals, up_front, min_points))
        {
            *self.pending.get_mut() = Some(handle);
        }
    }

    /// Keeps `matcher`, the neighbour cache an alignment of `points` (`pair_points` a pair)
    /// built against this target, for [`Self::take_matcher`].
    pub(crate) fn keep_matcher(
        &self,
        points: &[Point3<f64>],
        pair_points: usize,
        matcher: Matcher,
    ) {
        let mut kept = self.last_matcher.borrow_mut();
        if kept.len() >= KEPT_MATCHERS {
            kept.remove(0);
        }
        kept.push(MatcherMemo {
            points: points.to_vec(),
            pair_points,
            matcher,
        });
    }

    /// The kept neighbour cache when it was built for exactly `points` with the same pair size
    /// since the target last changed, set to reach `max_distance` and search `first_radius`
    /// away first; otherwise a new one. What a kept slot proves (no target point outside its
    /// kept ones lies nearer than its clear radius) holds whatever the reach, so its answers
    /// are those of fresh searches ([`crate::neighbour_cache`]): reusing it changes no result,
    /// only the searches run. An alignment run again from another start, the wide stages one
    /// after the other and the sweep after the scan's registration all pair the same points.
    pub(crate) fn matcher_for(
        &self,
        points: &[Point3<f64>],
        pair_points: usize,
        max_distance: f64,
        first_radius: f64,
    ) -> Matcher {
        let kept = {
            let mut memos = self.last_matcher.borrow_mut();
            memos
                .iter()
                .position(|memo| memo.points == points && memo.pair_points == pair_points)
                .map(|at| memos.remove(at))
        };
        match kept {
            Some(memo) => memo.matcher.with_reach(max_distance, first_radius),
            None => Matcher::new(
                points.len(),
                pair_points,
                (2 * pair_points).max(4),
                max_distance,
                first_radius,
            ),
        }
    }
}

/// Finite points of `cloud` as f64, voxel-filtered when `voxel > 0`. A finite point too far out
/// for a voxel key (a garbled return, not a measurement) is dropped with the non-finite ones
/// ([`PointCloud::voxel_downsample_keyable`]), so that it cannot turn the thinning off for the
/// whole cloud.
pub(crate) fn finite_points(cloud: &PointCloud, voxel: f32) -> Vec<Point3<f64>> {
    if voxel > 0.0 {
        // Points only (the channels would be averaged for nothing); the downsampling skips
        // non-finite points itself.
        let c = PointCloud::from_points(cloud.points().to_vec());
        if let Ok((down, _)) = c.voxel_downsample_keyable(voxel) {
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

/// Share of the points, nearest the median point, whose spread decides whether a target is
/// degenerate: a few absurd points must not hide the spread of the rest.
const SPREAD_SHARE: f64 = 0.9;

/// How many directions `points` spread along (0 to 3): the eigenvalues of the covariance of
/// the 90 % of them nearest their coordinate-wise median whose standard deviation exceeds both
/// 1e-6 of the largest one and what f32 storage can resolve at their distance from the origin
/// (plus 1e-6 m).
fn spread_dimensions(points: &[Point3<f64>]) -> usize {
    if points.is_empty() {
        return 0;
    }
    let median = |axis: usize| {
        let mut v: Vec<f64> = points.iter().map(|p| p[axis]).collect();
        let mid = v.len() / 2;
        *v.select_nth_unstable_by(mid, f64::total_cmp).1
    };
    let centre = Vector3::new(median(0), median(1), median(2));
    let mut near: Vec<(f64, usize)> = points
        .iter()
        .enumerate()
        .map(|(i, p)| ((p.coords - centre).norm_squared(), i))
        .collect();
    let keep = ((near.len() as f64 * SPREAD_SHARE).ceil() as usize).clamp(1, near.len());
    near.select_nth_unstable_by(keep - 1, |a, b| a.0.total_cmp(&b.0));
    let near = &near[..keep];
    let n = near.len() as f64;
    let mean = near
        .iter()
        .map(|&(_, i)| points[i].coords)
        .sum::<Vector3<f64>>()
        / n;
    let cov = near.iter().fold(Matrix3::zeros(), |m, &(_, i)| {
        let d = points[i].coords - mean;
        m + d * d.transpose()
    }) / n;
    let sigma = symmetric_eigen3(&cov).values.map(|v| v.max(0.0).sqrt());
    let floor = 1e-6 + f64::from(f32::EPSILON) * mean.amax();
    let tolerance = floor.max(1e-6 * sigma.max());
    sigma.iter().filter(|&&s| s > tolerance).count()
}

impl TargetIndex {
    /// Build the tree (and normals from `normals.0` nearest points, kept where the
    /// neighbourhood's planarity reaches `normals.1`, when asked).
    /// Coincident or collinear points are refused ([`Degeneracy::DegenerateTarget`]).
    pub(crate) fn new(
        points: Vec<Point3<f64>>,
        normals: Option<(usize, f64)>,
        min_points: usize,
    ) -> Result<Self, RegistrationError> {
        if points.len() < min_points {
            return Err(RegistrationError::TooFewPoints {
                what: "target",
                points: points.len(),
                required: min_points,
            });
        }
        let dimensions = spread_dimensions(&points);
        if dimensions < 2 {
            return Err(RegistrationError::Degenerate {
                cause: Degeneracy::DegenerateTarget { dimensions },
            });
        }
        let coords: Vec<[f32; 3]> = points
            .iter()
            .map(|p| [p.x as f32, p.y as f32, p.z as f32])
            .collect();
        let tree = ImmutableKdTree::new_from_slice(&coords).map_err(|e| match e {
            ConstructionError::AutoGeneratedItemIndexOverflow { item_count, .. } => {
                RegistrationError::TooManyPoints {
                    what: "target",
                    points: item_count,
                    max: u32::MAX as usize,
                }
            }
            ConstructionError::UnsplittableBucket { split_dim } => RegistrationError::Degenerate {
                cause: Degeneracy::CoincidentPoints { axis: split_dim },
            },
        })?;
        // Normals are computed on first use: an alignment touches only the target points that
        // are some source point's nearest neighbour, a fraction of a local map's points.
        let normals = normals.map(|(k, min_planarity)| NormalCache {
            k: std::num::NonZero::new(k.max(3)).unwrap_or(std::num::NonZero::<usize>::MIN),
            min_planarity,
            cells: (0..points.len()).map(|_| OnceLock::new()).collect(),
        });
        Ok(Self {
            points,
            tree,
            normals,
        })
    }

    /// Whether target point `i` may pair, and with which normal: `Some(None)` for a target
    /// prepared without normals (point-to-point), `Some(Some(n))` for a point with a normal,
    /// `None` for a point whose neighbourhood is not plane-like (`IcpConfig::min_planarity`).
    #[allow(clippy::option_option)] // The outer option is "may pair", the inner one the normal.
    pub(crate) fn pairing_normal(&self, i: usize) -> Option<Option<Vector3<f64>>> {
        if self.normals.is_none() {
            return Some(None);
        }
        self.normal(i).map(Some)
    }

    /// The unit normal of target point `i` (PCA of its nearest neighbours), when the target was
    /// prepared with normals and the neighbourhood is plane-like enough.
    pub(crate) fn normal(&self, i: usize) -> Option<Vector3<f64>> {
        let cache = self.normals.as_ref()?;
        *cache.cells[i]
            .get_or_init(|| pca_normal(&self.points, &self.tree, i, cache.k, cache.min_planarity))
    }

    /// The normal of point `i` when computed (or set) already (`&None` for a neighbourhood not
    /// plane-like enough); `None` when not computed yet or the target has no normals.
    fn computed_normal(&self, i: usize) -> Option<&Option<Vector3<f64>>> {
        self.normals.as_ref()?.cells.get(i)?.get()
    }

    /// Sets the normal of point `i` (one kept from an earlier index of the same voxel); a
    /// normal computed already stays.
    fn set_normal(&self, i: usize, normal: Option<Vector3<f64>>) {
        if let Some(cell) = self.normals.as_ref().and_then(|c| c.cells.get(i)) {
            let _ = cell.set(normal);
        }
    }

    /// Computes every normal not computed yet, on the machine's cores (each point's normal is
    /// the one [`Self::normal`] would give).
    pub(crate) fn compute_all_normals(&self) {
        if self.normals.is_some() {
            (0..self.points.len()).into_par_iter().for_each(|i| {
                self.normal(i);
            });
        }
    }
}

/// The normal of `points[i]` from the PCA of its `k` nearest points in `tree`, unless their
/// middle eigenvalue is below `min_planarity` times the largest (points along a line, whose
/// normal could be any direction across it).
fn pca_normal(
    points: &[Point3<f64>],
    tree: &ImmutableKdTree<f32, 3>,
    i: usize,
    k: std::num::NonZero<usize>,
    min_planarity: f64,
) -> Option<Vector3<f64>> {
    let p = points[i];
    let nn = tree
        .query(&[p.x as f32, p.y as f32, p.z as f32])
        .nearest_n::<SquaredEuclidean<f32>>(k)
        .execute();
    let n = nn.len().max(1) as f64;
    let mean = nn
        .iter()
        .fold(Vector3::zeros(), |m, r| m + points[r.item as usize].coords)
        / n;
    let cov = nn.iter().fold(Matrix3::zeros(), |m, r| {
        let d = points[r.item as usize].coords - mean;
        m + d * d.transpose()
    });
    // Eigenvalues ascending: the first vector is the normal.
    let eigen = symmetric_eigen3(&cov);
    // Rounding can leave a plane's middle eigenvalue a hair below 0: 0 keeps every normal.
    (eigen.values[1].max(0.0) >= min_planarity * eigen.values[2])
        .then(|| eigen.vectors.column(0).into_owned())
}

impl TargetIndex {
    /// The index of the target point nearest to `q` within `max_distance`.
    pub(crate) fn nearest_one(&self, q: &Point3<f64>, max_distance: f64) -> Option<usize> {
        let nn = self
            .tree
            .query(&[q.x as f32, q.y as f32, q.z as f32])
            .nearest_one::<SquaredEuclidean<f32>>()
            .execute();
        (f64::from(nn.distance) <= max_distance * max_distance).then_some(nn.item as usize)
    }
}

impl NearestSearch for TargetIndex {
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
    /// Number of target points (an in-place map's voxels; 0 for one too small to align
    /// against).
    #[must_use]
    pub fn len(&self) -> usize {
        match (&self.window, self.index()) {
            (Some(w), _) => w.voxels.len(),
            (None, Ok(index)) => index.points.len(),
            (None, Err(_)) => 0,
        }
    }

    /// Whether the target has no points.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
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

#[cfg(test)]
#[path = "target_tests.rs"]
mod tests;
