//! Errors of the pose-graph files and of the optimisers' settings.

use std::path::PathBuf;

use thiserror::Error;

/// Errors of the g2o and TORO readers and writers.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum GraphFileError {
    /// The file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A line could not be parsed.
    #[error("line {line}: {message}")]
    Line {
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// Tags this reader does not know (reported rather than silently dropped).
    #[error("unknown tags: {}", .tags.iter().map(ToString::to_string).collect::<Vec<_>>().join(", "))]
    UnknownTags {
        /// Each distinct unknown tag at its first use.
        tags: Vec<UnknownTag>,
    },
    /// SE(2) and SE(3) elements in one file.
    #[error("line {line}: the file mixes 2D and 3D elements")]
    MixedDimensions {
        /// 1-based line number.
        line: usize,
    },
    /// An edge's information matrix is not positive definite (and was not repaired).
    #[error(
        "line {line}: the information matrix of edge {edge} is not positive definite; read with \
         InformationRepair::NearestPositiveDefinite (the g2o example's --repair-information) to \
         replace it by the nearest positive-definite matrix"
    )]
    InformationNotPositiveDefinite {
        /// 1-based line number.
        line: usize,
        /// Index the edge would have had.
        edge: usize,
    },
    /// The graph rejected an element (duplicate node, unknown node, bad information).
    #[error("line {line}: {source}")]
    Graph {
        /// 1-based line number.
        line: usize,
        /// The cause.
        source: slam_core::OptimizeError,
    },
}

/// A tag of a graph file that the reader does not implement, at its first use.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnknownTag {
    /// 1-based line number.
    pub line: usize,
    /// The tag (`VERTEX_XY`, `EDGE_SE3_PRIOR`, ...).
    pub tag: String,
}

/// The tags a graph file uses that its reader does not implement, each once at its first line.
#[derive(Default)]
pub(crate) struct UnknownTags(Vec<UnknownTag>);

impl UnknownTags {
    /// Notes `tag` at `line` unless it was noted before.
    pub(crate) fn note(&mut self, line: usize, tag: &str) {
        if !self.0.iter().any(|u| u.tag == tag) {
            self.0.push(UnknownTag {
                line,
                tag: tag.to_string(),
            });
        }
    }

    /// [`GraphFileError::UnknownTags`] when any tag was noted.
    pub(crate) fn check(self) -> Result<(), GraphFileError> {
        if self.0.is_empty() {
            Ok(())
        } else {
            Err(GraphFileError::UnknownTags { tags: self.0 })
        }
    }
}

impl std::fmt::Display for UnknownTag {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} (line {})", self.tag, self.line)
    }
}
