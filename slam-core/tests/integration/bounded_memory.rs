//! Small files whose headers claim huge sizes: each is parsed in a child process capped at 1 GiB
//! of address space and 20 s of CPU (`ulimit -v`, `ulimit -t`), because an allocation failure
//! aborts the process and cannot be caught, and a hang never returns. Before the fixes these
//! reserved 1.6 TB (PCD `COUNT`), 4 GiB (compressed PCD) or looped for ever (PLY).
#![cfg(unix)]
#![allow(clippy::unwrap_used, clippy::panic)]

use slam_core::io::{parse_pcd, parse_ply};

/// Set in the child: run the test's body instead of spawning.
const CHILD: &str = "SLAM_CORE_BOUNDED_CHILD";

/// Run `body` in a memory- and CPU-capped child (this test binary, filtered to `test`); the
/// parent fails when the child does (error, abort or CPU limit).
fn capped(test: &str, body: impl FnOnce()) {
    if std::env::var_os(CHILD).is_some() {
        body();
        return;
    }
    let exe = std::env::current_exe().unwrap();
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg(r#"ulimit -v 1048576 && ulimit -t 20 && exec "$0" "$@""#)
        .arg(exe)
        .args(["--exact", &format!("bounded_memory::{test}")])
        .args(["--nocapture", "--test-threads=1"])
        .env(CHILD, "1")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{test} in a capped child: {}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    // The filter must have found the test: a child that ran nothing would pass vacuously.
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("1 passed"),
        "the capped child ran no test: {}",
        String::from_utf8_lossy(&out.stdout)
    );
}

#[test]
fn pcd_ascii_count_of_1e11_is_an_error() {
    capped("pcd_ascii_count_of_1e11_is_an_error", || {
        let file = b"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 99999999999\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n";
        let err = parse_pcd(file).unwrap_err().to_string();
        assert!(err.contains("3 values, 100000000001 expected"), "{err}");
    });
}

#[test]
fn pcd_compressed_stating_4_gib_is_an_error() {
    capped("pcd_compressed_stating_4_gib_is_an_error", || {
        // 357,913,941 points of 12 bytes: 4,294,967,292 bytes stated, 4 bytes of LZF given.
        let mut file = b"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 357913941\nHEIGHT 1\nPOINTS 357913941\nDATA binary_compressed\n".to_vec();
        file.extend_from_slice(&4u32.to_le_bytes());
        file.extend_from_slice(&4_294_967_292u32.to_le_bytes());
        file.extend_from_slice(&[0xE0, 0xFF, 0x00, 0x00]);
        let err = parse_pcd(&file).unwrap_err().to_string();
        assert!(err.contains("cannot decompress"), "{err}");
    });
}

#[test]
fn ply_element_of_2_pow_64_records_without_properties_ends() {
    capped(
        "ply_element_of_2_pow_64_records_without_properties_ends",
        || {
            let mut file = b"ply\nformat binary_little_endian 1.0\nelement nothing 18446744073709551615\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n".to_vec();
            for v in [1.0f32, 2.0, 3.0] {
                file.extend_from_slice(&v.to_le_bytes());
            }
            // Records without properties hold no bytes: the vertex follows at once.
            let cloud = parse_ply(&file).unwrap();
            assert_eq!(cloud.points(), &[nalgebra::Point3::new(1.0, 2.0, 3.0)]);
        },
    );
}

#[test]
fn ply_binary_counts_past_the_data_are_an_error() {
    capped("ply_binary_counts_past_the_data_are_an_error", || {
        let file = b"ply\nformat binary_little_endian 1.0\nelement face 1000000000000\nproperty list uchar int vertex_indices\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n\x00\x00";
        let err = parse_ply(file).unwrap_err().to_string();
        assert!(err.contains("do not fit"), "{err}");
    });
}
