//! `ScanContextIndex`: the keyframes' Scan Contexts, their ring keys in a k-d tree, and the
//! retrieval of places that look like a query scan, with the heading between them.

use kiddo::{MutableKdTree, SquaredEuclidean};
use slam_core::{InvalidSetting, PlaceMatch, PlaceRecognitionError, PlaceRecognizer, PointCloud};

use crate::scan_context::{SCAN_CONTEXT_RINGS, ScanContext, ScanContextConfig, ScanContextMatch};

/// Settings of [`ScanContextIndex`].
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct ScanContextIndexConfig {
    /// The most recent descriptors are not searched (they are the robot's own recent past, not
    /// a revisit), 50 keyframes.
    pub exclude_recent: usize,
    /// Nearest ring keys compared in full, 10 (the paper's choice).
    pub ring_key_candidates: usize,
    /// Matches farther than this (mean column cosine distance) are not places seen before, 0.08.
    pub max_distance: f64,
}

impl Default for ScanContextIndexConfig {
    fn default() -> Self {
        Self {
            exclude_recent: 50,
            ring_key_candidates: 10,
            max_distance: 0.08,
        }
    }
}

impl ScanContextIndexConfig {
    /// At least one ring-key candidate, a distance in (0, 1].
    ///
    /// # Errors
    /// [`PlaceRecognitionError::InvalidConfig`] naming the first bad setting.
    pub fn validate(&self) -> Result<(), PlaceRecognitionError> {
        if self.ring_key_candidates == 0 {
            return Err(InvalidSetting {
                setting: "ScanContextIndexConfig::ring_key_candidates",
                value: 0.0,
                expected: "at least 1",
            }
            .into());
        }
        if !(self.max_distance > 0.0 && self.max_distance <= 1.0) {
            return Err(InvalidSetting {
                setting: "ScanContextIndexConfig::max_distance",
                value: self.max_distance,
                expected: "in (0, 1]",
            }
            .into());
        }
        Ok(())
    }
}

/// A keyframe that looks like the query scan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaceCandidate {
    /// The id the keyframe was inserted with.
    pub id: u64,
    /// Descriptor distance and the query's heading in the keyframe's frame.
    pub matched: ScanContextMatch,
}

/// Keyframe descriptors for place recognition. Descriptors are searchable once
/// `exclude_recent` newer ones have been inserted.
///
/// ```
/// use nalgebra::Point3;
/// use registration::{ScanContext, ScanContextConfig, ScanContextIndex, ScanContextIndexConfig};
/// use slam_core::PointCloud;
///
/// let walls = |dx: f32| {
///     let mut pts = Vec::new();
///     for k in 0..200 {
///         let t = k as f32 / 20.0;
///         pts.extend([Point3::new(t - 5.0 + dx, 3.0, 0.5), Point3::new(-4.0 + dx, t - 5.0, 0.5)]);
///         pts.push(Point3::new(6.0 + dx, t - 5.0 - dx, 1.0));
///     }
///     PointCloud::from_points(pts)
/// };
/// let config = ScanContextConfig::default();
/// let mut index = ScanContextIndex::new(ScanContextIndexConfig { exclude_recent: 0, ..Default::default() })?;
/// for (id, dx) in [(7, 0.0), (8, 2.5)] {
///     index.insert(id, ScanContext::from_cloud(&walls(dx), &config)?)?;
/// }
/// let found = index.query(&ScanContext::from_cloud(&walls(0.05), &config)?);
/// assert_eq!(found[0].id, 7);
/// # Ok::<(), slam_core::PlaceRecognitionError>(())
/// ```
pub struct ScanContextIndex {
    config: ScanContextIndexConfig,
    /// Every descriptor inserted, oldest first, with its id.
    contexts: Vec<(u64, ScanContext)>,
    /// Ring keys of `contexts[..searchable]`, items indexing `contexts`.
    tree: MutableKdTree<f32, SCAN_CONTEXT_RINGS>,
    searchable: usize,
}

impl std::fmt::Debug for ScanContextIndex {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ScanContextIndex")
            .field("config", &self.config)
            .field("contexts", &self.contexts.len())
            .field("searchable", &self.searchable)
            .finish_non_exhaustive()
    }
}

impl ScanContextIndex {
    /// An empty index.
    ///
    /// # Errors
    /// [`PlaceRecognitionError::InvalidConfig`] for invalid settings.
    pub fn new(config: ScanContextIndexConfig) -> Result<Self, PlaceRecognitionError> {
        config.validate()?;
        Ok(Self {
            config,
            contexts: Vec::new(),
            tree: MutableKdTree::default(),
            searchable: 0,
        })
    }

    /// Descriptors inserted.
    #[must_use]
    pub fn len(&self) -> usize {
        self.contexts.len()
    }

    /// Whether none was inserted.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.contexts.is_empty()
    }

    /// Adds the descriptor of keyframe `id`; descriptors older than the `exclude_recent` newest
    /// become searchable.
    ///
    /// # Errors
    /// [`PlaceRecognitionError::IndexFull`] beyond 2^32 descriptors (the tree's item index).
    pub fn insert(&mut self, id: u64, context: ScanContext) -> Result<(), PlaceRecognitionError> {
        self.contexts.push((id, context));
        while self.searchable + self.config.exclude_recent < self.contexts.len() {
            let k = self.searchable;
            let full = PlaceRecognitionError::IndexFull {
                what: "the scan context index",
                keyframe: k + 1,
                max: u32::MAX as usize,
            };
            let item = u32::try_from(k).map_err(|_| full.clone())?;
            self.tree
                .add(self.contexts[k].1.ring_key(), item)
                .map_err(|_| full)?;
            self.searchable += 1;
        }
        Ok(())
    }

    /// Searchable keyframes that look like `query`, best first: the nearest ring keys compared
    /// in full, those within `max_distance` kept.
    #[must_use]
    pub fn query(&self, query: &ScanContext) -> Vec<PlaceCandidate> {
        if self.searchable == 0 {
            return Vec::new();
        }
        let Some(n) = std::num::NonZero::new(self.config.ring_key_candidates) else {
            return Vec::new();
        };
        let nearest = self
            .tree
            .query(query.ring_key())
            .nearest_n::<SquaredEuclidean<f32>>(n)
            .execute();
        let mut found: Vec<PlaceCandidate> = nearest
            .iter()
            .filter_map(|r| {
                let (id, context) = &self.contexts[r.item as usize];
                let matched = query.compare(context)?;
                (matched.distance <= self.config.max_distance)
                    .then_some(PlaceCandidate { id: *id, matched })
            })
            .collect();
        found.sort_by(|a, b| a.matched.distance.total_cmp(&b.matched.distance));
        found
    }
}

/// Scan Context place recognition for the Graph-SLAM engine: descriptors of keyframe scans in a
/// [`ScanContextIndex`]. A query also describes its scan as seen from `query_offset` ahead,
/// behind and to either side and keeps each keyframe's best match: Scan Context changes with the
/// sensor's position within a bin, and a revisit seldom stands where the keyframe stood.
#[derive(Debug)]
pub struct ScanContextRecognizer {
    descriptor: ScanContextConfig,
    index: ScanContextIndex,
    query_offset: f64,
}

impl ScanContextRecognizer {
    /// A recognizer with these descriptor and index settings, querying from the scan's own
    /// origin and from `query_offset` metres (0.5 m by [`ScanContextRecognizer::default_offset`])
    /// around it (0: the origin only).
    ///
    /// # Errors
    /// [`PlaceRecognitionError::InvalidConfig`] for invalid settings or an offset that is not finite
    /// and non-negative.
    pub fn new(
        descriptor: ScanContextConfig,
        index: ScanContextIndexConfig,
        query_offset: f64,
    ) -> Result<Self, PlaceRecognitionError> {
        descriptor.validate()?;
        if !(query_offset.is_finite() && query_offset >= 0.0) {
            return Err(InvalidSetting {
                setting: "ScanContextRecognizer::new query_offset",
                value: query_offset,
                expected: "finite and not negative",
            }
            .into());
        }
        Ok(Self {
            descriptor,
            index: ScanContextIndex::new(index)?,
            query_offset,
        })
    }

    /// The query offset the engine's pipelines use, 0.5 m: half a keyframe spacing.
    #[must_use]
    pub fn default_offset() -> f64 {
        0.5
    }

    /// The index of keyframe descriptors.
    #[must_use]
    pub fn index(&self) -> &ScanContextIndex {
        &self.index
    }
}

impl PlaceRecognizer for ScanContextRecognizer {
    fn add_keyframe(
        &mut self,
        keyframe: usize,
        scan: &PointCloud,
    ) -> Result<(), PlaceRecognitionError> {
        let context = ScanContext::from_cloud(scan, &self.descriptor)?;
        self.index.insert(keyframe as u64, context)
    }

    fn candidates(&self, scan: &PointCloud) -> Result<Vec<PlaceMatch>, PlaceRecognitionError> {
        let here = ScanContext::from_cloud(scan, &self.descriptor)?;
        self.candidates_from(scan, &here)
    }

    fn candidates_then_add(
        &mut self,
        keyframe: usize,
        scan: &PointCloud,
    ) -> Result<Vec<PlaceMatch>, PlaceRecognitionError> {
        let here = ScanContext::from_cloud(scan, &self.descriptor)?;
        let found = self.candidates_from(scan, &here)?;
        self.index.insert(keyframe as u64, here)?;
        Ok(found)
    }
}

impl ScanContextRecognizer {
    /// Matches of `scan` (described at its origin as `here`) and of its views from the offsets.
    fn candidates_from(
        &self,
        scan: &PointCloud,
        here: &ScanContext,
    ) -> Result<Vec<PlaceMatch>, PlaceRecognitionError> {
        let d = self.query_offset;
        let offsets: &[(f64, f64)] = if d > 0.0 {
            &[(d, 0.0), (-d, 0.0), (0.0, d), (0.0, -d)]
        } else {
            &[]
        };
        let mut best: Vec<PlaceMatch> = Vec::new();
        let mut keep = |found: Vec<PlaceCandidate>| {
            for c in found {
                let Ok(keyframe) = usize::try_from(c.id) else {
                    continue;
                };
                match best.iter_mut().find(|m| m.keyframe == keyframe) {
                    Some(m) if m.distance <= c.matched.distance => {}
                    Some(m) => {
                        m.distance = c.matched.distance;
                        m.yaw = c.matched.yaw;
                    }
                    None => best.push(PlaceMatch {
                        keyframe,
                        yaw: c.matched.yaw,
                        distance: c.matched.distance,
                    }),
                }
            }
        };
        keep(self.index.query(here));
        for &(dx, dy) in offsets {
            let there = ScanContext::seen_from(scan, &self.descriptor, dx as f32, dy as f32)?;
            keep(self.index.query(&there));
        }
        best.sort_by(|a, b| a.distance.total_cmp(&b.distance));
        Ok(best)
    }
}
