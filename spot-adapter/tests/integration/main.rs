//! spot-adapter's integration tests in one binary: one link instead of one per file, and one
//! harness that runs every test across the cores (`cargo test -p spot-nav-adapter --release --test
//! integration [MODULE::]NAME`). Each module is one subject; `common` is what the navigation
//! tests share.

mod common;

mod aliasing;
mod bag_frames;
mod bag_gyro;
mod bags;
mod bounded_work;
mod building;
mod cloud_folder_export;
mod commanded;
mod config;
mod evaluation;
mod exploration;
mod floors;
mod floors_walk;
mod keyframe_scans;
mod lidar_models;
mod lidar_only;
mod motion_profiles;
mod multi_goal;
mod navigation;
mod place_recognition;
mod point_cloud2_fuzz;
mod recording;
mod simulator;
mod slam_loop;
mod slam_revisits;
mod tilted_estimate;
mod tracking;
