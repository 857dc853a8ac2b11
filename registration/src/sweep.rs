//! Point-to-plane registration of a sweep together with its own motion: the pose at the
//! sweep's start and a correction to the constant velocity it was deskewed with, solved
//! jointly (a continuous-time ICP in the spirit of CT-ICP, Dellenbach et al., ICRA 2022, with
//! one velocity a sweep instead of two poses).
//!
//! A point `d` deskewed with velocity `v` and measured `t` seconds into the sweep lies at
//! `T0 exp(t v_true) exp(-t v) d ~ T0 exp(t c) d` in the map, with `c = v_true - v` the
//! correction: 12 unknowns, the pose `T0` (left perturbation `e`) and `c` (whose perturbation
//! `h` moves the point's pose `P = T0 exp(t c)` on the right by `t h`, so on the left by
//! `Ad(P) t h`). Each pair's point-to-plane row is `[J, t J Ad(P)]` with `J = [n, w x n]` at the
//! moved point `w`; the correction is kept near zero by a weak prior, so that a direction the
//! sweep does not constrain (along a corridor) keeps the velocity it was deskewed with.

use nalgebra::{Point3, SMatrix, SVector, Vector6};
use rayon::prelude::*;
use slam_core::{
    Degeneracy, InvalidSetting, PointCloud, Pose3, RegistrationError, SweepAlignment, SweepPath,
    se3_adjoint, se3_exp,
};

use crate::alignment_inputs::checked_target_index;
use crate::alignment_report::alignment_report;
use crate::config::IcpConfig;
use crate::icp::{Pair, first_search_radius, inliers_and_rmse, thin_source};
use crate::matcher::Matcher;
use crate::pool_awake::with_pool_awake;
use crate::target::{PreparedTarget, TargetIndex};

/// The prior on the velocity correction, relative to the pairs' summed weight, for its linear
/// part (per m/s) ...
const LINEAR_PRIOR: f64 = 1e-2;
/// ... and its angular part (per rad/s).
const ANGULAR_PRIOR: f64 = 1e-5;

/// The points of `sweep` thinned to `config.source_voxel` with their mean times (seconds).
fn sweep_points(
    config: &IcpConfig,
    sweep: &PointCloud,
) -> Result<(Vec<Point3<f64>>, Vec<f64>), RegistrationError> {
    let thinned = if config.source_voxel > 0.0 {
        sweep.voxel_downsample(config.source_voxel).map_err(|_| {
            RegistrationError::from(InvalidSetting {
                setting: "IcpConfig::source_voxel",
                value: f64::from(config.source_voxel),
                expected: "finite and positive",
            })
        })?
    } else {
        sweep.clone()
    };
    let times = thinned.time().ok_or(RegistrationError::TooFewPoints {
        what: "sweep (no per-point times)",
        points: 0,
        required: config.min_correspondences,
    })?;
    let (points, times): (Vec<_>, Vec<_>) = thinned
        .points()
        .iter()
        .zip(times)
        .filter(|(p, t)| p.iter().all(|v| v.is_finite()) && t.is_finite())
        .map(|(p, &t)| (p.cast::<f64>(), f64::from(t)))
        .unzip();
    if points.len() < config.min_correspondences {
        return Err(RegistrationError::TooFewPoints {
            what: "source",
            points: points.len(),
            required: config.min_correspondences,
        });
    }
    Ok((points, times))
}

/// Point-to-plane registration of `sweep` (deskewed, with its `time` channel) against `target`
/// from `initial`, with the velocity correction; `config`'s reach, kernel, iterations and
/// tolerances.
pub(crate) fn align_sweep(
    config: &IcpConfig,
    sweep: &PointCloud,
    target: &PreparedTarget,
    initial: &Pose3,
) -> Result<SweepAlignment, RegistrationError> {
    let index = checked_target_index(config, target, initial)?;
    let (points, times) = sweep_points(config, sweep)?;
    let (points, times) = match (
        thin_source(&points, config.max_source_points),
        thin_source(&times, config.max_source_points),
    ) {
        (Some(p), Some(t)) => (p, t),
        _ => (points, times),
    };
    // The scan's own registration usually paired these same points against this target just
    // before: its neighbours start this one (the same answers as fresh searches), and this
    // one's start the next (a recheck from another position).
    let mut matcher = target.matcher_for(
        &points,
        1,
        config.max_correspondence_distance,
        first_search_radius(config),
    );
    // On a worker of the thread pool, as `icp::align`.
    let result = with_pool_awake(|| {
        align_sweep_indexed(config, &points, &times, &mut matcher, index, initial)
    });
    target.keep_matcher(&points, 1, matcher);
    result
}

/// [`align_sweep`] once the target is indexed and the sweep thinned.
fn align_sweep_indexed(
    config: &IcpConfig,
    points: &[Point3<f64>],
    times: &[f64],
    matcher: &mut Matcher,
    target: &TargetIndex,
    initial: &Pose3,
) -> Result<SweepAlignment, RegistrationError> {
    let mut pose = *initial;
    let mut correction = Vector6::zeros();
    let mut moved = vec![Point3::origin(); points.len()];
    let mut pairs = Vec::with_capacity(points.len());
    let (mut converged, mut iterations) = (false, 0);
    let mut weights = Vec::with_capacity(points.len());
    let (lo, hi) = times
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &t| {
            (lo.min(t), hi.max(t))
        });
    // Every point moved by its own pose, paired with the target; too few pairs is an error.
    // The poses over the sweep are blended between steps of at most 1 mrad (`SweepPath`): one
    // exponential a step instead of one a point and iteration.
    let matched = |pose: &Pose3,
                   correction: &Vector6<f64>,
                   moved: &mut [Point3<f64>],
                   matcher: &mut Matcher,
                   pairs: &mut Vec<Pair>| {
        let path = SweepPath::over(lo, hi, correction);
        moved
            .par_iter_mut()
            .zip(points.par_iter().zip(times.par_iter()))
            .with_min_len(256)
            .for_each(|(m, (p, &t))| *m = pose * path.moved(p, t));
        matcher.correspondences(moved, target, &Pose3::identity(), pairs);
        if pairs.len() < config.min_correspondences {
            return Err(RegistrationError::TooFewCorrespondences {
                found: pairs.len(),
                required: config.min_correspondences,
            });
        }
        Ok(())
    };
    for _ in 0..config.max_iterations {
        iterations += 1;
        matched(&pose, &correction, &mut moved, matcher, &mut pairs)?;
        let (h, b) = normal_equations(config, &pairs, times, &pose, &correction, &mut weights);
        let Some(step) = h.cholesky().map(|c| -c.solve(&b)) else {
            return Err(RegistrationError::Degenerate {
                cause: Degeneracy::SingularNormalEquations,
            });
        };
        if !step.iter().all(|v| v.is_finite()) {
            return Err(RegistrationError::Degenerate {
                cause: Degeneracy::NonFiniteUpdate,
            });
        }
        let e: Vector6<f64> = step.fixed_rows::<6>(0).into_owned();
        pose = se3_exp(&e) * pose;
        correction += step.fixed_rows::<6>(6);
        if e.fixed_rows::<3>(0).norm() < config.translation_tolerance
            && e.fixed_rows::<3>(3).norm() < config.rotation_tolerance
        {
            converged = true;
            break;
        }
    }
    pose.rotation.renormalize();
    matched(&pose, &correction, &mut moved, matcher, &mut pairs)?;
    let (h, _) = normal_equations(config, &pairs, times, &pose, &correction, &mut weights);
    let information = h.fixed_view::<6, 6>(0, 0).into_owned();
    let (inliers, rmse) = inliers_and_rmse(&pairs, &weights, residual);
    Ok(SweepAlignment {
        alignment: alignment_report(
            pose,
            converged,
            iterations,
            inliers,
            points.len(),
            rmse,
            &information,
        ),
        velocity_correction: correction,
    })
}

/// The point-to-plane residual of a pair (metres).
fn residual(pair: &Pair) -> f64 {
    pair.n.map_or(f64::INFINITY, |n| n.dot(&(pair.p - pair.q)))
}

/// `(J^T W J + prior, J^T W r + prior)` over the pose and the velocity correction; `weights`
/// gets each pair's robust weight.
fn normal_equations(
    config: &IcpConfig,
    pairs: &[Pair],
    times: &[f64],
    pose: &Pose3,
    correction: &Vector6<f64>,
    weights: &mut Vec<f64>,
) -> (SMatrix<f64, 12, 12>, SVector<f64, 12>) {
    weights.clear();
    // `Ad(P)` for each point's pose `P = T0 exp(t c)` is `Ad(T0)` to first order in the small
    // correction: one adjoint an iteration instead of one a point.
    let ad_t = se3_adjoint(pose).transpose();
    let mut h = SMatrix::<f64, 12, 12>::zeros();
    let mut b = SVector::<f64, 12>::zeros();
    let mut sum_w = 0.0;
    for pair in pairs {
        let r = residual(pair);
        let w = config.kernel.weight(r);
        weights.push(w);
        if w == 0.0 || !r.is_finite() {
            continue;
        }
        sum_w += w;
        let n = pair.n.unwrap_or_default();
        let c = pair.p.coords.cross(&n);
        let j = Vector6::new(n.x, n.y, n.z, c.x, c.y, c.z);
        let t = times[pair.slot];
        let jc = (ad_t * j) * t;
        let mut row = SVector::<f64, 12>::zeros();
        row.fixed_rows_mut::<6>(0).copy_from(&j);
        row.fixed_rows_mut::<6>(6).copy_from(&jc);
        // Lower triangle only, in place: a 12x12 product per pair dominated the sweep.
        h.syger(w, &row, &row, 1.0);
        b.axpy(r * w, &row, 1.0);
    }
    h.fill_upper_triangle_with_lower_triangle();
    // Keep the correction near zero where the pairs do not constrain it.
    for i in 6..12 {
        let prior = if i < 9 { LINEAR_PRIOR } else { ANGULAR_PRIOR } * sum_w.max(1.0);
        h[(i, i)] += prior;
        b[i] += prior * correction[i - 6];
    }
    (h, b)
}

#[cfg(test)]
mod tests {
    use nalgebra::{Point3, Vector3, Vector6};
    use slam_core::{PointCloud, Pose3, Registrator, pose3_from_xyz_rpy, se3_exp};

    use crate::{IcpConfig, IcpKernel, PointToPlaneIcp};

    /// Where a ray from `o` along `d` leaves the room `[-5, 6] x [-3, 4] x [-1, 2.5]`.
    fn hit(o: &Point3<f64>, d: &Vector3<f64>) -> Point3<f64> {
        let (lo, hi) = (Vector3::new(-5.0, -3.0, -1.0), Vector3::new(6.0, 4.0, 2.5));
        let t = (0..3)
            .map(|a| {
                if d[a] > 0.0 {
                    (hi[a] - o[a]) / d[a]
                } else {
                    (lo[a] - o[a]) / d[a]
                }
            })
            .fold(f64::INFINITY, f64::min);
        o + d * t
    }

    /// A 0.1 s sweep of the room from a sensor starting at `start` and moving at `twist` (per
    /// second, sensor frame): each column's rays cast from the pose at its time, points in the
    /// sensor frame at that time, with their times.
    fn sweep(start: &Pose3, twist: &Vector6<f64>) -> PointCloud {
        let (mut points, mut times) = (Vec::new(), Vec::new());
        for col in 0..720 {
            let t = f64::from(col) / 720.0 * 0.1;
            let pose = start * se3_exp(&(twist * t));
            let az = f64::from(col) / 720.0 * std::f64::consts::TAU;
            for ring in 0..32 {
                let el = (-25.0 + 50.0 * f64::from(ring) / 31.0f64).to_radians();
                let d = Vector3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
                let world = hit(&Point3::from(pose.translation.vector), &(pose.rotation * d));
                points.push((pose.inverse() * world).cast::<f32>());
                times.push(t as f32);
            }
        }
        PointCloud::from_points(points)
            .with_time(times)
            .unwrap_or_default()
    }

    /// Point-to-plane ICP as the sweep tests run it: Tukey 20 cm, 10 cm source voxels.
    fn sweep_icp() -> PointToPlaneIcp {
        PointToPlaneIcp {
            config: IcpConfig {
                kernel: IcpKernel::Tukey { k: 0.2 },
                source_voxel: 0.1,
                ..IcpConfig::default()
            },
        }
    }

    #[test]
    fn a_sweep_deskewed_with_a_wrong_velocity_gives_back_its_start_and_the_correction() {
        let icp = sweep_icp();
        // The map: the room seen from a still sensor, dense.
        let map = sweep(&Pose3::identity(), &Vector6::zeros());
        let target = icp.prepare_target(&map).unwrap_or_else(|e| panic!("{e}"));
        // A shaking hand: 1.2 m/s forward, 0.3 m/s up, turning at 60 degrees a second and
        // rolling at 20 during the sweep ...
        let start = pose3_from_xyz_rpy(0.3, -0.2, 0.1, 0.02, -0.01, 0.3);
        let twist = Vector6::new(1.2, 0.0, 0.3, 20f64.to_radians(), 0.0, 60f64.to_radians());
        // ... deskewed with a constant-velocity guess 0.2 m/s and 40 degrees a second off.
        let guessed = twist
            + Vector6::new(
                -0.2,
                0.05,
                0.0,
                0.0,
                15f64.to_radians(),
                -37f64.to_radians(),
            );
        let deskewed = slam_core::deskew(&sweep(&start, &twist), &guessed)
            .unwrap_or_else(|| panic!("the sweep has times"));
        let guess = start * pose3_from_xyz_rpy(0.05, 0.03, 0.0, 0.0, 0.0, 0.02);
        let plain = icp
            .align(
                &icp.prepare_source(&deskewed)
                    .unwrap_or_else(|e| panic!("{e}")),
                &target,
                &guess,
            )
            .unwrap_or_else(|e| panic!("{e}"));
        let swept = icp
            .align_sweep(&deskewed, &target, &guess)
            .unwrap_or_else(|| panic!("point-to-plane aligns sweeps"))
            .unwrap_or_else(|e| panic!("{e}"));
        let error = |p: &Pose3| {
            let d = start.inverse() * p;
            (d.translation.vector.norm(), d.rotation.angle().to_degrees())
        };
        let (t0, r0) = error(&plain.pose);
        let (t1, r1) = error(&swept.alignment.pose);
        let found = guessed + swept.velocity_correction;
        let w_err = (found.fixed_rows::<3>(3) - twist.fixed_rows::<3>(3))
            .norm()
            .to_degrees();
        eprintln!(
            "rigid: {t0:.4} m, {r0:.3} deg off; with the sweep's motion: {t1:.4} m, {r1:.3} deg off, turn rate {w_err:.2} deg/s off"
        );
        assert!(r0 > 1.0, "the skew must matter: {r0} degrees");
        // The turn rate is found; the linear velocity is held near the guess (a weak sensor
        // would otherwise trade it for a drift): its 0.2 m/s leave about a centimetre.
        assert!(r1 < 0.2 && w_err < 5.0, "{r1} degrees, {w_err} deg/s");
        assert!(t1 < 0.02, "{t1} m");
    }

    #[test]
    fn a_sweep_after_the_scans_registration_ends_where_it_ends_alone() {
        // The registration leaves its neighbours in the target for the sweep of the same
        // points: the sweep must end exactly where it ends on a target without them.
        let icp = sweep_icp();
        let map = sweep(&Pose3::identity(), &Vector6::zeros());
        let start = pose3_from_xyz_rpy(0.3, -0.2, 0.1, 0.02, -0.01, 0.3);
        let twist = Vector6::new(1.2, 0.0, 0.3, 0.3, 0.0, 1.0);
        let deskewed = slam_core::deskew(&sweep(&start, &twist), &(twist * 0.8))
            .unwrap_or_else(|| panic!("the sweep has times"));
        let guess = start * pose3_from_xyz_rpy(0.05, 0.03, 0.0, 0.0, 0.0, 0.02);
        let used = icp.prepare_target(&map).unwrap_or_else(|e| panic!("{e}"));
        let source = icp
            .prepare_source(&deskewed)
            .unwrap_or_else(|e| panic!("{e}"));
        let registered = icp
            .align(&source, &used, &guess)
            .unwrap_or_else(|e| panic!("{e}"));
        let after = icp
            .align_sweep(&deskewed, &used, &registered.pose)
            .unwrap_or_else(|| panic!("point-to-plane aligns sweeps"))
            .unwrap_or_else(|e| panic!("{e}"));
        let fresh = icp.prepare_target(&map).unwrap_or_else(|e| panic!("{e}"));
        let alone = icp
            .align_sweep(&deskewed, &fresh, &registered.pose)
            .unwrap_or_else(|| panic!("point-to-plane aligns sweeps"))
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(after.alignment.pose, alone.alignment.pose);
        assert_eq!(after.velocity_correction, alone.velocity_correction);
        assert_eq!(after.alignment.inliers, alone.alignment.inliers);
    }
}
