//! One function per reader of user data: parse the bytes; when they parse, write the result with
//! our writer, read it back and panic unless it is the same data. The fuzz targets call these;
//! `tests/seeds.rs` runs every seed and every saved crash through them on stable Rust.

use crate::same::assert_same_cloud;
use crate::same::{assert_close_pose, assert_close_pose2};
use gridmap::{RosMapYaml, ros_map_pgm, ros_map_yaml};
use pathfind::movingai::{map_text, parse_map};
use pathfind::movingai::{parse_scenarios, scenarios_text};
use posegraph::g2o::{G2oGraph, g2o_text_se2, g2o_text_se3, parse_g2o};
use posegraph::toro::{parse_toro, toro_text};
use slam_core::io::{PcdEncoding, parse_pcd, write_pcd_to};
use slam_core::io::{PlyEncoding, parse_ply, write_ply_to};
use slam_core::io::{parse_kitti_bin, write_kitti_bin_to};
use slam_core::io::{parse_kitti_poses, write_kitti_poses_to};
use slam_core::io::{parse_tum, write_tum_to};
use slam_core::{GraphPose, PoseGraph};
use spot_adapter::record::parse_index;
use spot_adapter::record::{calibration_text, parse_calibration};
use std::path::Path;

/// PCD (ascii, binary and `binary_compressed` data: one reader): a file that parses is written in
/// both of our encodings and must read back to the same cloud.
#[must_use]
pub fn pcd(data: &[u8]) -> bool {
    let Ok(cloud) = parse_pcd(data) else {
        return false;
    };
    for encoding in [PcdEncoding::Binary, PcdEncoding::Ascii] {
        let mut bytes = Vec::new();
        write_pcd_to(&mut bytes, &cloud, encoding).expect("writing to memory");
        let back = parse_pcd(&bytes).expect("our own PCD reads back");
        assert_same_cloud(&cloud, &back, "PCD");
    }
    true
}

/// PLY (ascii, binary little and big endian: one reader): a file that parses is written in
/// both of our encodings and must read back to the same cloud.
#[must_use]
pub fn ply(data: &[u8]) -> bool {
    let Ok(cloud) = parse_ply(data) else {
        return false;
    };
    for encoding in [PlyEncoding::BinaryLittleEndian, PlyEncoding::Ascii] {
        let mut bytes = Vec::new();
        write_ply_to(&mut bytes, &cloud, encoding).expect("writing to memory");
        let back = parse_ply(&bytes).expect("our own PLY reads back");
        assert_same_cloud(&cloud, &back, "PLY");
    }
    true
}

/// KITTI velodyne scans (`x y z reflectance` as f32): written back bit for bit.
#[must_use]
pub fn kitti_bin(data: &[u8]) -> bool {
    let Ok(cloud) = parse_kitti_bin(data) else {
        return false;
    };
    let mut bytes = Vec::new();
    write_kitti_bin_to(&mut bytes, &cloud).expect("writing to memory");
    let back = parse_kitti_bin(&bytes).expect("our own scan reads back");
    assert_same_cloud(&cloud, &back, "KITTI scan");
    true
}

/// KITTI pose files (3x4 matrices): the poses written back read the same (the reader
/// re-orthonormalises rotations, so to rounding).
#[must_use]
pub fn kitti_poses(data: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(data) else {
        return false;
    };
    let Ok(poses) = parse_kitti_poses(text) else {
        return false;
    };
    let mut bytes = Vec::new();
    write_kitti_poses_to(&mut bytes, &poses).expect("writing to memory");
    let back = parse_kitti_poses(std::str::from_utf8(&bytes).expect("UTF-8"))
        .expect("our own poses read back");
    assert_eq!(poses.len(), back.len());
    for (a, b) in poses.iter().zip(&back) {
        assert_close_pose(a, b, 1e-9, "KITTI pose");
    }
    true
}

/// TUM trajectories (`stamp tx ty tz qx qy qz qw`): stamps exact, poses to rounding.
#[must_use]
pub fn tum(data: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(data) else {
        return false;
    };
    let Ok(poses) = parse_tum(text) else {
        return false;
    };
    let mut bytes = Vec::new();
    write_tum_to(&mut bytes, &poses).expect("writing to memory");
    let back =
        parse_tum(std::str::from_utf8(&bytes).expect("UTF-8")).expect("our own TUM reads back");
    assert_eq!(poses.len(), back.len());
    for (a, b) in poses.iter().zip(&back) {
        assert_eq!(a.stamp.to_bits(), b.stamp.to_bits(), "stamp");
        assert_close_pose(&a.pose, &b.pose, 1e-9, "TUM pose");
    }
    true
}

fn same_structure<P: GraphPose>(a: &PoseGraph<P>, b: &PoseGraph<P>) {
    assert_eq!(a.nodes().len(), b.nodes().len());
    for (n, m) in a.nodes().iter().zip(b.nodes()) {
        assert_eq!((n.id, n.fixed), (m.id, m.fixed));
    }
    assert_eq!(a.edges().len(), b.edges().len());
    for (e, f) in a.edges().iter().zip(b.edges()) {
        assert_eq!((e.from, e.to), (f.from, f.to));
        assert_eq!(e.information, f.information);
    }
}

/// g2o graphs (SE(2) and SE(3)): ids, fixed flags, information exact; poses to rounding.
#[must_use]
pub fn g2o(data: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(data) else {
        return false;
    };
    let Ok(graph) = parse_g2o(text) else {
        return false;
    };
    match &graph {
        G2oGraph::Se3(g) => {
            let Ok(G2oGraph::Se3(back)) = parse_g2o(&g2o_text_se3(g)) else {
                panic!("our own SE(3) g2o does not read back")
            };
            same_structure(g, &back);
            for (n, m) in g.nodes().iter().zip(back.nodes()) {
                assert_close_pose(&n.pose, &m.pose, 1e-9, "g2o vertex");
            }
            for (e, f) in g.edges().iter().zip(back.edges()) {
                assert_close_pose(&e.measurement, &f.measurement, 1e-9, "g2o edge");
            }
        }
        G2oGraph::Se2(g) => {
            let Ok(G2oGraph::Se2(back)) = parse_g2o(&g2o_text_se2(g)) else {
                panic!("our own SE(2) g2o does not read back")
            };
            same_structure(g, &back);
            for (n, m) in g.nodes().iter().zip(back.nodes()) {
                assert_close_pose2(&n.pose, &m.pose, 1e-9, "g2o SE(2) vertex");
            }
            for (e, f) in g.edges().iter().zip(back.edges()) {
                assert_close_pose2(&e.measurement, &f.measurement, 1e-9, "g2o SE(2) edge");
            }
        }
    }
    true
}

/// TORO 2D graphs: ids and information exact (ids as integers), poses to rounding.
#[must_use]
pub fn toro(data: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(data) else {
        return false;
    };
    let Ok(g) = parse_toro(text) else {
        return false;
    };
    let back = parse_toro(&toro_text(&g)).expect("our own TORO reads back");
    same_structure(&g, &back);
    for (n, m) in g.nodes().iter().zip(back.nodes()) {
        assert_close_pose2(&n.pose, &m.pose, 1e-9, "TORO vertex");
    }
    for (e, f) in g.edges().iter().zip(back.edges()) {
        assert_close_pose2(&e.measurement, &f.measurement, 1e-9, "TORO edge");
    }
    true
}

/// Moving AI `.map` grids: the same blocked cells and terrain letters after writing.
#[must_use]
pub fn movingai_map(data: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(data) else {
        return false;
    };
    let Ok(map) = parse_map(text) else {
        return false;
    };
    let back = parse_map(&map_text(&map)).expect("our own map reads back");
    assert_eq!(back.grid, map.grid);
    assert_eq!(back.terrain, map.terrain);
    true
}

/// Moving AI `.scen` scenarios: every field the same after writing (the tolerance follows the
/// version written, so it is not compared).
#[must_use]
pub fn movingai_scen(data: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(data) else {
        return false;
    };
    let Ok(scen) = parse_scenarios(text) else {
        return false;
    };
    let back = parse_scenarios(&scenarios_text(&scen)).expect("our own scenarios read back");
    assert_eq!(back.len(), scen.len());
    for (a, b) in scen.iter().zip(&back) {
        assert_eq!(
            (a.bucket, &a.map, a.map_width, a.map_height, a.start, a.goal),
            (b.bucket, &b.map, b.map_width, b.map_height, b.start, b.goal)
        );
        assert_eq!(a.optimal_length.to_bits(), b.optimal_length.to_bits());
    }
    true
}

/// ROS `map_server` maps: the input is the YAML text, a NUL byte, then the image file's bytes
/// (PGM or PNG). The YAML keys read back from their text; the grid, written as `map_saver`
/// would (PGM and YAML), reads back cell for cell.
#[must_use]
pub fn ros_map(data: &[u8]) -> bool {
    let split = data.iter().position(|&b| b == 0).unwrap_or(data.len());
    let (yaml, image) = (&data[..split], data.get(split + 1..).unwrap_or_default());
    let Ok(yaml) = std::str::from_utf8(yaml) else {
        return false;
    };
    let Ok(keys) = RosMapYaml::parse(yaml) else {
        return false;
    };
    assert_eq!(
        RosMapYaml::parse(&keys.to_text()).expect("our own YAML reads back"),
        keys
    );
    let Ok(grid) = keys.grid_from_image(image) else {
        return false;
    };
    let pgm = ros_map_pgm(&grid, Path::new("map.pgm")).expect("encoding to memory");
    let yaml = ros_map_yaml(&grid, "map.pgm").to_text();
    let back = RosMapYaml::parse(&yaml)
        .expect("our own YAML reads back")
        .grid_from_image(&pgm)
        .expect("our own PGM reads back");
    assert_eq!(back, grid);
    true
}

/// spot-nav recording indexes (`index stamp cloud` lines): the same entries after writing.
#[must_use]
pub fn recording_index(data: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(data) else {
        return false;
    };
    let Ok(entries) = parse_index(text) else {
        return false;
    };
    let written: String = entries.iter().map(|e| e.to_line() + "\n").collect();
    let back = parse_index(&written).expect("our own index reads back");
    assert_eq!(back, entries);
    true
}

/// spot-nav recording calibrations (`body_T_lidar tx ty tz qx qy qz qw`): the same mounting
/// after writing (to rounding of the quaternion).
#[must_use]
pub fn recording_calibration(data: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(data) else {
        return false;
    };
    let Ok(pose) = parse_calibration(text) else {
        return false;
    };
    let back = parse_calibration(&calibration_text(&pose)).expect("our own calibration reads back");
    assert_close_pose(&pose, &back, 1e-9, "body_T_lidar");
    true
}
