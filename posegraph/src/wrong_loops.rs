//! Wrong loop closures for testing outlier-robust optimisers, in the protocol of Sünderhauf and
//! Protzel ("Switchable Constraints for Robust Pose Graph SLAM", IROS 2012; their Vertigo
//! package's random outliers): pairs of distant nodes drawn at random, each claimed to be the
//! same place (an identity measurement) with a real loop's information.

use slam_core::{OptimizeError, PoseGraph};

use crate::solver::SolverPose;

/// Add `count` wrong loop closures to `graph` and return their edge indices (appended after
/// the existing edges, so they are the last ones). Each joins two nodes whose ids differ by more
/// than one, that are not joined yet and whose positions in `reference` (the poses the distance
/// is judged by, one per node in [`PoseGraph::nodes`] order: the clean graph's optimum, say)
/// are at least `min_distance` metres apart; the measurement is the identity and the
/// information `information`. `next_u64` is the random source (a seeded PCG generator gives the
/// same graph on every platform).
///
/// Fewer edges are added when the pairs run out (after 1,000 draws per edge).
///
/// # Errors
/// [`OptimizeError::InformationNotPositiveDefinite`] for a bad `information`.
pub fn add_wrong_loops<P: SolverPose>(
    graph: &mut PoseGraph<P>,
    reference: &[P],
    count: usize,
    min_distance: f64,
    information: P::Information,
    next_u64: &mut impl FnMut() -> u64,
) -> Result<Vec<usize>, OptimizeError> {
    let n = graph.node_count().min(reference.len());
    let mut joined: std::collections::HashSet<(usize, usize)> = graph
        .edges()
        .iter()
        .map(|e| (e.from.min(e.to), e.from.max(e.to)))
        .collect();
    let mut added = Vec::with_capacity(count);
    if n < 3 {
        return Ok(added);
    }
    // Uniform in 0..n by the multiply-shift method (no modulo bias worth the name, portable).
    let mut index = || ((u128::from(next_u64()) * n as u128) >> 64) as usize;
    let mut draws = 0;
    while added.len() < count && draws < 1000 * count {
        draws += 1;
        let (a, b) = (index(), index());
        let (lo, hi) = (a.min(b), a.max(b));
        let (ida, idb) = (graph.nodes()[lo].id, graph.nodes()[hi].id);
        if ida.abs_diff(idb) <= 1
            || joined.contains(&(lo, hi))
            || (reference[lo].position() - reference[hi].position()).norm() < min_distance
        {
            continue;
        }
        joined.insert((lo, hi));
        added.push(graph.add_edge(ida, idb, P::identity_pose(), information, None)?);
    }
    Ok(added)
}

/// How an outlier-robust run did on a graph from [`add_wrong_loops`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RobustScore {
    /// Mean distance (metres) of the nodes' positions from `reference`'s.
    pub mean_position_error: f64,
    /// Largest such distance (metres).
    pub max_position_error: f64,
    /// Wrong loops whose weight is 0.5 or more.
    pub wrong_kept: usize,
    /// True loops (edges before the wrong ones whose node ids differ by more than one) whose
    /// weight is below 0.5.
    pub true_lost: usize,
    /// True loops in all.
    pub true_loops: usize,
}

/// Score `graph` after a robust optimisation against `reference` (the clean optimum, one pose
/// per node): edges from `first_wrong` on are the wrong loops, `weights` the optimiser's final
/// weight of every edge (missing weights count as 1).
#[must_use]
pub fn score<P: SolverPose>(
    graph: &PoseGraph<P>,
    reference: &[P],
    weights: &[f64],
    first_wrong: usize,
) -> RobustScore {
    let (mut sum, mut max) = (0.0, 0.0f64);
    for (node, r) in graph.nodes().iter().zip(reference) {
        let d = (node.pose.position() - r.position()).norm();
        sum += d;
        max = max.max(d);
    }
    let kept = |k: usize| weights.get(k).is_none_or(|&w| w >= 0.5);
    let mut score = RobustScore {
        mean_position_error: sum / graph.node_count().max(1) as f64,
        max_position_error: max,
        wrong_kept: 0,
        true_lost: 0,
        true_loops: 0,
    };
    for (k, e) in graph.edges().iter().enumerate() {
        if k >= first_wrong {
            score.wrong_kept += usize::from(kept(k));
        } else if graph.nodes()[e.from].id.abs_diff(graph.nodes()[e.to].id) > 1 {
            score.true_loops += 1;
            score.true_lost += usize::from(!kept(k));
        }
    }
    score
}
