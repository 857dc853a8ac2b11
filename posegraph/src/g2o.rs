//! g2o files: `VERTEX_SE3:QUAT`, `EDGE_SE3:QUAT` (21 upper-triangular information values),
//! `VERTEX_SE2`, `EDGE_SE2`, `FIX`. Information matrices are kept as written: g2o orders SE(3)
//! information as `[translation; rotation]`, the order of our `[rho; phi]` tangent, as GTSAM's
//! reader does after its own reordering.

use std::fmt::Write as _;
use std::path::Path;

use nalgebra::{Matrix3, Matrix6, Translation3, Vector2};
use slam_core::{GraphPose, Pose2, Pose3, PoseGraph, quaternion_from_xyzw, quaternion_to_xyzw};

use crate::error::{GraphFileError, UnknownTags};
use crate::graph_text_lines::{line_err, tagged_lines};
use crate::information_repair::{InformationRepair, RepairedEdge};
use crate::se2_text::{Se2Format, se2_text};

/// A graph read from a g2o file: 2D or 3D.
#[derive(Clone, Debug)]
pub enum G2oGraph {
    /// `VERTEX_SE2` / `EDGE_SE2`.
    Se2(PoseGraph<Pose2>),
    /// `VERTEX_SE3:QUAT` / `EDGE_SE3:QUAT`.
    Se3(PoseGraph<Pose3>),
}

fn numbers(
    words: &[&str],
    line: usize,
    want: usize,
    tag: &str,
) -> Result<Vec<f64>, GraphFileError> {
    if words.len() != want {
        return Err(line_err(
            line,
            format!("{tag} has {} values, {want} expected", words.len()),
        ));
    }
    words
        .iter()
        .map(|w| {
            w.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| line_err(line, format!("{tag}: {w:?} is not a finite number")))
        })
        .collect()
}

fn id(word: &str, line: usize) -> Result<u64, GraphFileError> {
    word.parse::<u64>()
        .map_err(|_| line_err(line, format!("{word:?} is not a vertex id")))
}

/// Parse g2o text; information matrices that are not positive definite are refused.
///
/// # Errors
/// [`GraphFileError::Line`] for malformed lines, [`GraphFileError::Graph`] for duplicate or
/// unknown vertices, [`GraphFileError::InformationNotPositiveDefinite`],
/// [`GraphFileError::MixedDimensions`], and [`GraphFileError::UnknownTags`] when the file uses
/// tags this reader does not implement.
pub fn parse_g2o(text: &str) -> Result<G2oGraph, GraphFileError> {
    parse_g2o_with(text, InformationRepair::Refuse).map(|(graph, _)| graph)
}

/// Parse g2o text, with `repair` deciding what happens to information matrices that are not
/// positive definite; returns the graph and the edges repaired.
///
/// # Errors
/// As [`parse_g2o`].
// One pass over the lines with one arm per tag; the arms are short and read best side by side.
#[allow(clippy::too_many_lines)]
pub fn parse_g2o_with(
    text: &str,
    repair: InformationRepair,
) -> Result<(G2oGraph, Vec<RepairedEdge>), GraphFileError> {
    let mut repaired = Vec::new();
    let mut g2: Option<PoseGraph<Pose2>> = None;
    let mut g3: Option<PoseGraph<Pose3>> = None;
    let mut fixes: Vec<(usize, u64)> = Vec::new();
    let mut unknown = UnknownTags::default();
    for (line, tag, rest) in tagged_lines(text) {
        let graph_err = |source| GraphFileError::Graph { line, source };
        match tag {
            "VERTEX_SE3:QUAT" => {
                if g2.is_some() {
                    return Err(GraphFileError::MixedDimensions { line });
                }
                let (idw, vals) = rest
                    .split_first()
                    .ok_or_else(|| line_err(line, "no vertex id"))?;
                let v = numbers(vals, line, 7, tag)?;
                let q = quaternion_from_xyzw([v[3], v[4], v[5], v[6]])
                    .ok_or_else(|| line_err(line, "quaternion is not unit"))?;
                let pose = Pose3::from_parts(Translation3::new(v[0], v[1], v[2]), q);
                g3.get_or_insert_with(PoseGraph::new)
                    .add_node(id(idw, line)?, pose)
                    .map_err(graph_err)?;
            }
            "EDGE_SE3:QUAT" => {
                if g2.is_some() {
                    return Err(GraphFileError::MixedDimensions { line });
                }
                if rest.len() < 2 {
                    return Err(line_err(line, "edge needs two vertex ids"));
                }
                let (a, b) = (id(rest[0], line)?, id(rest[1], line)?);
                let v = numbers(&rest[2..], line, 7 + 21, tag)?;
                let q = quaternion_from_xyzw([v[3], v[4], v[5], v[6]])
                    .ok_or_else(|| line_err(line, "quaternion is not unit"))?;
                let z = Pose3::from_parts(Translation3::new(v[0], v[1], v[2]), q);
                let mut info = Matrix6::zeros();
                let mut idx = 7;
                for r in 0..6 {
                    for c in r..6 {
                        info[(r, c)] = v[idx];
                        info[(c, r)] = v[idx];
                        idx += 1;
                    }
                }
                let edge = g3.as_ref().map_or(0, PoseGraph::edge_count);
                let info = repair.apply(info, line, edge, &mut repaired)?;
                g3.get_or_insert_with(PoseGraph::new)
                    .add_edge(a, b, z, info, None)
                    .map_err(graph_err)?;
            }
            "VERTEX_SE2" => {
                if g3.is_some() {
                    return Err(GraphFileError::MixedDimensions { line });
                }
                let (idw, vals) = rest
                    .split_first()
                    .ok_or_else(|| line_err(line, "no vertex id"))?;
                let v = numbers(vals, line, 3, tag)?;
                let pose = Pose2::new(Vector2::new(v[0], v[1]), v[2]);
                g2.get_or_insert_with(PoseGraph::new)
                    .add_node(id(idw, line)?, pose)
                    .map_err(graph_err)?;
            }
            "EDGE_SE2" => {
                if g3.is_some() {
                    return Err(GraphFileError::MixedDimensions { line });
                }
                if rest.len() < 2 {
                    return Err(line_err(line, "edge needs two vertex ids"));
                }
                let (a, b) = (id(rest[0], line)?, id(rest[1], line)?);
                let v = numbers(&rest[2..], line, 3 + 6, tag)?;
                let z = Pose2::new(Vector2::new(v[0], v[1]), v[2]);
                let info = Matrix3::new(v[3], v[4], v[5], v[4], v[6], v[7], v[5], v[7], v[8]);
                let edge = g2.as_ref().map_or(0, PoseGraph::edge_count);
                let info = repair.apply(info, line, edge, &mut repaired)?;
                g2.get_or_insert_with(PoseGraph::new)
                    .add_edge(a, b, z, info, None)
                    .map_err(graph_err)?;
            }
            "FIX" => {
                if rest.is_empty() {
                    return Err(line_err(line, "FIX needs a vertex id"));
                }
                for w in rest {
                    fixes.push((line, id(w, line)?));
                }
            }
            other => unknown.note(line, other),
        }
    }
    unknown.check()?;
    let mut out = match (g2, g3) {
        (Some(g), None) => G2oGraph::Se2(g),
        (None, Some(g)) => G2oGraph::Se3(g),
        (None, None) => return Err(line_err(0, "no vertices or edges")),
        (Some(_), Some(_)) => return Err(GraphFileError::MixedDimensions { line: 0 }),
    };
    for (line, id) in fixes {
        let r = match &mut out {
            G2oGraph::Se2(g) => g.fix(id),
            G2oGraph::Se3(g) => g.fix(id),
        };
        r.map_err(|source| GraphFileError::Graph { line, source })?;
    }
    Ok((out, repaired))
}

/// Read a g2o file.
///
/// # Errors
/// [`GraphFileError::Io`], or as [`parse_g2o`].
pub fn read_g2o(path: impl AsRef<Path>) -> Result<G2oGraph, GraphFileError> {
    read_g2o_with(path, InformationRepair::Refuse).map(|(graph, _)| graph)
}

/// Read a g2o file with `repair` (see [`parse_g2o_with`]).
///
/// # Errors
/// [`GraphFileError::Io`], or as [`parse_g2o`].
pub fn read_g2o_with(
    path: impl AsRef<Path>,
    repair: InformationRepair,
) -> Result<(G2oGraph, Vec<RepairedEdge>), GraphFileError> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|source| GraphFileError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_g2o_with(&text, repair)
}

/// g2o text of an SE(3) graph (full precision: it reads back exactly).
#[must_use]
pub fn g2o_text_se3(graph: &PoseGraph<Pose3>) -> String {
    let mut s = String::new();
    for n in graph.nodes() {
        let t = n.pose.translation.vector;
        let q = quaternion_to_xyzw(&n.pose.rotation);
        let _ = writeln!(
            s,
            "VERTEX_SE3:QUAT {} {} {} {} {} {} {} {}",
            n.id, t.x, t.y, t.z, q[0], q[1], q[2], q[3]
        );
    }
    for n in graph.nodes().iter().filter(|n| n.fixed) {
        let _ = writeln!(s, "FIX {}", n.id);
    }
    for e in graph.edges() {
        let (a, b) = (graph.nodes()[e.from].id, graph.nodes()[e.to].id);
        let t = e.measurement.translation.vector;
        let q = quaternion_to_xyzw(&e.measurement.rotation);
        let _ = write!(
            s,
            "EDGE_SE3:QUAT {a} {b} {} {} {} {} {} {} {}",
            t.x, t.y, t.z, q[0], q[1], q[2], q[3]
        );
        for r in 0..6 {
            for c in r..6 {
                let _ = write!(s, " {}", e.information[(r, c)]);
            }
        }
        s.push('\n');
    }
    s
}

/// g2o text of an SE(2) graph (full precision).
#[must_use]
pub fn g2o_text_se2(graph: &PoseGraph<Pose2>) -> String {
    se2_text(
        graph,
        &Se2Format {
            vertex: "VERTEX_SE2",
            edge: "EDGE_SE2",
            information: [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)],
            fix_lines: true,
        },
    )
}

/// Write a graph as a g2o file.
///
/// # Errors
/// [`GraphFileError::Io`].
pub fn write_g2o(path: impl AsRef<Path>, graph: &G2oGraph) -> Result<(), GraphFileError> {
    let path = path.as_ref();
    let text = match graph {
        G2oGraph::Se2(g) => g2o_text_se2(g),
        G2oGraph::Se3(g) => g2o_text_se3(g),
    };
    std::fs::write(path, text).map_err(|source| GraphFileError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// The cost in g2o's own convention: SE(3) error `[t; qv]` of `z^-1 a^-1 b` (quaternion vector
/// part with `qw >= 0`), SE(2) error `[x, y, theta]` of `z^-1 a^-1 b`; `sum e^T Omega e`.
#[must_use]
pub fn g2o_chi2(graph: &G2oGraph) -> f64 {
    match graph {
        G2oGraph::Se3(g) => g
            .edges()
            .iter()
            .map(|e| {
                let d = e.measurement.inverse()
                    * (g.nodes()[e.from].pose.inverse() * g.nodes()[e.to].pose);
                let q = d.rotation;
                let s = if q.w < 0.0 { -1.0 } else { 1.0 };
                let t = d.translation.vector;
                let v = nalgebra::Vector6::new(t.x, t.y, t.z, s * q.i, s * q.j, s * q.k);
                Pose3::mahalanobis_squared(&v, &e.information)
            })
            .sum(),
        G2oGraph::Se2(g) => g
            .edges()
            .iter()
            .map(|e| {
                let d = e.measurement.inverse()
                    * (g.nodes()[e.from].pose.inverse() * g.nodes()[e.to].pose);
                let t = d.translation.vector;
                let v = nalgebra::Vector3::new(t.x, t.y, d.rotation.angle());
                Pose2::mahalanobis_squared(&v, &e.information)
            })
            .sum(),
    }
}
