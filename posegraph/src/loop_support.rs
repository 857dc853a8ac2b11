//! Local pairwise consistency of loop closures (the test of Mangelson et al.'s pairwise
//! consistency maximisation, "Pairwise Consistent Measurement Set Maximization for Robust
//! Multi-robot Map Merging", ICRA 2018, restricted to short odometry chains): two candidate
//! loops `a -> b` and `c -> d` with `c` within a few odometry steps of `a` and `d` of `b` close a
//! cycle of measurements alone, `Z_cd^-1 O_ac^-1 Z_ab O_bd` (`O` the composed odometry), whose
//! log-map error is tested against the chi-square threshold with the covariances of the cycle's
//! edges added up (short chains: the transport of each covariance along the chain is left out).
//! The test needs no pose estimate, so it holds however far the guess has drifted. A true loop
//! usually has such a partner (places are revisited along a stretch, not at one pose); a wrong
//! loop between random places almost never has.

use std::collections::HashMap;

use nalgebra::SMatrix;
use slam_core::PoseGraph;

use crate::linearize::{ErrorModel, Linearize};
use crate::solver::SolverPose;

/// The odometry between node ids `from` and `to` (`|from - to| <= window`) by composing the
/// consecutive-id edges, with its summed covariance; `None` when a step is missing or an
/// information matrix is singular.
fn chain<P: Linearize<D> + SolverPose, const D: usize>(
    graph: &PoseGraph<P>,
    odometry: &HashMap<u64, usize>,
    from: u64,
    to: u64,
) -> Option<(P, SMatrix<f64, D, D>)> {
    let mut pose = P::identity_pose();
    let mut cov = SMatrix::<f64, D, D>::zeros();
    let mut id = from;
    while id != to {
        let next = if to > id { id + 1 } else { id - 1 };
        let e = &graph.edges()[*odometry.get(&id.min(next))?];
        let forward = graph.nodes()[e.from].id == id;
        let step = if forward {
            e.measurement
        } else {
            e.measurement.inverse_pose()
        };
        pose = pose.compose(&step);
        cov += P::info(&e.information).try_inverse()?;
        id = next;
    }
    Some((pose, cov))
}

/// For each edge, whether it is a candidate (`candidate[k]`) with a consistent partner: another
/// candidate whose two ends are within `window` odometry steps of its own (in either direction)
/// and whose cycle error is below `c2`.
pub(crate) fn supported<P: Linearize<D> + SolverPose, const D: usize>(
    graph: &PoseGraph<P>,
    candidate: &[bool],
    window: u64,
    c2: f64,
) -> Vec<bool> {
    let m = graph.edge_count();
    let mut out = vec![false; m];
    if window == 0 {
        return out;
    }
    let id = |i: usize| graph.nodes()[i].id;
    // Odometry edges by their lower id; candidate loops by each end's id.
    let mut odometry: HashMap<u64, usize> = HashMap::new();
    let mut at: HashMap<u64, Vec<usize>> = HashMap::new();
    for (k, e) in graph.edges().iter().enumerate() {
        let (a, b) = (id(e.from), id(e.to));
        if candidate[k] {
            at.entry(a).or_default().push(k);
            at.entry(b).or_default().push(k);
        } else if a.abs_diff(b) == 1 {
            odometry.entry(a.min(b)).or_insert(k);
        }
    }
    let cov_of = |k: usize| P::info(&graph.edges()[k].information).try_inverse();
    for k in (0..m).filter(|&k| candidate[k]) {
        if out[k] {
            continue;
        }
        let e = &graph.edges()[k];
        let (a, b) = (id(e.from), id(e.to));
        let Some(cov_k) = cov_of(k) else { continue };
        'partners: for u in a.saturating_sub(window)..=a.saturating_add(window) {
            for &l in at.get(&u).map_or(&[][..], Vec::as_slice) {
                if l == k {
                    continue;
                }
                let f = &graph.edges()[l];
                let (c0, d0) = (id(f.from), id(f.to));
                // Orient the partner as c (near a) -> d (near b).
                let (c, d, z_cd) = if c0 == u && d0.abs_diff(b) <= window {
                    (c0, d0, f.measurement)
                } else if d0 == u && c0.abs_diff(b) <= window {
                    (d0, c0, f.measurement.inverse_pose())
                } else {
                    continue;
                };
                let (Some((o_ac, cov_ac)), Some((o_bd, cov_bd)), Some(cov_l)) = (
                    chain(graph, &odometry, a, c),
                    chain(graph, &odometry, b, d),
                    cov_of(l),
                ) else {
                    continue;
                };
                let err = P::error(
                    ErrorModel::LogMap,
                    &z_cd,
                    &o_ac,
                    &e.measurement.compose(&o_bd),
                );
                let Some(info) = (cov_k + cov_l + cov_ac + cov_bd).try_inverse() else {
                    continue;
                };
                if (err.transpose() * info * err)[0] <= c2 {
                    out[k] = true;
                    out[l] = true;
                    break 'partners;
                }
            }
        }
    }
    out
}
