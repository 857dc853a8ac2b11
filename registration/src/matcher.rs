//! `Matcher`: the correspondences of a whole source, searched in fixed chunks on the machine's
//! cores, each chunk with its own [`NeighbourCache`].

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;
use slam_core::Pose3;

use crate::icp::Pair;
use crate::neighbour_cache::{Candidate, NeighbourCache, Neighbours};
use crate::target::TargetIndex;

/// Source points a chunk: an eighth of the source, from 32 to 256 points. Derived from the
/// source's size only, not from the number of cores, so that the pairs (and every result
/// computed from them) are the same on every machine: each chunk's pairs are the serial loop's
/// for its points, and the chunks are joined in order. A wide stage's 600 points in eight
/// chunks keep both cores busy to the end, where three of 256 left one idle for a third of
/// each search.
fn chunk_len(len: usize) -> usize {
    len.div_ceil(8).clamp(32, 256)
}

/// One chunk's neighbour cache and pairs.
struct Chunk {
    cache: NeighbourCache,
    pairs: Vec<Pair>,
    nearest: Vec<Candidate>,
}

/// Pairs each source point with its target neighbours, reusing them across the iterations of
/// one alignment (see [`NeighbourCache`]).
pub(crate) struct Matcher {
    chunks: Vec<Chunk>,
    /// Points a chunk ([`chunk_len`]).
    chunk: usize,
}

impl Matcher {
    /// A matcher for `len` source points answering `k` nearest within `max_distance`, keeping
    /// `kept` per search and searching `first_radius` away first.
    pub(crate) fn new(
        len: usize,
        k: usize,
        kept: usize,
        max_distance: f64,
        first_radius: f64,
    ) -> Self {
        let chunk = chunk_len(len);
        let chunks = (0..len)
            .step_by(chunk)
            .map(|start| Chunk {
                cache: NeighbourCache::new(chunk.min(len - start), k, kept, max_distance)
                    .with_first_radius(first_radius),
                pairs: Vec::new(),
                nearest: Vec::with_capacity(kept),
            })
            .collect();
        Self { chunks, chunk }
    }

    /// The same cache answering within `max_distance`, searching `first_radius` away first.
    pub(crate) fn with_reach(mut self, max_distance: f64, first_radius: f64) -> Self {
        for chunk in &mut self.chunks {
            chunk.cache.set_reach(max_distance, first_radius);
        }
        self
    }

    /// Each source point moved by `pose` and its target point within reach, into `pairs` in
    /// source order: the nearest target point when `k` is 1, the mean of the `k` nearest when
    /// more; points without a neighbour within reach, or whose nearest target point has no
    /// normal where normals are asked for, are left out.
    pub(crate) fn correspondences(
        &mut self,
        source: &[Point3<f64>],
        target: &TargetIndex,
        pose: &Pose3,
        pairs: &mut Vec<Pair>,
    ) {
        let chunk_len = self.chunk;
        self.chunks
            .par_iter_mut()
            .zip(source.par_chunks(chunk_len))
            .enumerate()
            .for_each(|(c, (chunk, points))| {
                chunk.pairs.clear();
                for (i, s) in points.iter().enumerate() {
                    let p = pose * s;
                    let found = chunk.cache.nearest(i, target, &p, &mut chunk.nearest);
                    if found == Neighbours::TooFew {
                        continue;
                    }
                    let nearest = &chunk.nearest;
                    let Some(first) = nearest.first().map(|c| c.id as usize) else {
                        continue;
                    };
                    let Some(n) = target.pairing_normal(first) else {
                        continue;
                    };
                    let q = if nearest.len() == 1 {
                        target.points[first]
                    } else {
                        let sum = nearest.iter().fold(Vector3::zeros(), |m, c| {
                            m + target.points[c.id as usize].coords
                        });
                        Point3::from(sum / nearest.len() as f64)
                    };
                    chunk.pairs.push(Pair {
                        slot: c * chunk_len + i,
                        p,
                        q,
                        n,
                    });
                }
            });
        pairs.clear();
        for chunk in &self.chunks {
            pairs.extend_from_slice(&chunk.pairs);
        }
    }
}
