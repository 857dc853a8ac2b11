//! Errors reading and writing pose-graph files.

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
    #[error("unknown tags: {}", .tags.iter().map(|(l, t)| format!("{t} (line {l})")).collect::<Vec<_>>().join(", "))]
    UnknownTags {
        /// (line, tag) of each distinct unknown tag's first use.
        tags: Vec<(usize, String)>,
    },
    /// SE(2) and SE(3) elements in one file.
    #[error("line {line}: the file mixes 2D and 3D elements")]
    MixedDimensions {
        /// 1-based line number.
        line: usize,
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
