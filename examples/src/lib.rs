//! What the spot-nav examples share: where the bundled data lives, command-line pieces (backend
//! choices, `X,Y` goals, the simulator's sensor and motion), standard output that ends quietly
//! on a closed pipe, progress on stderr, timing summaries, the map-and-evaluate loop of the
//! `slam` and `mission` examples, and what `slam` adds to it: a ground-truth file, tracking
//! health and `summary.json`; and the settings files of `--config` and `--print-config`.
//!
//! Every example's `main` is a one-liner around [`run`], which gives each failure an exit
//! status of 1 and a one-line reason on stderr:
//!
//! ```no_run
//! use std::process::ExitCode;
//!
//! use spot_nav_examples::out;
//!
//! fn main() -> ExitCode {
//!     spot_nav_examples::run(|| {
//!         out!("hello")?; // `println!` would panic when stdout is a closed pipe
//!         Ok(())
//!     })
//! }
//! ```
//!
//! Not a library to build on: its functions print, exit and read the bundled files by path.

pub mod args;
pub mod data;
pub mod ground_truth;
pub mod health;
pub mod mapping;
pub mod output;
pub mod picture;
pub mod progress;
pub mod settings;
pub mod sim_options;
pub mod stats;
pub mod summary;

pub use args::{Registration, parse_goal, parse_numbers, value_name};
pub use ground_truth::{GroundTruthFile, GroundTruthFormat};
pub use health::{HealthSummary, print_tracking_health};
pub use mapping::{MappedScans, Mapping, evaluate, map_and_evaluate, map_samples};
pub use output::{StdoutClosed, run, write_line};
pub use progress::Progress;
pub use settings::{SettingsArgs, SettingsFormat, load_settings, print_settings};
pub use sim_options::{Motion, Sensor};
pub use stats::{Timings, quantile};
