//! The text lines shared by the two SE(2) graph formats (g2o's `VERTEX_SE2`/`EDGE_SE2` and
//! TORO's `VERTEX2`/`EDGE2`): `TAG id x y theta` and `TAG from to dx dy dtheta` followed by six
//! information entries in the format's own order. Floats are printed so they read back exactly.

use std::fmt::Write as _;

use slam_core::{Pose2, PoseGraph};

/// How one SE(2) format spells its lines.
pub(crate) struct Se2Format {
    pub(crate) vertex: &'static str,
    pub(crate) edge: &'static str,
    /// The (row, column) of each written information entry, in order.
    pub(crate) information: [(usize, usize); 6],
    /// Whether fixed nodes are written as `FIX id` lines (TORO has none).
    pub(crate) fix_lines: bool,
}

/// The text of `graph` in `format`.
pub(crate) fn se2_text(graph: &PoseGraph<Pose2>, format: &Se2Format) -> String {
    let mut s = String::new();
    for n in graph.nodes() {
        let t = n.pose.translation.vector;
        let theta = n.pose.rotation.angle();
        let _ = writeln!(s, "{} {} {} {} {theta}", format.vertex, n.id, t.x, t.y);
    }
    if format.fix_lines {
        for n in graph.nodes().iter().filter(|n| n.fixed) {
            let _ = writeln!(s, "FIX {}", n.id);
        }
    }
    for e in graph.edges() {
        let (a, b) = (graph.nodes()[e.from].id, graph.nodes()[e.to].id);
        let t = e.measurement.translation.vector;
        let theta = e.measurement.rotation.angle();
        let _ = write!(s, "{} {a} {b} {} {} {theta}", format.edge, t.x, t.y);
        for &(r, c) in &format.information {
            let _ = write!(s, " {}", e.information[(r, c)]);
        }
        s.push('\n');
    }
    s
}
