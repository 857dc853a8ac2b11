//! The pose-graph data type that the SLAM engine builds and an [`Optimizer`](crate::Optimizer)
//! solves: nodes with poses (some fixed), between-edges with information matrices and optional
//! robust kernels. SE(3) and SE(2) share one generic type through [`GraphPose`].

use std::collections::HashMap;
use std::fmt::Debug;

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

use crate::error::{GraphValue, OptimizeError};
use crate::geometry::{Pose2, Pose3, se2_log, se3_log};
use crate::robust_kernel::RobustKernel;

/// A pose type a graph can hold: SE(3) ([`Pose3`]) or SE(2) ([`Pose2`]).
pub trait GraphPose: Copy + Debug + PartialEq + Send + Sync + 'static {
    /// Degrees of freedom (6 or 3).
    const DOF: usize;
    /// Tangent vector (`[rho; phi]` for SE(3), `[x, y, theta]` for SE(2)).
    type Tangent: Copy + Debug + PartialEq;
    /// Information matrix, DOF x DOF, in the tangent's order.
    type Information: Copy + Debug + PartialEq + Send + Sync;

    /// The edge error `log(z^-1 (a^-1 b))` of measurement `z` between `a` and `b` (GTSAM's
    /// `BetweenFactor` convention).
    fn edge_error(z: &Self, a: &Self, b: &Self) -> Self::Tangent;
    /// `e^T Omega e`.
    fn mahalanobis_squared(e: &Self::Tangent, information: &Self::Information) -> f64;
    /// Whether `information` is finite, symmetric (to 1e-9 relative) and positive definite.
    fn information_is_valid(information: &Self::Information) -> bool;
    /// The identity information matrix.
    fn identity_information() -> Self::Information;
    /// Whether every number is finite.
    fn is_finite(&self) -> bool;
}

fn symmetric_positive_definite<const N: usize>(m: &nalgebra::SMatrix<f64, N, N>) -> bool {
    if !m.iter().all(|v| v.is_finite()) {
        return false;
    }
    let scale = m.amax().max(f64::MIN_POSITIVE);
    if (m - m.transpose()).amax() > 1e-9 * scale {
        return false;
    }
    m.cholesky().is_some()
}

impl GraphPose for Pose3 {
    const DOF: usize = 6;
    type Tangent = Vector6<f64>;
    type Information = Matrix6<f64>;

    fn edge_error(z: &Self, a: &Self, b: &Self) -> Vector6<f64> {
        se3_log(&(z.inverse() * (a.inverse() * b)))
    }
    fn mahalanobis_squared(e: &Vector6<f64>, information: &Matrix6<f64>) -> f64 {
        (e.transpose() * information * e)[0]
    }
    fn information_is_valid(information: &Matrix6<f64>) -> bool {
        symmetric_positive_definite(information)
    }
    fn identity_information() -> Matrix6<f64> {
        Matrix6::identity()
    }
    fn is_finite(&self) -> bool {
        crate::geometry::pose3_is_finite(self)
    }
}

impl GraphPose for Pose2 {
    const DOF: usize = 3;
    type Tangent = Vector3<f64>;
    type Information = Matrix3<f64>;

    fn edge_error(z: &Self, a: &Self, b: &Self) -> Vector3<f64> {
        se2_log(&(z.inverse() * (a.inverse() * b)))
    }
    fn mahalanobis_squared(e: &Vector3<f64>, information: &Matrix3<f64>) -> f64 {
        (e.transpose() * information * e)[0]
    }
    fn information_is_valid(information: &Matrix3<f64>) -> bool {
        symmetric_positive_definite(information)
    }
    fn identity_information() -> Matrix3<f64> {
        Matrix3::identity()
    }
    fn is_finite(&self) -> bool {
        self.translation.vector.iter().all(|v| v.is_finite())
            && self.rotation.re.is_finite()
            && self.rotation.im.is_finite()
    }
}

/// A node: a user-chosen id, its pose (`world_T_node`) and whether the optimiser must keep it.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Node<P> {
    /// The caller's id (g2o vertex id, keyframe number); unique within a graph.
    pub id: u64,
    /// Current estimate.
    pub pose: P,
    /// Held constant by optimisers (the gauge).
    pub fixed: bool,
}

/// A between-edge: `measurement` of `from^-1 * to`, with its information matrix.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(bound(
        serialize = "P: serde::Serialize, P::Information: serde::Serialize",
        deserialize = "P: serde::Deserialize<'de>, P::Information: serde::Deserialize<'de>"
    ))
)]
pub struct Edge<P: GraphPose> {
    /// Index (not id) of the first node in [`PoseGraph::nodes`].
    pub from: usize,
    /// Index of the second node.
    pub to: usize,
    /// Measured `from_T_to`.
    pub measurement: P,
    /// Inverse covariance of the measurement, in the tangent's order.
    pub information: P::Information,
    /// Optional robust kernel (for loop closures that may be wrong).
    pub kernel: Option<RobustKernel>,
}

/// A pose graph over SE(3) (`PoseGraph<Pose3>`) or SE(2) (`PoseGraph<Pose2>`). Nodes and edges
/// are only ever appended, so an optimiser can keep work from earlier calls and redo only what
/// the new nodes and edges touch.
///
/// With the `serde` feature a graph (de)serialises as its `nodes` and `edges` (edges by node
/// index, as [`PoseGraph::edges`] gives them); a graph read back is rebuilt node by node and
/// edge by edge, so it passes the checks of [`add_node`](Self::add_node) and
/// [`add_edge`](Self::add_edge).
///
/// ```
/// use slam_core::{GraphPose, PoseGraph, Pose2};
/// let mut g = PoseGraph::<Pose2>::new();
/// g.add_node(10, Pose2::identity())?;
/// g.add_node(11, Pose2::new([1.0, 0.0].into(), 0.0))?;
/// g.fix(10)?;
/// g.add_edge(10, 11, Pose2::new([1.0, 0.0].into(), 0.0), Pose2::identity_information(), None)?;
/// assert!(g.cost() < 1e-20);
/// g.check_gauge()?;
/// # Ok::<(), slam_core::OptimizeError>(())
/// ```
#[derive(Clone, Debug, Default)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(
        try_from = "serde_form::RawGraph<P>",
        into = "serde_form::RawGraph<P>",
        bound(
            serialize = "P: serde::Serialize, P::Information: serde::Serialize",
            deserialize = "P: serde::Deserialize<'de>, P::Information: serde::Deserialize<'de>"
        )
    )
)]
pub struct PoseGraph<P: GraphPose> {
    nodes: Vec<Node<P>>,
    edges: Vec<Edge<P>>,
    index: HashMap<u64, usize>,
}

impl<P: GraphPose> PoseGraph<P> {
    /// An empty graph.
    #[must_use]
    pub fn new() -> Self {
        Self {
            nodes: Vec::new(),
            edges: Vec::new(),
            index: HashMap::new(),
        }
    }

    /// Add a free node; returns its index.
    ///
    /// # Errors
    /// [`OptimizeError::DuplicateNode`] or [`OptimizeError::NonFinite`].
    pub fn add_node(&mut self, id: u64, pose: P) -> Result<usize, OptimizeError> {
        if self.index.contains_key(&id) {
            return Err(OptimizeError::DuplicateNode { id });
        }
        if !pose.is_finite() {
            return Err(OptimizeError::NonFinite {
                what: GraphValue::NodePose { id },
            });
        }
        self.nodes.push(Node {
            id,
            pose,
            fixed: false,
        });
        self.index.insert(id, self.nodes.len() - 1);
        Ok(self.nodes.len() - 1)
    }

    /// Add an edge between the nodes with ids `from` and `to`; returns its index.
    ///
    /// # Errors
    /// [`OptimizeError::UnknownNode`], [`OptimizeError::SelfLoop`], [`OptimizeError::NonFinite`],
    /// [`OptimizeError::InformationNotPositiveDefinite`] or
    /// [`OptimizeError::InvalidRobustKernel`].
    pub fn add_edge(
        &mut self,
        from: u64,
        to: u64,
        measurement: P,
        information: P::Information,
        kernel: Option<RobustKernel>,
    ) -> Result<usize, OptimizeError> {
        let a = self
            .node_index(from)
            .ok_or(OptimizeError::UnknownNode { id: from })?;
        let b = self
            .node_index(to)
            .ok_or(OptimizeError::UnknownNode { id: to })?;
        if a == b {
            return Err(OptimizeError::SelfLoop { id: from });
        }
        if !measurement.is_finite() {
            return Err(OptimizeError::NonFinite {
                what: GraphValue::Measurement {
                    edge: self.edges.len(),
                    from,
                    to,
                },
            });
        }
        if !P::information_is_valid(&information) {
            return Err(OptimizeError::InformationNotPositiveDefinite {
                edge: self.edges.len(),
            });
        }
        if let Some(kernel) = kernel
            && !kernel.is_valid()
        {
            return Err(OptimizeError::InvalidRobustKernel {
                edge: self.edges.len(),
                kernel,
            });
        }
        self.edges.push(Edge {
            from: a,
            to: b,
            measurement,
            information,
            kernel,
        });
        Ok(self.edges.len() - 1)
    }

    /// Hold the node with id `id` constant.
    ///
    /// # Errors
    /// [`OptimizeError::UnknownNode`].
    pub fn fix(&mut self, id: u64) -> Result<(), OptimizeError> {
        let i = self
            .node_index(id)
            .ok_or(OptimizeError::UnknownNode { id })?;
        self.nodes[i].fixed = true;
        Ok(())
    }

    /// Let the node with id `id` move again.
    ///
    /// # Errors
    /// [`OptimizeError::UnknownNode`].
    pub fn unfix(&mut self, id: u64) -> Result<(), OptimizeError> {
        let i = self
            .node_index(id)
            .ok_or(OptimizeError::UnknownNode { id })?;
        self.nodes[i].fixed = false;
        Ok(())
    }

    /// The index of the node with id `id`.
    #[must_use]
    pub fn node_index(&self, id: u64) -> Option<usize> {
        self.index.get(&id).copied()
    }

    /// The pose of the node with id `id`.
    #[must_use]
    pub fn pose(&self, id: u64) -> Option<&P> {
        self.node_index(id).map(|i| &self.nodes[i].pose)
    }

    /// Nodes in insertion order.
    #[must_use]
    pub fn nodes(&self) -> &[Node<P>] {
        &self.nodes
    }

    /// Edges in insertion order.
    #[must_use]
    pub fn edges(&self) -> &[Edge<P>] {
        &self.edges
    }

    /// Set the pose of the node at `index` (optimisers write their result through this).
    ///
    /// # Panics
    /// If `index` is out of range.
    pub fn set_pose(&mut self, index: usize, pose: P) {
        self.nodes[index].pose = pose;
    }

    /// Number of nodes.
    #[must_use]
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Number of edges.
    #[must_use]
    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }

    /// The squared Mahalanobis error of edge `e` at the current poses (no kernel).
    #[must_use]
    pub fn edge_chi2(&self, e: &Edge<P>) -> f64 {
        let err = P::edge_error(
            &e.measurement,
            &self.nodes[e.from].pose,
            &self.nodes[e.to].pose,
        );
        P::mahalanobis_squared(&err, &e.information)
    }

    /// Total cost `sum_e rho_e(e^T Omega e)` (no factor 1/2; `rho` is the identity without a
    /// kernel).
    #[must_use]
    pub fn cost(&self) -> f64 {
        self.edges
            .iter()
            .map(|e| {
                let s = self.edge_chi2(e);
                e.kernel.map_or(s, |k| k.rho(s))
            })
            .sum()
    }

    /// Check that the problem has a gauge: at least one fixed node and every node connected to a
    /// fixed node through edges.
    ///
    /// # Errors
    /// [`OptimizeError::EmptyGraph`], [`OptimizeError::NoFixedNode`] or
    /// [`OptimizeError::Disconnected`].
    pub fn check_gauge(&self) -> Result<(), OptimizeError> {
        fn find(p: &mut [usize], mut i: usize) -> usize {
            while p[i] != i {
                p[i] = p[p[i]];
                i = p[i];
            }
            i
        }
        if self.nodes.is_empty() {
            return Err(OptimizeError::EmptyGraph);
        }
        // Union-find over edges, then every root must hold a fixed node.
        let mut parent: Vec<usize> = (0..self.nodes.len()).collect();
        for e in &self.edges {
            let (a, b) = (find(&mut parent, e.from), find(&mut parent, e.to));
            if a != b {
                parent[a] = b;
            }
        }
        let mut anchored = vec![false; self.nodes.len()];
        let mut any_fixed = false;
        for (i, n) in self.nodes.iter().enumerate() {
            if n.fixed {
                any_fixed = true;
                let r = find(&mut parent, i);
                anchored[r] = true;
            }
        }
        if !any_fixed {
            return Err(OptimizeError::NoFixedNode);
        }
        let mut count = 0;
        let mut first_id = 0;
        for i in 0..self.nodes.len() {
            let r = find(&mut parent, i);
            if !anchored[r] {
                if count == 0 {
                    first_id = self.nodes[i].id;
                }
                count += 1;
            }
        }
        if count > 0 {
            return Err(OptimizeError::Disconnected { count, first_id });
        }
        Ok(())
    }
}

/// The serialised form of a graph: its nodes and edges, rebuilt through `add_node`, `fix` and
/// `add_edge` on the way back in so a bad file cannot break the graph's invariants.
#[cfg(feature = "serde")]
mod serde_form {
    use super::{Edge, GraphPose, Node, PoseGraph};

    #[derive(serde::Serialize, serde::Deserialize)]
    #[serde(bound(
        serialize = "P: serde::Serialize, P::Information: serde::Serialize",
        deserialize = "P: serde::Deserialize<'de>, P::Information: serde::Deserialize<'de>"
    ))]
    pub(super) struct RawGraph<P: GraphPose> {
        nodes: Vec<Node<P>>,
        edges: Vec<Edge<P>>,
    }

    impl<P: GraphPose> From<PoseGraph<P>> for RawGraph<P> {
        fn from(g: PoseGraph<P>) -> Self {
            Self {
                nodes: g.nodes,
                edges: g.edges,
            }
        }
    }

    impl<P: GraphPose> TryFrom<RawGraph<P>> for PoseGraph<P> {
        /// The graph's own error (a duplicate id, a bad information matrix, ...), or an edge
        /// whose node index is past the nodes.
        type Error = String;
        fn try_from(raw: RawGraph<P>) -> Result<Self, String> {
            let mut graph = PoseGraph::new();
            for node in &raw.nodes {
                graph
                    .add_node(node.id, node.pose)
                    .map_err(|e| e.to_string())?;
                if node.fixed {
                    graph.fix(node.id).map_err(|e| e.to_string())?;
                }
            }
            for (k, edge) in raw.edges.iter().enumerate() {
                let id = |index: usize| {
                    raw.nodes.get(index).map(|n| n.id).ok_or_else(|| {
                        format!(
                            "edge {k} joins node index {index}, but the graph has {} nodes",
                            raw.nodes.len()
                        )
                    })
                };
                graph
                    .add_edge(
                        id(edge.from)?,
                        id(edge.to)?,
                        edge.measurement,
                        edge.information,
                        edge.kernel,
                    )
                    .map_err(|e| e.to_string())?;
            }
            Ok(graph)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::pose3_from_xyz_rpy;

    #[test]
    fn edges_validate_their_inputs() {
        let mut g = PoseGraph::<Pose3>::new();
        g.add_node(1, Pose3::identity()).unwrap();
        g.add_node(2, pose3_from_xyz_rpy(1.0, 0.0, 0.0, 0.0, 0.0, 0.3))
            .unwrap();
        assert!(matches!(
            g.add_node(1, Pose3::identity()),
            Err(OptimizeError::DuplicateNode { id: 1 })
        ));
        let info = Matrix6::identity();
        assert!(matches!(
            g.add_edge(1, 3, Pose3::identity(), info, None),
            Err(OptimizeError::UnknownNode { id: 3 })
        ));
        assert!(matches!(
            g.add_edge(1, 1, Pose3::identity(), info, None),
            Err(OptimizeError::SelfLoop { .. })
        ));
        let mut bad = info;
        bad[(0, 0)] = -1.0;
        assert!(matches!(
            g.add_edge(1, 2, Pose3::identity(), bad, None),
            Err(OptimizeError::InformationNotPositiveDefinite { .. })
        ));
        bad[(0, 0)] = f64::NAN;
        assert!(g.add_edge(1, 2, Pose3::identity(), bad, None).is_err());
        assert_eq!(
            g.add_node(3, Pose3::translation(f64::NAN, 0.0, 0.0)),
            Err(OptimizeError::NonFinite {
                what: GraphValue::NodePose { id: 3 }
            })
        );
        assert_eq!(
            g.add_edge(
                1,
                2,
                Pose3::translation(0.0, f64::INFINITY, 0.0),
                info,
                None
            ),
            Err(OptimizeError::NonFinite {
                what: GraphValue::Measurement {
                    edge: 0,
                    from: 1,
                    to: 2
                }
            })
        );
        let kernel = RobustKernel::Huber { delta: 0.0 };
        assert_eq!(
            g.add_edge(1, 2, Pose3::identity(), info, Some(kernel)),
            Err(OptimizeError::InvalidRobustKernel { edge: 0, kernel })
        );
        assert!(matches!(g.check_gauge(), Err(OptimizeError::NoFixedNode)));
        g.fix(1).unwrap();
        assert!(matches!(
            g.check_gauge(),
            Err(OptimizeError::Disconnected {
                count: 1,
                first_id: 2
            })
        ));
        let z = pose3_from_xyz_rpy(1.0, 0.0, 0.0, 0.0, 0.0, 0.3);
        g.add_edge(1, 2, z, info, None).unwrap();
        g.check_gauge().unwrap();
        assert!(g.cost() < 1e-20);
        // A 0.1 rad yaw error costs 0.01 with identity information.
        g.set_pose(1, pose3_from_xyz_rpy(1.0, 0.0, 0.0, 0.0, 0.0, 0.4));
        assert!((g.cost() - 0.01).abs() < 1e-9);
    }
}
