//! The ICP loop shared by the two backends: correspondences on the target's k-d tree, a step
//! from the backend, convergence tests, and the final report.

use nalgebra::{Matrix6, Point3, SymmetricEigen, Vector3, Vector6};
use rayon::prelude::*;
use slam_core::{
    Alignment, Degeneracy, PointCloud, Pose3, RegistrationError, SweepAlignment, se3_exp, so3_hat,
};

use crate::alignment_inputs::checked_target_index;
use crate::alignment_report::alignment_report;
use crate::config::IcpConfig;
use crate::matcher::Matcher;
use crate::pool_awake::with_pool_awake;
use crate::target::{PreparedTarget, TargetIndex};

/// One correspondence: source point moved by the current pose, its target point, and the target
/// normal when available.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Pair {
    /// The source point's index.
    pub(crate) slot: usize,
    pub(crate) p: Point3<f64>,
    pub(crate) q: Point3<f64>,
    pub(crate) n: Option<Vector3<f64>>,
}

/// What sets an ICP backend apart: what it pairs a source point with, how it turns the pairs
/// into an update (applied on the left), and whether it registers sweeps.
pub(crate) trait IcpStep {
    /// Whether the target carries PCA normals (the step pairs points with planes).
    const TARGET_NORMALS: bool;
    /// How many nearest target points a source point is paired with (their mean; 1: the
    /// nearest, as textbook ICP).
    fn pair_points(config: &IcpConfig) -> usize;
    /// The residual of a pair (metres).
    fn residual(pair: &Pair) -> f64;
    /// The update `delta` with `pose <- exp(delta) pose`.
    ///
    /// # Errors
    /// When the pairs do not determine an update (a singular system, too few weighted pairs).
    fn step(pairs: &[Pair], weights: &[f64]) -> Result<Vector6<f64>, RegistrationError>;
    /// `J^T W J` of the pairs (left perturbation, `[rho; phi]`).
    fn information(pairs: &[Pair], weights: &[f64]) -> Matrix6<f64>;
    /// `(J^T W J, J^T W r)` when the step is a Gauss-Newton solve of them (`None` for a
    /// closed-form step).
    fn normal_equations(_pairs: &[Pair], _weights: &[f64]) -> Option<(Matrix6<f64>, Vector6<f64>)> {
        None
    }
    /// The registration of a sweep together with the correction to the velocity it was
    /// deskewed with ([`slam_core::Registrator::align_sweep`]); `None` when the backend has none.
    fn align_sweep(
        _config: &IcpConfig,
        _sweep: &PointCloud,
        _target: &PreparedTarget,
        _initial: &Pose3,
    ) -> Option<Result<SweepAlignment, RegistrationError>> {
        None
    }
}

/// The Gauss-Newton update `-H^-1 b` restricted to the directions the pairs constrain: the
/// eigenvectors of `H` whose eigenvalue is at least `floor` (the rest get no update; `None` when
/// none is left or the system is not finite).
fn well_constrained_step(h: &Matrix6<f64>, b: &Vector6<f64>, floor: f64) -> Option<Vector6<f64>> {
    if !(h.iter().all(|v| v.is_finite()) && b.iter().all(|v| v.is_finite())) {
        return None;
    }
    let eig = SymmetricEigen::new(*h);
    let mut delta = Vector6::zeros();
    let mut kept = 0;
    for (i, &lambda) in eig.eigenvalues.iter().enumerate() {
        if lambda >= floor && lambda > 0.0 {
            let v = eig.eigenvectors.column(i);
            delta -= v * (v.dot(b) / lambda);
            kept += 1;
        }
    }
    (kept > 0).then_some(delta)
}

/// Jacobian of `p` moved by a left perturbation: `d(exp(d) p)/dd = [I, -[p]x]`.
pub(crate) fn point_jacobian(p: &Point3<f64>) -> nalgebra::Matrix3x6<f64> {
    let mut j = nalgebra::Matrix3x6::zeros();
    j.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&nalgebra::Matrix3::identity());
    j.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&(-so3_hat(&p.coords)));
    j
}

/// Each coarse-stage source point moved by `pose` and its nearest target point within reach
/// (one plain search each), into `pairs`, in source order (searched in chunks on the machine's
/// cores).
fn coarse_correspondences(
    source: &[Point3<f64>],
    stride: usize,
    target: &TargetIndex,
    pose: &Pose3,
    max_distance: f64,
    pairs: &mut Vec<Pair>,
) {
    pairs.clear();
    let found: Vec<Vec<Pair>> = source
        .par_chunks(COARSE_CHUNK * stride)
        .enumerate()
        .map(|(c, chunk)| {
            chunk
                .iter()
                .enumerate()
                .step_by(stride)
                .filter_map(|(i, s)| {
                    let p = pose * s;
                    let t = target.nearest_one(&p, max_distance)?;
                    let n = target.pairing_normal(t)?;
                    Some(Pair {
                        slot: c * COARSE_CHUNK * stride + i,
                        p,
                        q: target.points[t],
                        n,
                    })
                })
                .collect()
        })
        .collect();
    for part in found {
        pairs.extend(part);
    }
}

/// Coarse-stage points searched a chunk.
const COARSE_CHUNK: usize = 64;

/// The coarse stage ends once an update moves less than this (metres) ...
const COARSE_TRANSLATION: f64 = 0.01;
/// ... and turns less than this (radians, 0.1 degrees).
const COARSE_ROTATION: f64 = 1.745e-3;

/// One robust step from `pairs`, applied to `pose`; returns the update's translation and
/// rotation norms.
fn update<S: IcpStep>(
    config: &IcpConfig,
    pairs: &[Pair],
    weights: &mut Vec<f64>,
    pose: &mut Pose3,
) -> Result<(f64, f64), RegistrationError> {
    weights.clear();
    weights.extend(pairs.iter().map(|p| config.kernel.weight(S::residual(p))));
    let constrained = if config.degeneracy_threshold > 0.0 {
        S::normal_equations(pairs, weights)
    } else {
        None
    };
    let delta = match constrained {
        Some((h, b)) => {
            let floor = config.degeneracy_threshold * weights.iter().sum::<f64>();
            well_constrained_step(&h, &b, floor).ok_or(RegistrationError::Degenerate {
                cause: Degeneracy::SingularNormalEquations,
            })?
        }
        None => S::step(pairs, weights)?,
    };
    if !delta.iter().all(|v| v.is_finite()) {
        return Err(RegistrationError::Degenerate {
            cause: Degeneracy::NonFiniteUpdate,
        });
    }
    *pose = se3_exp(&delta) * *pose;
    Ok((
        delta.fixed_rows::<3>(0).norm(),
        delta.fixed_rows::<3>(3).norm(),
    ))
}

/// ICP from `initial`, pairing each source point with the mean of its
/// [`IcpStep::pair_points`] nearest target points.
pub(crate) fn align<S: IcpStep>(
    config: &IcpConfig,
    source: &[Point3<f64>],
    target: &PreparedTarget,
    initial: &Pose3,
) -> Result<Alignment, RegistrationError> {
    let index = checked_target_index(config, target, initial)?;
    let pair_points = S::pair_points(config);
    let thinned = thin_source(source, config.max_source_points);
    let source = thinned.as_deref().unwrap_or(source);
    let matcher = target.matcher_for(
        source,
        pair_points,
        config.max_correspondence_distance,
        first_search_radius(config),
    );
    // On a worker of the thread pool, with another kept looking for work: each iteration's
    // search then forks onto it directly, not through the pool's queue from outside and not
    // by waking it from sleep (`with_pool_awake`).
    let mut left = None;
    let result =
        with_pool_awake(|| align_indexed::<S>(config, source, index, matcher, initial, &mut left));
    // The neighbours it found, for another alignment of the same points against the same
    // target (the next wide stage, a recheck, the sweep).
    if let Some(matcher) = left {
        target.keep_matcher(source, pair_points, matcher);
    }
    result
}

/// How far a neighbour search looks first: half the reach, or two target voxels, where the
/// tree prunes more (the HDL-32E pair aligns in 12.8 ms instead of 13.2 ms); farther only when
/// too few points lie that near.
pub(crate) fn first_search_radius(config: &IcpConfig) -> f64 {
    (0.5 * config.max_correspondence_distance).max(2.0 * f64::from(config.target_voxel))
}

/// [`align`] once the target is indexed and the source thinned; the neighbour cache it ends
/// with goes into `left`.
fn align_indexed<S: IcpStep>(
    config: &IcpConfig,
    source: &[Point3<f64>],
    target: &TargetIndex,
    mut matcher: Matcher,
    initial: &Pose3,
    left: &mut Option<Matcher>,
) -> Result<Alignment, RegistrationError> {
    let mut pairs = Vec::with_capacity(source.len());
    let mut pose = *initial;
    let mut converged = false;
    let mut iterations = 0;
    let mut weights = Vec::new();
    // Coarse stage: while the pose still moves centimetres per step, the neighbours cached
    // below would be stale after every step; a subsample with single plain searches gets
    // there for a fraction of the searches.
    let stride = config.coarse_stride;
    if stride > 1 && source.len() / stride >= config.min_correspondences {
        for _ in 0..config.max_iterations {
            iterations += 1;
            coarse_correspondences(
                source,
                stride,
                target,
                &pose,
                config.max_correspondence_distance,
                &mut pairs,
            );
            if pairs.len() < config.min_correspondences {
                // Too few for the subsample: leave it to the full set.
                break;
            }
            let (dt, dr) = update::<S>(config, &pairs, &mut weights, &mut pose)?;
            if dt < COARSE_TRANSLATION && dr < COARSE_ROTATION {
                break;
            }
        }
    }
    // The k nearest target points of each source point, and more (4 at least): later
    // iterations reuse them while they provably stay nearest (`matcher`).
    for _ in 0..config.max_iterations {
        iterations += 1;
        matcher.correspondences(source, target, &pose, &mut pairs);
        if pairs.len() < config.min_correspondences {
            return Err(RegistrationError::TooFewCorrespondences {
                found: pairs.len(),
                required: config.min_correspondences,
            });
        }
        let (dt, dr) = update::<S>(config, &pairs, &mut weights, &mut pose)?;
        if dt < config.translation_tolerance && dr < config.rotation_tolerance {
            converged = true;
            break;
        }
    }
    // Composed step after step from the caller's guess: keep the quaternion unit.
    pose.rotation.renormalize();
    // Report at the final pose.
    matcher.correspondences(source, target, &pose, &mut pairs);
    if pairs.len() < config.min_correspondences {
        return Err(RegistrationError::TooFewCorrespondences {
            found: pairs.len(),
            required: config.min_correspondences,
        });
    }
    *left = Some(matcher);
    weights.clear();
    weights.extend(pairs.iter().map(|p| config.kernel.weight(S::residual(p))));
    let (inliers, rmse) = inliers_and_rmse(&pairs, &weights, S::residual);
    let information = S::information(&pairs, &weights);
    Ok(alignment_report(
        pose,
        converged,
        iterations,
        inliers,
        source.len(),
        rmse,
        &information,
    ))
}

/// Every `k`-th point of `source`, the smallest `k` that leaves at most `max` (0: no limit);
/// `None` when it is within the limit already. A voxelised scan lists its voxels in the order
/// the sweep first met them, so a stride keeps them spread over the whole scan.
pub(crate) fn thin_source<T: Copy>(source: &[T], max: usize) -> Option<Vec<T>> {
    (max > 0 && source.len() > max).then(|| {
        let k = source.len().div_ceil(max);
        source.iter().step_by(k).copied().collect()
    })
}

/// The pairs with a weight above zero, and their RMS residual (infinite without any).
pub(crate) fn inliers_and_rmse(
    pairs: &[Pair],
    weights: &[f64],
    residual: impl Fn(&Pair) -> f64,
) -> (usize, f64) {
    let (inliers, sq) = pairs
        .iter()
        .zip(weights)
        .filter(|(_, w)| **w > 0.0)
        .fold((0, 0.0), |(n, sq), (p, _)| {
            (n + 1, sq + residual(p).powi(2))
        });
    let rmse = if inliers > 0 {
        (sq / inliers as f64).sqrt()
    } else {
        f64::INFINITY
    };
    (inliers, rmse)
}
