//! The three backend traits: registration, pose-graph optimisation and grid planning.

pub mod optimizer;
pub mod planner;
pub mod registrator;
