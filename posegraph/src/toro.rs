//! TORO 2D graph files: `VERTEX2 id x y theta` and
//! `EDGE2 from to dx dy dtheta I_xx I_xy I_yy I_tt I_xt I_yt` (TORO's information order).

use std::path::Path;

use nalgebra::{Matrix3, Vector2};
use slam_core::{Pose2, PoseGraph};

use crate::error::{GraphFileError, UnknownTags};
use crate::graph_text_lines::{line_err, tagged_lines};
use crate::se2_text::{Se2Format, se2_text};

/// Parse TORO text into an SE(2) graph (no node is fixed: fix one before optimising).
///
/// # Errors
/// [`GraphFileError::Line`], [`GraphFileError::Graph`] or [`GraphFileError::UnknownTags`].
pub fn parse_toro(text: &str) -> Result<PoseGraph<Pose2>, GraphFileError> {
    let mut g = PoseGraph::new();
    let mut unknown = UnknownTags::default();
    for (line, tag, rest) in tagged_lines(text) {
        // `ids` vertex ids (whole numbers, parsed as integers so that ids above 2^53 stay
        // exact), then `values` finite numbers.
        let fields = |ids: usize, values: usize| -> Result<(Vec<u64>, Vec<f64>), GraphFileError> {
            if rest.len() != ids + values {
                return Err(line_err(
                    line,
                    format!("{tag} has {} values, {} expected", rest.len(), ids + values),
                ));
            }
            let id_of = |w: &&str| {
                w.parse::<u64>()
                    .map_err(|_| line_err(line, format!("{w:?} is not a vertex id")))
            };
            let number = |w: &&str| {
                w.parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| line_err(line, format!("{w:?} is not a number")))
            };
            Ok((
                rest[..ids].iter().map(id_of).collect::<Result<_, _>>()?,
                rest[ids..].iter().map(number).collect::<Result<_, _>>()?,
            ))
        };
        let graph_err = |source| GraphFileError::Graph { line, source };
        match tag {
            "VERTEX2" | "VERTEX" => {
                let (id, v) = fields(1, 3)?;
                g.add_node(id[0], Pose2::new(Vector2::new(v[0], v[1]), v[2]))
                    .map_err(graph_err)?;
            }
            "EDGE2" | "EDGE" => {
                let (id, v) = fields(2, 9)?;
                let z = Pose2::new(Vector2::new(v[0], v[1]), v[2]);
                // TORO: I_xx I_xy I_yy I_tt I_xt I_yt.
                let (xx, xy, yy, tt, xt, yt) = (v[3], v[4], v[5], v[6], v[7], v[8]);
                let info = Matrix3::new(xx, xy, xt, xy, yy, yt, xt, yt, tt);
                g.add_edge(id[0], id[1], z, info, None).map_err(graph_err)?;
            }
            other => unknown.note(line, other),
        }
    }
    unknown.check()?;
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

/// TORO text of an SE(2) graph (`VERTEX2` and `EDGE2` lines at full precision: it reads back
/// exactly). TORO has no way to mark a node fixed, so fixed flags are not written.
#[must_use]
pub fn toro_text(graph: &PoseGraph<Pose2>) -> String {
    se2_text(
        graph,
        &Se2Format {
            vertex: "VERTEX2",
            edge: "EDGE2",
            // TORO: I_xx I_xy I_yy I_tt I_xt I_yt.
            information: [(0, 0), (0, 1), (1, 1), (2, 2), (0, 2), (1, 2)],
            fix_lines: false,
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_above_2_pow_53_stay_exact() {
        // 2^53 + 1 is not an f64: read through a float it became 2^53.
        let text = "VERTEX2 9007199254740993 1 2 0.5\nVERTEX2 9007199254740992 0 0 0\n\
                    EDGE2 9007199254740992 9007199254740993 1 2 0.5 1 0 1 1 0 0\n";
        let g = parse_toro(text).unwrap();
        let ids: Vec<u64> = g.nodes().iter().map(|n| n.id).collect();
        assert_eq!(ids, [9_007_199_254_740_993, 9_007_199_254_740_992]);
        assert_eq!((g.edges()[0].from, g.edges()[0].to), (1, 0));
    }

    #[test]
    fn ids_must_be_whole_numbers() {
        for bad in ["VERTEX2 1.5 0 0 0", "VERTEX2 -1 0 0 0", "VERTEX2 1e3 0 0 0"] {
            assert!(
                matches!(parse_toro(bad), Err(GraphFileError::Line { line: 1, .. })),
                "{bad}"
            );
        }
    }

    #[test]
    fn written_text_reads_back_the_same_graph() {
        let text = "VERTEX2 0 0 0 0\nVERTEX2 7 1.25 -2.5 0.75\n\
                    EDGE2 0 7 1.25 -2.5 0.75 10 0.5 20 30 0.25 0.125\n";
        let g = parse_toro(text).unwrap();
        let back = parse_toro(&toro_text(&g)).unwrap();
        assert_eq!(toro_text(&back), toro_text(&g));
        assert_eq!(back.edges()[0].information, g.edges()[0].information);
    }
}
