//! Messages found by fuzzing (`fuzz/`, targets `point_cloud2`, `ros1_bag`, `mcap_bag`) whose
//! decoding took time or memory out of proportion to their bytes: decoded in a child process
//! capped in CPU time and address space (`ulimit -t`, `ulimit -v`), because a hang or an
//! allocation failure cannot be caught in the process itself.
#![cfg(unix)]
#![allow(clippy::unwrap_used, clippy::panic)]

use spot_adapter::record::{
    Header, PointCloud2, PointCloud2Config, PointCloud2Decoder, PointField,
};

/// Set in the child: run the checks instead of spawning.
const CHILD: &str = "SPOT_ADAPTER_BOUNDED_CHILD";

/// Run the test `name` of this binary again in a child process with at most `cpu_seconds` of CPU
/// and 1 GiB of address space; panic unless it succeeds.
fn in_capped_child(name: &str, cpu_seconds: u32) {
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!(
            r#"ulimit -v 1048576 && ulimit -t {cpu_seconds} && exec "$0" "$@""#
        ))
        .arg(std::env::current_exe().unwrap())
        .args(["--exact", name, "--nocapture", "--test-threads=1"])
        .env(CHILD, "1")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "capped child: {}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
}

fn field(name: &str, offset: u32, datatype: u8) -> PointField {
    PointField {
        name: name.into(),
        offset,
        datatype,
        count: 1,
    }
}

fn decode_rows_without_points() {
    // Width 0, so no point and no byte of data, but 2^32 - 1 rows of zero bytes each: every
    // size agrees, and the decoder used to walk the empty rows one by one (the fuzzer's input
    // took over 10 s; `fuzz/regressions/point_cloud2/empty_rows_timeout`).
    for height in [u32::MAX, u32::MAX - 1, 1 << 31, 3 << 30] {
        let msg = PointCloud2 {
            header: Header {
                stamp: 1.7e9,
                frame_id: "os_sensor".into(),
            },
            height,
            width: 0,
            fields: vec![
                field("x", 0, 7),
                field("y", 4, 7),
                field("z", 8, 7),
                field("t", 12, 6),
            ],
            is_bigendian: false,
            point_step: 16,
            row_step: 0,
            data: &[],
        };
        let decoded = PointCloud2Decoder::new(PointCloud2Config::default())
            .decode(&msg)
            .unwrap();
        assert!(decoded.cloud.is_empty());
    }
}

#[test]
fn clouds_of_empty_rows_decode_without_visiting_them() {
    if std::env::var_os(CHILD).is_some() {
        decode_rows_without_points();
        return;
    }
    in_capped_child("clouds_of_empty_rows_decode_without_visiting_them", 5);
}
