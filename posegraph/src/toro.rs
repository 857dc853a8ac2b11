//! TORO 2D graph files: `VERTEX2 id x y theta` and
//! `EDGE2 from to dx dy dtheta I_xx I_xy I_yy I_tt I_xt I_yt` (TORO's information order).

use std::path::Path;

use nalgebra::{Matrix3, Vector2};
use slam_core::{Pose2, PoseGraph};

use crate::error::{GraphFileError, UnknownTag};

fn line_err(line: usize, message: impl Into<String>) -> GraphFileError {
    GraphFileError::Line {
        line,
        message: message.into(),
    }
}

/// Parse TORO text into an SE(2) graph (no node is fixed: fix one before optimising).
///
/// # Errors
/// [`GraphFileError::Line`], [`GraphFileError::Graph`] or [`GraphFileError::UnknownTags`].
pub fn parse_toro(text: &str) -> Result<PoseGraph<Pose2>, GraphFileError> {
    let mut g = PoseGraph::new();
    let mut unknown: Vec<UnknownTag> = Vec::new();
    for (k, raw) in text.lines().enumerate() {
        let line = k + 1;
        let words: Vec<&str> = raw.split_whitespace().collect();
        let Some((&tag, rest)) = words.split_first() else {
            continue;
        };
        if tag.starts_with('#') {
            continue;
        }
        let nums = |want: usize| -> Result<Vec<f64>, GraphFileError> {
            if rest.len() != want {
                return Err(line_err(
                    line,
                    format!("{tag} has {} values, {want} expected", rest.len()),
                ));
            }
            rest.iter()
                .map(|w| {
                    w.parse::<f64>()
                        .ok()
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| line_err(line, format!("{w:?} is not a number")))
                })
                .collect()
        };
        let as_id = |v: f64| -> Result<u64, GraphFileError> {
            (v >= 0.0 && v.fract() == 0.0)
                .then_some(v as u64)
                .ok_or_else(|| line_err(line, format!("{v} is not a vertex id")))
        };
        let graph_err = |source| GraphFileError::Graph { line, source };
        match tag {
            "VERTEX2" | "VERTEX" => {
                let v = nums(4)?;
                g.add_node(as_id(v[0])?, Pose2::new(Vector2::new(v[1], v[2]), v[3]))
                    .map_err(graph_err)?;
            }
            "EDGE2" | "EDGE" => {
                let v = nums(11)?;
                let z = Pose2::new(Vector2::new(v[2], v[3]), v[4]);
                // TORO: I_xx I_xy I_yy I_tt I_xt I_yt.
                let (xx, xy, yy, tt, xt, yt) = (v[5], v[6], v[7], v[8], v[9], v[10]);
                let info = Matrix3::new(xx, xy, xt, xy, yy, yt, xt, yt, tt);
                g.add_edge(as_id(v[0])?, as_id(v[1])?, z, info, None)
                    .map_err(graph_err)?;
            }
            other => {
                if !unknown.iter().any(|u| u.tag == other) {
                    unknown.push(UnknownTag {
                        line,
                        tag: other.to_string(),
                    });
                }
            }
        }
    }
    if !unknown.is_empty() {
        return Err(GraphFileError::UnknownTags { tags: unknown });
    }
    Ok(g)
}

/// Read a TORO file.
///
/// # Errors
/// [`GraphFileError::Io`], or as [`parse_toro`].
pub fn read_toro(path: impl AsRef<Path>) -> Result<PoseGraph<Pose2>, GraphFileError> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|source| GraphFileError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_toro(&text)
}
