//! Chordal initialisation: a global initial guess that does not depend on the graph's own guess.
//!
//! Rotations first, by the chordal relaxation (Martinec and Pajdla, CVPR 2007; Carlone, Tron,
//! Daniilidis and Dellaert, "Initialization Techniques for 3D SLAM", ICRA 2015, section IV-A):
//! each edge asks `R_b = R_a R_z`, which is linear in the entries of the rotation matrices, so
//! `min sum kappa ||R_b^T - R_z^T R_a^T||_F^2` over unconstrained matrices is a sparse linear
//! least-squares problem (the columns of `R^T` decouple and share one normal matrix, solved with
//! faer's sparse Cholesky); each solution is then projected onto SO(3) (SVD) or SO(2). Then the
//! translations, given those rotations: `min sum ||t_b - t_a - R_a t_z||^2` weighted by the edge's
//! translational information rotated into the world frame, again one sparse linear solve. Fixed
//! nodes keep their poses and anchor both solves.
//!
//! The result is a starting point for [`LevenbergMarquardt`](crate::LevenbergMarquardt) or
//! [`GaussNewton`](crate::GaussNewton), not an optimum: on torus3D, LM from the file's own guess
//! stops in a local minimum, LM from the chordal guess reaches SE-Sync's certified optimum.

use nalgebra::{
    Matrix2, Matrix3, Rotation2, Rotation3, SMatrix, SVector, Translation3, UnitComplex,
    UnitQuaternion, Vector2, Vector3,
};
use slam_core::{FactorizationFailure, GraphPose, OptimizeError, Pose2, Pose3, PoseGraph};

use crate::normal_equations::NormalEquations;

/// A pose type with a chordal initialisation: [`Pose3`] and [`Pose2`].
pub trait ChordalInitialization: GraphPose {
    /// Replace the poses of the free nodes of `graph` by the chordal estimate (see
    /// [`initialize_chordal`]).
    ///
    /// # Errors
    /// As [`initialize_chordal`].
    fn initialize_chordal(graph: &mut PoseGraph<Self>) -> Result<(), OptimizeError>;
}

/// Replace the poses of the free nodes of `graph` by the chordal estimate: rotations from the
/// chordal relaxation projected onto SO(n), then translations by linear least squares given those
/// rotations. The fixed nodes keep their poses. The graph's current free poses are not used.
///
/// ```
/// use posegraph::initialize_chordal;
/// use slam_core::{GraphPose, PoseGraph, Pose2};
///
/// // A triangle whose free poses start far from where the edges put them.
/// let mut g = PoseGraph::<Pose2>::new();
/// g.add_node(0, Pose2::identity())?;
/// g.add_node(1, Pose2::new([5.0, -3.0].into(), 2.0))?;
/// g.add_node(2, Pose2::new([-4.0, 1.0].into(), -2.5))?;
/// g.fix(0)?;
/// let quarter = std::f64::consts::FRAC_PI_2;
/// let info = Pose2::identity_information();
/// g.add_edge(0, 1, Pose2::new([1.0, 0.0].into(), quarter), info, None)?;
/// g.add_edge(1, 2, Pose2::new([1.0, 0.0].into(), quarter), info, None)?;
/// g.add_edge(0, 2, Pose2::new([1.0, 1.0].into(), 2.0 * quarter), info, None)?;
/// initialize_chordal(&mut g)?;
/// assert!(g.cost() < 1e-20);
/// # Ok::<(), slam_core::OptimizeError>(())
/// ```
///
/// # Errors
/// [`OptimizeError::NoFixedNode`] and [`OptimizeError::Disconnected`] as the optimisers;
/// [`OptimizeError::Factorization`] if a linear system cannot be solved.
pub fn initialize_chordal<P: ChordalInitialization>(
    graph: &mut PoseGraph<P>,
) -> Result<(), OptimizeError> {
    P::initialize_chordal(graph)
}

impl ChordalInitialization for Pose3 {
    fn initialize_chordal(graph: &mut PoseGraph<Self>) -> Result<(), OptimizeError> {
        run::<Pose3, 3>(graph)
    }
}

impl ChordalInitialization for Pose2 {
    fn initialize_chordal(graph: &mut PoseGraph<Self>) -> Result<(), OptimizeError> {
        run::<Pose2, 2>(graph)
    }
}

/// What the two linear solves need from a pose type with `B`-dimensional rotations.
trait Parts<const B: usize>: GraphPose {
    /// The rotation matrix.
    fn rotation(&self) -> SMatrix<f64, B, B>;
    /// The translation.
    fn translation(&self) -> SVector<f64, B>;
    /// The pose with the rotation nearest to `m` (any `B x B` matrix) and translation `t`.
    fn from_matrix(m: &SMatrix<f64, B, B>, t: &SVector<f64, B>) -> Self;
    /// The scalar rotation weight `kappa` of an edge.
    fn rotation_weight(information: &Self::Information) -> f64;
    /// The translational block of an edge's information.
    fn translation_information(information: &Self::Information) -> SMatrix<f64, B, B>;
}

impl Parts<3> for Pose3 {
    fn rotation(&self) -> Matrix3<f64> {
        self.rotation.to_rotation_matrix().into_inner()
    }
    fn translation(&self) -> Vector3<f64> {
        self.translation.vector
    }
    fn from_matrix(m: &Matrix3<f64>, t: &Vector3<f64>) -> Self {
        // Nearest rotation in the Frobenius norm: U diag(1, 1, det(U V^T)) V^T.
        let svd = m.svd(true, true);
        let r = match (svd.u, svd.v_t) {
            (Some(u), Some(v_t)) => {
                let d = (u * v_t).determinant().signum();
                u * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * v_t
            }
            _ => Matrix3::identity(),
        };
        let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
        Pose3::from_parts(Translation3::from(*t), q)
    }
    fn rotation_weight(information: &nalgebra::Matrix6<f64>) -> f64 {
        // SE-Sync's kappa (up to a common factor): 3 / tr(Omega_R^-1).
        let omega_r = information.fixed_view::<3, 3>(3, 3).into_owned();
        omega_r
            .try_inverse()
            .map_or(omega_r.trace() / 3.0, |c| 3.0 / c.trace())
    }
    fn translation_information(information: &nalgebra::Matrix6<f64>) -> Matrix3<f64> {
        information.fixed_view::<3, 3>(0, 0).into_owned()
    }
}

impl Parts<2> for Pose2 {
    fn rotation(&self) -> Matrix2<f64> {
        self.rotation.to_rotation_matrix().into_inner()
    }
    fn translation(&self) -> Vector2<f64> {
        self.translation.vector
    }
    fn from_matrix(m: &Matrix2<f64>, t: &Vector2<f64>) -> Self {
        // The nearest rotation to [[a, b], [c, d]] has angle atan2(c - b, a + d).
        let angle = (m[(1, 0)] - m[(0, 1)]).atan2(m[(0, 0)] + m[(1, 1)]);
        let r = UnitComplex::from_rotation_matrix(&Rotation2::new(angle));
        Pose2::from_parts((*t).into(), r)
    }
    fn rotation_weight(information: &Matrix3<f64>) -> f64 {
        information[(2, 2)]
    }
    fn translation_information(information: &Matrix3<f64>) -> Matrix2<f64> {
        information.fixed_view::<2, 2>(0, 0).into_owned()
    }
}

/// One linear edge term `r = x_b - A x_a - c` with weight `W` (`x` has `K` columns).
struct Term<const B: usize, const K: usize> {
    a: SMatrix<f64, B, B>,
    c: SMatrix<f64, B, K>,
    w: SMatrix<f64, B, B>,
}

/// Minimise `sum_k r_k^T W_k r_k` over the free nodes' `x`, with `known[i]` for fixed node `i`.
/// Returns `x` for every node (the known value for fixed nodes).
fn solve_linear<P: GraphPose, const B: usize, const K: usize>(
    graph: &PoseGraph<P>,
    ne: &mut NormalEquations<B>,
    terms: &[Term<B, K>],
    known: &[SMatrix<f64, B, K>],
) -> Result<Vec<SMatrix<f64, B, K>>, OptimizeError> {
    let n = ne.dimension();
    ne.clear();
    let mut rhs = faer::Mat::<f64>::zeros(n, K);
    let identity = SMatrix::<f64, B, B>::identity();
    let mut add_rhs = |v: usize, m: SMatrix<f64, B, K>| {
        for c in 0..K {
            for r in 0..B {
                rhs[(v * B + r, c)] += m[(r, c)];
            }
        }
    };
    for (k, (e, t)) in graph.edges().iter().zip(terms).enumerate() {
        let minus_a = -t.a;
        ne.add_hessian(k, &minus_a, &identity, &t.w);
        match ne.edge_variables(k) {
            (Some(va), Some(vb)) => {
                add_rhs(va, minus_a.transpose() * t.w * t.c);
                add_rhs(vb, t.w * t.c);
            }
            (None, Some(vb)) => add_rhs(vb, t.w * (t.c + t.a * known[e.from])),
            (Some(va), None) => add_rhs(va, minus_a.transpose() * t.w * (t.c - known[e.to])),
            (None, None) => {}
        }
    }
    let values = std::mem::take(&mut ne.values);
    let factorized = ne.factorize(&values);
    ne.values = values;
    if !factorized {
        return Err(OptimizeError::Factorization {
            stage: "chordal relaxation",
            cause: FactorizationFailure::NotPositiveDefinite,
        });
    }
    ne.solve_in_place(rhs.as_mut());
    let mut out = known.to_vec();
    for (i, x) in out.iter_mut().enumerate() {
        if let Some(v) = ne.variable(i) {
            *x = SMatrix::<f64, B, K>::from_fn(|r, c| rhs[(v * B + r, c)]);
        }
    }
    if out.iter().all(|x| x.iter().all(|v| v.is_finite())) {
        Ok(out)
    } else {
        Err(OptimizeError::Factorization {
            stage: "chordal relaxation",
            cause: FactorizationFailure::NonFiniteSolution,
        })
    }
}

fn run<P: Parts<B>, const B: usize>(graph: &mut PoseGraph<P>) -> Result<(), OptimizeError> {
    graph.check_gauge()?;
    let mut ne = NormalEquations::<B>::new(graph)?;
    if ne.dimension() == 0 {
        return Ok(());
    }
    // Rotations: x = R^T, so each edge asks x_b = R_z^T x_a.
    let known: Vec<SMatrix<f64, B, B>> = graph
        .nodes()
        .iter()
        .map(|n| n.pose.rotation().transpose())
        .collect();
    let terms: Vec<Term<B, B>> = graph
        .edges()
        .iter()
        .map(|e| Term {
            a: e.measurement.rotation().transpose(),
            c: SMatrix::zeros(),
            w: SMatrix::identity() * P::rotation_weight(&e.information),
        })
        .collect();
    let x = solve_linear(graph, &mut ne, &terms, &known)?;
    let rotations: Vec<SMatrix<f64, B, B>> = graph
        .nodes()
        .iter()
        .zip(&x)
        .map(|(n, x)| {
            if n.fixed {
                n.pose.rotation()
            } else {
                P::from_matrix(&x.transpose(), &SVector::zeros()).rotation()
            }
        })
        .collect();
    // Translations: t_b - t_a - R_a t_z, weighted by R_a R_z Omega_t R_z^T R_a^T.
    let known: Vec<SMatrix<f64, B, 1>> =
        graph.nodes().iter().map(|n| n.pose.translation()).collect();
    let terms: Vec<Term<B, 1>> = graph
        .edges()
        .iter()
        .map(|e| {
            let ra = rotations[e.from];
            let rot = ra * e.measurement.rotation();
            Term {
                a: SMatrix::identity(),
                c: ra * e.measurement.translation(),
                w: rot * P::translation_information(&e.information) * rot.transpose(),
            }
        })
        .collect();
    let t = solve_linear(graph, &mut ne, &terms, &known)?;
    for (i, (r, t)) in rotations.iter().zip(&t).enumerate() {
        if ne.variable(i).is_some() {
            graph.set_pose(i, P::from_matrix(r, t));
        }
    }
    Ok(())
}
