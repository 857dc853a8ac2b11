//! # posegraph
//!
//! Pose-graph optimisation for spot-nav: [`GaussNewton`] and [`LevenbergMarquardt`] over
//! [`slam_core::PoseGraph`] (SE(3) and SE(2)), with analytic Jacobians of the log-map error
//! (`e = log(z^-1 a^-1 b)`, as GTSAM's `BetweenFactor`), the sparse normal equations assembled
//! straight into a CSC pattern built once per graph structure, and faer's sparse Cholesky with the
//! symbolic factorisation reused for every numeric one. Robust kernels enter as IRLS weights.
//! [`ErrorModel::G2o`] minimises g2o's error convention instead. [`initialize_chordal`] gives a
//! global initial guess (chordal relaxation for rotations, then linear least squares for
//! translations; Carlone et al., ICRA 2015). [`g2o`] reads and writes g2o files and evaluates
//! g2o's own chi2 convention.
//!
//! Outlier-robust optimisation: [`GraduatedNonConvexity`] (Yang, Antonante, Tzoumas, Carlone,
//! "Graduated Non-Convexity for Robust Spatial Perception", RA-L 2020) over this crate's LM, with
//! the truncated least squares and Geman-McClure losses ([`GncLoss`]), known-inlier edges
//! ([`KnownInliers`]: odometry by default), a pairwise consistency test of candidate loops on
//! short odometry chains (the test of PCM, Mangelson et al., ICRA 2018) and every edge's final
//! weight in its [`GncReport`]; [`wrong_loops`] adds random wrong loop closures to test it
//! (Sünderhauf and Protzel's protocol, IROS 2012). A Geman-McClure kernel on an edge is graduated
//! the same way inside [`LevenbergMarquardt`] and [`GaussNewton`].
//!
//! ```
//! use posegraph::LevenbergMarquardt;
//! use slam_core::{GraphPose, Optimizer, PoseGraph, Pose2};
//!
//! // Three poses on a line, a loop edge that disagrees by 0.3 m.
//! let mut g = PoseGraph::<Pose2>::new();
//! for i in 0..3u64 {
//!     g.add_node(i, Pose2::new([i as f64, 0.0].into(), 0.0))?;
//! }
//! g.fix(0)?;
//! let info = Pose2::identity_information();
//! g.add_edge(0, 1, Pose2::new([1.0, 0.0].into(), 0.0), info, None)?;
//! g.add_edge(1, 2, Pose2::new([1.0, 0.0].into(), 0.0), info, None)?;
//! g.add_edge(0, 2, Pose2::new([2.3, 0.0].into(), 0.0), info, None)?;
//! let report = LevenbergMarquardt::default().optimize(&mut g)?;
//! // The 0.3 m disagreement is shared equally by the three edges: 3 * 0.1^2.
//! assert!((report.final_cost - 0.03).abs() < 1e-9);
//! # Ok::<(), slam_core::OptimizeError>(())
//! ```
//!
//! Incremental smoothing: [`IncrementalSmoother`] follows a growing graph through
//! [`slam_core::IncrementalOptimizer::update`] with iSAM2's fluid relinearisation and partial
//! re-elimination (Kaess et al., "iSAM2: Incremental smoothing and mapping using the Bayes
//! tree", IJRR 2012) on a block sparse Cholesky factor: a loop closure re-factors the nodes it
//! affects and their ancestors in the elimination tree, not the whole graph.
//!
//! When not to use it: for graphs that need a certified global optimum (the chordal guess usually
//! leads LM to it, as on torus3D, but nothing certifies it: use SE-Sync), or for landmark-based
//! factor graphs (this crate handles between-pose constraints only).

mod block_factor;
mod chordal;
mod error;
pub mod g2o;
mod gauss_newton;
mod gnc;
mod gnc_loss;
mod graph_text_lines;
mod incremental;
pub mod information_repair;
mod levenberg_marquardt;
mod linearize;
mod loop_support;
mod normal_equations;
mod se2_text;
mod solver;
mod sparse_cholesky;
pub mod toro;
pub mod wrong_loops;

pub use chordal::{ChordalInitialization, initialize_chordal};
pub use error::{GraphFileError, UnknownTag};
pub use gauss_newton::GaussNewton;
pub use gnc::{GncConfig, GncReport, GraduatedNonConvexity, KnownInliers};
pub use gnc_loss::GncLoss;
pub use incremental::{IncrementalConfig, IncrementalSmoother, SmootherStatistics};
pub use levenberg_marquardt::LevenbergMarquardt;
pub use linearize::{ErrorModel, Linearize};
pub use solver::{SolverConfig, SolverPose};
