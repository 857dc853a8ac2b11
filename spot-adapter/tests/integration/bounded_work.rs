//! Messages and bags found by fuzzing (`fuzz/`, targets `point_cloud2` and `mcap_bag`) whose
//! decoding took time or memory out of proportion to their bytes: decoded in a child process
//! capped in CPU time and address space (`ulimit -t`, `ulimit -v`), because a hang or an
//! allocation failure cannot be caught in the process itself.
#![cfg(unix)]
#![allow(clippy::unwrap_used, clippy::panic)]

use spot_adapter::record::RecordError;
use spot_adapter::record::{
    Bag, BagConfig, Header, PointCloud2, PointCloud2Config, PointCloud2Decoder, PointField,
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
        .args(["--exact", &format!("bounded_work::{name}")])
        .args(["--nocapture", "--test-threads=1"])
        .env(CHILD, "1")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "capped child: {}\n{}",
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

/// An MCAP record: opcode, u64 length, body.
fn mcap_record(opcode: u8, body: &[u8]) -> Vec<u8> {
    let mut out = vec![opcode];
    out.extend_from_slice(&(body.len() as u64).to_le_bytes());
    out.extend_from_slice(body);
    out
}

fn open_mcap(name: &str, records: &[Vec<u8>]) -> Result<Bag, RecordError> {
    let dir = std::env::temp_dir().join(format!("spot-adapter-bounded-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    let mut bytes = b"\x89MCAP0\r\n".to_vec();
    for r in records {
        bytes.extend_from_slice(r);
    }
    std::fs::write(&path, bytes).unwrap();
    let bag = Bag::open(&path, &BagConfig::default());
    std::fs::remove_dir_all(&dir).unwrap();
    bag
}

fn open_mcap_with_long_strings() {
    let header = mcap_record(1, &[0, 0, 0, 0, 0, 0, 0, 0]);
    // A channel whose topic claims 4 GiB (the `mcap` crate reserved that much before reading
    // it; the fuzzer's input is `fuzz/regressions/mcap_bag/channel_topic_claims_4_gib`).
    let mut channel = vec![1, 0, 0, 0];
    channel.extend_from_slice(&u32::MAX.to_le_bytes());
    channel.extend_from_slice(b"/points");
    match open_mcap("channel.mcap", &[header.clone(), mcap_record(4, &channel)]) {
        Err(RecordError::McapLength {
            what,
            claimed,
            left: 7,
            ..
        }) => {
            assert_eq!(what, "channel record: a string");
            assert_eq!(claimed, u64::from(u32::MAX));
        }
        other => panic!("{other:?}"),
    }
    // A schema's name, likewise.
    let mut schema = vec![1, 0];
    schema.extend_from_slice(&u32::MAX.to_le_bytes());
    let err = open_mcap("schema.mcap", &[header, mcap_record(3, &schema)]).unwrap_err();
    assert!(
        matches!(
            err,
            RecordError::McapLength {
                what: "schema record: a string",
                ..
            }
        ),
        "{err}"
    );
    // A header (not needed for messages, so not parsed) and a metadata record, likewise: the
    // file is then refused for its missing end, not aborted.
    let mut long = vec![0xff, 0xff, 0xff, 0xff];
    long.extend_from_slice(b"ros2");
    let err = open_mcap(
        "header.mcap",
        &[mcap_record(1, &long), mcap_record(12, &long)],
    )
    .unwrap_err();
    assert!(matches!(err, RecordError::Mcap { .. }), "{err}");
}

#[test]
fn mcap_strings_longer_than_their_record_are_refused_before_allocating() {
    if std::env::var_os(CHILD).is_some() {
        open_mcap_with_long_strings();
        return;
    }
    in_capped_child(
        "mcap_strings_longer_than_their_record_are_refused_before_allocating",
        20,
    );
}

#[test]
fn records_past_their_uncompressed_mcap_chunk_are_refused() {
    // An uncompressed chunk of 20 bytes whose message record claims 100: the `mcap` crate read
    // on past the chunk and subtracted with overflow (a panic in debug builds; the fuzzer's
    // input is `fuzz/regressions/mcap_bag/chunk_record_past_its_chunk`).
    let mut message = vec![5];
    message.extend_from_slice(&100u64.to_le_bytes());
    message.extend_from_slice(&[0; 11]);
    let mut chunk = vec![0u8; 32]; // times, sizes, CRC, no compression
    chunk.extend_from_slice(&(message.len() as u64).to_le_bytes());
    chunk.extend_from_slice(&message);
    let filler = mcap_record(12, &[0; 120]);
    let header = mcap_record(1, &[0, 0, 0, 0, 0, 0, 0, 0]);
    match open_mcap("chunk.mcap", &[header, mcap_record(6, &chunk), filler]) {
        Err(RecordError::McapLength {
            what,
            claimed: 100,
            left: 11,
            ..
        }) => assert_eq!(what, "uncompressed chunk: a record"),
        other => panic!("{other:?}"),
    }
}

fn open_mcap_claiming_a_gigabyte() {
    // A 30-byte file whose first record claims just under 1 GiB: its buffer used to be made
    // at the length claimed (the fuzzer's MCAP inputs ran at 45 per second, 1.2 GB resident).
    let mut record = vec![1];
    record.extend_from_slice(&((1u64 << 30) - 16).to_le_bytes());
    record.extend_from_slice(&[0; 12]);
    let err = open_mcap("claim.mcap", &[record]).unwrap_err();
    assert!(matches!(err, RecordError::Mcap { .. }), "{err}");
}

#[test]
fn mcap_buffers_grow_with_the_data_not_with_the_lengths_claimed() {
    if std::env::var_os(CHILD).is_some() {
        open_mcap_claiming_a_gigabyte();
        return;
    }
    in_capped_child(
        "mcap_buffers_grow_with_the_data_not_with_the_lengths_claimed",
        20,
    );
}
