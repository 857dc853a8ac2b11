//! File formats on the real files in `tests/data` (see its README) and on malformed input.
#![allow(clippy::unwrap_used)]

use std::path::PathBuf;

use nalgebra::Point3;
use proptest::prelude::*;
use slam_core::io::{
    PcdEncoding, PlyEncoding, StampedPose, parse_kitti_bin, parse_kitti_poses, parse_pcd,
    parse_ply, parse_tum, read_kitti_poses, read_pcd, read_ply, write_kitti_bin_to,
    write_kitti_poses_to, write_pcd_to, write_ply_to, write_tum_to,
};
use slam_core::{FormatError, PointCloud, pose3_from_xyz_rpy};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn pcd_round_trips(cloud: &PointCloud) {
    for enc in [PcdEncoding::Binary, PcdEncoding::Ascii] {
        let mut bytes = Vec::new();
        write_pcd_to(&mut bytes, cloud, enc).unwrap();
        let back = parse_pcd(&bytes).unwrap();
        assert_same(cloud, &back);
    }
}

fn ply_round_trips(cloud: &PointCloud) {
    for enc in [PlyEncoding::BinaryLittleEndian, PlyEncoding::Ascii] {
        let mut bytes = Vec::new();
        write_ply_to(&mut bytes, cloud, enc).unwrap();
        let back = parse_ply(&bytes).unwrap();
        assert_same(cloud, &back);
    }
}

/// Bit-for-bit equality (NaN-safe).
fn assert_same(a: &PointCloud, b: &PointCloud) {
    assert_eq!(a.len(), b.len());
    // NaN payloads do not survive text; every other value must come back bit for bit.
    let canon = |v: f32| {
        if v.is_nan() {
            f32::NAN.to_bits()
        } else {
            v.to_bits()
        }
    };
    let bits = |c: &PointCloud| {
        c.points()
            .iter()
            .flat_map(|p| [canon(p.x), canon(p.y), canon(p.z)])
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(a), bits(b));
    assert_eq!(a.ring(), b.ring());
    let fb = |v: Option<&[f32]>| v.map(|v| v.iter().map(|&x| canon(x)).collect::<Vec<_>>());
    assert_eq!(fb(a.intensity()), fb(b.intensity()));
    assert_eq!(fb(a.time()), fb(b.time()));
}

#[test]
fn garage_pcd_with_padding_fields() {
    if slam_core::skip_without_test_data!("tests/data") {
        return;
    }
    let cloud = read_pcd(data("hdl32e_garage_1503604882.703390000.pcd")).unwrap();
    assert_eq!(cloud.len(), 42_006);
    let ring = cloud.ring().unwrap();
    assert_eq!(*ring.iter().max().unwrap(), 31);
    assert_eq!(*ring.iter().min().unwrap(), 0);
    // Every one of the 32 lasers contributes points.
    let mut seen = [false; 32];
    for &r in ring {
        seen[usize::from(r)] = true;
    }
    assert!(seen.iter().all(|&s| s));
    assert!(cloud.intensity().is_some() && cloud.time().is_none());
    // A tight garage: the README reports a 99th-percentile range of about 4.7 m.
    let mut r: Vec<f32> = cloud
        .points()
        .iter()
        .filter(|p| p.x.is_finite())
        .map(|p| p.coords.norm())
        .collect();
    r.sort_by(f32::total_cmp);
    let p99 = r[(r.len() as f64 * 0.99) as usize];
    assert!((3.5..6.0).contains(&p99), "p99 range {p99}");
    pcd_round_trips(&cloud);
}

#[test]
fn ouster_pcd_with_time_and_ring() {
    if slam_core::skip_without_test_data!("tests/data") {
        return;
    }
    let cloud = read_pcd(data("os1_128_frame_00_fid1795.pcd")).unwrap();
    assert_eq!(cloud.len(), 107_647);
    let t = cloud.time().unwrap();
    assert!(t.iter().all(|&t| (0.0..0.1).contains(&t)));
    assert!(t.iter().copied().fold(0.0f32, f32::max) > 0.09);
    let ring = cloud.ring().unwrap();
    assert!(ring.iter().all(|&r| r < 128));
    assert!(ring.contains(&0) && ring.contains(&127));
    pcd_round_trips(&cloud);
    ply_round_trips(&cloud);
}

#[test]
fn small_gicp_ply() {
    if slam_core::skip_without_test_data!("tests/data") {
        return;
    }
    let cloud = read_ply(data("hdl32e_pair_target.ply")).unwrap();
    assert_eq!(cloud.len(), 69_088);
    assert!(cloud.intensity().is_some());
    assert!(
        cloud
            .points()
            .iter()
            .all(|p| p.iter().all(|v| v.is_finite()))
    );
    ply_round_trips(&cloud);
    pcd_round_trips(&cloud);
}

#[test]
fn ouster_kitti_poses() {
    if slam_core::skip_without_test_data!("tests/data") {
        return;
    }
    let poses = read_kitti_poses(data("os1_128_poses_kitti.txt")).unwrap();
    assert_eq!(poses.len(), 3);
    assert!(poses[0].translation.vector.norm() < 1e-15 && poses[0].rotation.angle() < 1e-15);
    let step1 = (poses[0].inverse() * poses[1]).translation.vector.norm();
    let step2 = (poses[1].inverse() * poses[2]).translation.vector.norm();
    assert!((step1 - 0.245).abs() < 1e-3, "{step1}");
    assert!((step2 - 0.253).abs() < 1e-3, "{step2}");
    let mut text = Vec::new();
    write_kitti_poses_to(&mut text, &poses).unwrap();
    let back = parse_kitti_poses(std::str::from_utf8(&text).unwrap()).unwrap();
    for (a, b) in poses.iter().zip(&back) {
        assert!((a.to_homogeneous() - b.to_homogeneous()).amax() < 1e-15);
    }
}

#[test]
fn kitti_bin_round_trip_and_errors() {
    let cloud = PointCloud::from_points(vec![
        Point3::new(1.5, -2.25, 0.125),
        Point3::new(f32::MAX, 0.0, -0.0),
    ])
    .with_intensity(vec![0.5, 1.0])
    .unwrap();
    let mut bytes = Vec::new();
    write_kitti_bin_to(&mut bytes, &cloud).unwrap();
    assert_eq!(bytes.len(), 32);
    assert_same(&parse_kitti_bin(&bytes).unwrap(), &cloud);
    assert!(matches!(
        parse_kitti_bin(&bytes[..30]),
        Err(FormatError::Byte { offset: 16, .. })
    ));
}

#[test]
fn tum_round_trip_and_errors() {
    let poses: Vec<StampedPose> = (0..5)
        .map(|i| StampedPose {
            stamp: 1_503_604_882.703_39 + f64::from(i) * 0.1,
            pose: pose3_from_xyz_rpy(f64::from(i), -0.5, 0.1, 0.01, -0.2, 3.1),
        })
        .collect();
    let mut text = Vec::new();
    write_tum_to(&mut text, &poses).unwrap();
    let back = parse_tum(std::str::from_utf8(&text).unwrap()).unwrap();
    assert_eq!(back.len(), 5);
    for (a, b) in poses.iter().zip(&back) {
        assert_eq!(a.stamp.to_bits(), b.stamp.to_bits());
        assert!((a.pose.to_homogeneous() - b.pose.to_homogeneous()).amax() < 1e-15);
    }
    let bad = "# header\n1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 0\n";
    assert!(matches!(
        parse_tum(bad),
        Err(FormatError::Line { line: 3, .. })
    ));
    assert!(matches!(
        parse_tum("1.0 0 0 0 0 0 0 0\n"),
        Err(FormatError::Line { line: 1, .. })
    ));
    assert!(matches!(
        parse_tum("1.0 0 0 x 0 0 0 1\n"),
        Err(FormatError::Line { line: 1, .. })
    ));
}

#[test]
fn kitti_pose_errors() {
    assert!(matches!(
        parse_kitti_poses("1 0 0 0 0 1 0 0 0 0 1\n"),
        Err(FormatError::Line { line: 1, .. })
    ));
    // A reflection is not a rotation.
    let refl = "1 0 0 0\n0 1 0 0 0 0 -1 0\n";
    assert!(parse_kitti_poses(refl).is_err());
    assert!(matches!(
        parse_kitti_poses("1 0 0 0 0 1 0 0 0 0 -1 0\n"),
        Err(FormatError::Line { line: 1, .. })
    ));
    assert!(matches!(
        parse_kitti_poses("2 0 0 0 0 1 0 0 0 0 1 0\n"),
        Err(FormatError::Line { line: 1, .. })
    ));
}

#[test]
fn ascii_pcd_with_fields_in_any_order() {
    let text = "VERSION 0.7\nFIELDS ring z _ x y intensity\nSIZE 2 4 1 8 4 4\nTYPE U F U F F F\nCOUNT 1 1 3 1 1 1\n\
WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n3 1.5 9 9 9 0.25 -2 7\n4 2.5 0 0 0 -1 3 8\n";
    let c = parse_pcd(text.as_bytes()).unwrap();
    assert_eq!(
        c.points(),
        &[Point3::new(0.25, -2.0, 1.5), Point3::new(-1.0, 3.0, 2.5)]
    );
    assert_eq!(c.ring(), Some(&[3u16, 4][..]));
    assert_eq!(c.intensity(), Some(&[7.0f32, 8.0][..]));
}

#[test]
fn pcd_errors_name_the_place() {
    let head = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n";
    let short = format!("{head}1 2 3\n");
    assert!(matches!(
        parse_pcd(short.as_bytes()),
        Err(FormatError::Line { .. })
    ));
    let bad = format!("{head}1 2 3\n1 x 3\n");
    assert!(matches!(
        parse_pcd(bad.as_bytes()),
        Err(FormatError::Line { line: 9, .. })
    ));
    let wrong_count = format!("{head}1 2 3\n1 2\n");
    assert!(matches!(
        parse_pcd(wrong_count.as_bytes()),
        Err(FormatError::Line { line: 9, .. })
    ));
    let mismatch =
        "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 3\nHEIGHT 1\nPOINTS 2\nDATA ascii\n";
    assert!(matches!(
        parse_pcd(mismatch.as_bytes()),
        Err(FormatError::Line { line: 7, .. })
    ));
    let no_z = "FIELDS x y\nSIZE 4 4\nTYPE F F\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2\n";
    assert!(matches!(
        parse_pcd(no_z.as_bytes()),
        Err(FormatError::MissingField { field: "z" })
    ));
    let float_ring =
        "FIELDS x y z ring\nSIZE 4 4 4 4\nTYPE F F F F\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3 4\n";
    assert!(matches!(
        parse_pcd(float_ring.as_bytes()),
        Err(FormatError::NonIntegerRing { field }) if field == "ring"
    ));
    // A binary header that claims far more points than the data holds.
    let mut huge =
        b"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 4000000000\nHEIGHT 1\nDATA binary\n".to_vec();
    huge.extend_from_slice(&[0u8; 24]);
    assert!(matches!(parse_pcd(&huge), Err(FormatError::Byte { .. })));
    assert!(matches!(
        parse_pcd(b"FIELDS x y z\n"),
        Err(FormatError::Line { .. })
    ));
    assert!(matches!(
        parse_pcd(b"FOO 1\n"),
        Err(FormatError::Line { line: 1, .. })
    ));
}

/// The same points with mixed field types (one of three values, some no channel reads) read
/// alike from `ascii`, `binary` and `binary_compressed` data (the compressed blocks as LZF literal
/// runs).
#[test]
fn pcd_binary_and_compressed_points_read_as_their_ascii() {
    use std::fmt::Write as _;
    let n = 200usize;
    // x F8, extra I4, normal F4 x3, y F4, z F4, ring U2, intensity F4, t F8
    let head = |data: &str| {
        format!(
            "FIELDS x extra normal y z ring intensity t\nSIZE 8 4 4 4 4 2 4 8\n\
TYPE F I F F F U F F\nCOUNT 1 1 3 1 1 1 1 1\nWIDTH {n}\nHEIGHT 1\nPOINTS {n}\nDATA {data}\n"
        )
    };
    let row = |i: usize| {
        let f = i as f64;
        (
            (f * 0.31).sin() * 30.0,
            i as i32 * 5 - 400,
            [0.5f32, -0.25, f as f32],
            (f * 0.07).cos() as f32 * 9.0,
            -2.0 + (i % 11) as f32 * 0.25,
            (i % 64) as u16,
            (i % 200) as f32,
            f * 1e-4,
        )
    };
    let mut text = head("ascii");
    for i in 0..n {
        let r = row(i);
        writeln!(
            text,
            "{} {} {} {} {} {} {} {} {} {}",
            r.0, r.1, r.2[0], r.2[1], r.2[2], r.3, r.4, r.5, r.6, r.7
        )
        .unwrap();
    }
    let from_text = parse_pcd(text.as_bytes()).unwrap();
    // One record a point ...
    let mut binary = head("binary").into_bytes();
    // ... or one block a field.
    let mut blocks: Vec<Vec<u8>> = vec![Vec::new(); 8];
    for i in 0..n {
        let r = row(i);
        let fields: [Vec<u8>; 8] = [
            r.0.to_le_bytes().to_vec(),
            r.1.to_le_bytes().to_vec(),
            r.2.iter().flat_map(|v| v.to_le_bytes()).collect(),
            r.3.to_le_bytes().to_vec(),
            r.4.to_le_bytes().to_vec(),
            r.5.to_le_bytes().to_vec(),
            r.6.to_le_bytes().to_vec(),
            r.7.to_le_bytes().to_vec(),
        ];
        for (block, f) in blocks.iter_mut().zip(&fields) {
            binary.extend_from_slice(f);
            block.extend_from_slice(f);
        }
    }
    let raw: Vec<u8> = blocks.concat();
    let mut lzf = Vec::new();
    for run in raw.chunks(32) {
        lzf.push((run.len() - 1) as u8);
        lzf.extend_from_slice(run);
    }
    let mut compressed = head("binary_compressed").into_bytes();
    compressed.extend_from_slice(&(lzf.len() as u32).to_le_bytes());
    compressed.extend_from_slice(&(raw.len() as u32).to_le_bytes());
    compressed.extend_from_slice(&lzf);
    assert_same(&from_text, &parse_pcd(&binary).unwrap());
    assert_same(&from_text, &parse_pcd(&compressed).unwrap());
    assert_eq!(from_text.len(), n);
    assert_eq!(from_text.ring().unwrap()[65], 1);
    assert!((from_text.points()[3].z - (-1.25)).abs() < 1e-6);
}

#[test]
fn binary_compressed_pcd() {
    let head = b"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA binary_compressed\n";
    // Column layout: x0 x1 x2 y0 y1 y2 z0 z1 z2, as two LZF literal runs (32 + 4 bytes).
    let values = [1.0f32, 2.0, 3.0, -1.0, -2.0, -3.0, 0.5, 0.25, 0.125];
    let raw: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    let mut lzf = vec![31u8];
    lzf.extend_from_slice(&raw[..32]);
    lzf.push(3);
    lzf.extend_from_slice(&raw[32..]);
    let mut bytes = head.to_vec();
    bytes.extend_from_slice(&(lzf.len() as u32).to_le_bytes());
    bytes.extend_from_slice(&36u32.to_le_bytes());
    bytes.extend_from_slice(&lzf);
    let c = parse_pcd(&bytes).unwrap();
    assert_eq!(
        c.points(),
        &[
            Point3::new(1.0, -1.0, 0.5),
            Point3::new(2.0, -2.0, 0.25),
            Point3::new(3.0, -3.0, 0.125)
        ]
    );
    // A back reference: one literal zero, then 35 bytes copied from one byte back.
    let zeros = [0x00u8, 0x00, 0xE0, 26, 0x00];
    let mut bytes = head.to_vec();
    bytes.extend_from_slice(&5u32.to_le_bytes());
    bytes.extend_from_slice(&36u32.to_le_bytes());
    bytes.extend_from_slice(&zeros);
    let c = parse_pcd(&bytes).unwrap();
    assert!(c.points().iter().all(|p| *p == Point3::origin()));
    // A back reference before the start of the output is an error, not a panic.
    let mut bad = head.to_vec();
    bad.extend_from_slice(&2u32.to_le_bytes());
    bad.extend_from_slice(&36u32.to_le_bytes());
    bad.extend_from_slice(&[0xE0, 0x05]);
    assert!(matches!(parse_pcd(&bad), Err(FormatError::Byte { .. })));
}

/// The same vertices with mixed property types (some no channel reads) read alike from text,
/// from little- and big-endian records of one fixed size, and from records that also carry a
/// list (read one by one).
#[test]
fn ply_binary_records_read_as_their_text() {
    use std::fmt::Write as _;
    // (x f64, extra i32, y f32, z f32, ring u8, intensity f32, time f64)
    let rows: Vec<(f64, i32, f32, f32, u8, f32, f64)> = (0..300)
        .map(|i| {
            let f = f64::from(i);
            (
                (f * 0.37).sin() * 40.0,
                i * 7 - 900,
                (f * 0.11).cos() as f32 * 12.5,
                -1.25 + (i % 13) as f32 * 0.5,
                (i % 128) as u8,
                (i % 255) as f32,
                f * 1e-4,
            )
        })
        .collect();
    let props = "property double x\nproperty int extra\nproperty float y\nproperty float z\n\
property uchar ring\nproperty float intensity\nproperty double time\n";
    let header = |format: &str, list: bool| {
        format!(
            "ply\nformat {format} 1.0\nelement vertex {}\n{props}{}end_header\n",
            rows.len(),
            if list {
                "property list uchar int idx\n"
            } else {
                ""
            }
        )
    };
    let mut text = header("ascii", false);
    for r in &rows {
        writeln!(
            text,
            "{} {} {} {} {} {} {}",
            r.0, r.1, r.2, r.3, r.4, r.5, r.6
        )
        .unwrap();
    }
    let from_text = parse_ply(text.as_bytes()).unwrap();
    for (format, list) in [
        ("binary_little_endian", false),
        ("binary_big_endian", false),
        ("binary_little_endian", true),
    ] {
        let little = format == "binary_little_endian";
        let mut b = header(format, list).into_bytes();
        macro_rules! put {
            ($v:expr) => {
                if little {
                    b.extend_from_slice(&$v.to_le_bytes())
                } else {
                    b.extend_from_slice(&$v.to_be_bytes())
                }
            };
        }
        for r in &rows {
            put!(r.0);
            put!(r.1);
            put!(r.2);
            put!(r.3);
            put!(r.4);
            put!(r.5);
            put!(r.6);
            if list {
                put!(2u8);
                put!(5i32);
                put!(-6i32);
            }
        }
        let from_binary = parse_ply(&b).unwrap();
        assert_same(&from_text, &from_binary);
        // One byte short is an error with a byte offset, not a shorter cloud.
        assert!(matches!(
            parse_ply(&b[..b.len() - 1]),
            Err(FormatError::Byte { .. })
        ));
    }
    assert_eq!(from_text.len(), rows.len());
    assert_eq!(from_text.ring().unwrap()[129], 1);
    // A ring that is no whole number in 0..=65535 is refused at the end of its record.
    let head = "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\n\
property float y\nproperty float z\nproperty int ring\nend_header\n";
    let mut b = head.as_bytes().to_vec();
    for ring in [0i32, 5, -1, 7] {
        for v in [1.0f32, 2.0, 3.0] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b.extend_from_slice(&ring.to_le_bytes());
    }
    let at = head.len() + 3 * 16;
    assert!(matches!(
        parse_ply(&b),
        Err(FormatError::Byte { offset, .. }) if offset == at
    ));
}

#[test]
fn ply_skips_other_elements_and_lists() {
    let text = "ply\nformat ascii 1.0\nelement camera 1\nproperty float fov\nelement vertex 2\n\
property double x\nproperty float nx\nproperty double y\nproperty double z\nproperty list uchar int idx\n\
element face 1\nproperty list uchar int vertex_indices\nend_header\n60\n1 9 2 3 2 5 6\n4 9 5 6 0\n3 0 1 0\n";
    let c = parse_ply(text.as_bytes()).unwrap();
    assert_eq!(
        c.points(),
        &[Point3::new(1.0, 2.0, 3.0), Point3::new(4.0, 5.0, 6.0)]
    );
    // Binary big endian with a list before the vertex element.
    let mut b = b"ply\nformat binary_big_endian 1.0\nelement tag 1\nproperty list uchar short v\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n".to_vec();
    b.extend_from_slice(&[2, 0, 1, 0, 2]);
    for v in [1.0f32, -2.0, 0.5] {
        b.extend_from_slice(&v.to_be_bytes());
    }
    let c = parse_ply(&b).unwrap();
    assert_eq!(c.points(), &[Point3::new(1.0, -2.0, 0.5)]);
    // Truncated binary data and a lying list length are errors with a byte offset.
    assert!(matches!(
        parse_ply(&b[..b.len() - 1]),
        Err(FormatError::Byte { .. })
    ));
    let mut lying = b.clone();
    let at = lying.len() - 17;
    lying[at] = 255;
    assert!(parse_ply(&lying).is_err());
    assert!(matches!(
        parse_ply(b"plx\n"),
        Err(FormatError::Line { line: 1, .. })
    ));
    assert!(matches!(
        parse_ply(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n"),
        Err(FormatError::MissingField { field: "y" })
    ));
}

proptest! {
    /// Arbitrary bytes after a valid header never panic, and any cloud round-trips exactly.
    #[test]
    fn garbage_never_panics(tail in proptest::collection::vec(any::<u8>(), 0..300)) {
        for head in [
            &b"FIELDS x y z ring\nSIZE 4 4 4 2\nTYPE F F F U\nWIDTH 3\nHEIGHT 1\nDATA binary\n"[..],
            &b"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 3\nPOINTS 3\nDATA binary_compressed\n"[..],
            &b"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 3\nPOINTS 3\nDATA ascii\n"[..],
        ] {
            let mut bytes = head.to_vec();
            bytes.extend_from_slice(&tail);
            let _ = parse_pcd(&bytes);
        }
        let mut ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nproperty list uint uchar l\nend_header\n".to_vec();
        ply.extend_from_slice(&tail);
        let _ = parse_ply(&ply);
        let _ = parse_ply(&tail);
        let _ = parse_pcd(&tail);
        let _ = parse_kitti_bin(&tail);
    }

    #[test]
    fn random_clouds_round_trip(pts in proptest::collection::vec((any::<f32>(), any::<f32>(), any::<f32>(), any::<u16>(), any::<f32>()), 0..50)) {
        let cloud = PointCloud::from_points(pts.iter().map(|p| Point3::new(p.0, p.1, p.2)).collect())
            .with_ring(pts.iter().map(|p| p.3).collect()).unwrap()
            .with_time(pts.iter().map(|p| p.4).collect()).unwrap();
        pcd_round_trips(&cloud);
        ply_round_trips(&cloud);
    }
}
