//! The backend traits: registration, pose-graph optimisation, grid planning, and place
//! recognition for loop closure.

pub mod optimizer;
pub mod place_recognizer;
pub mod planner;
pub mod registrator;
