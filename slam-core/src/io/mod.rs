//! File formats: point clouds (PCD, PLY, KITTI `.bin`) and trajectories (KITTI poses, TUM).
