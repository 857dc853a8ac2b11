//! `PointCloud2` decoding on random layouts and bytes: it answers (a cloud or an error) and never
//! panics, and a decoded cloud accounts for every point of the message.

use proptest::prelude::*;
use spot_adapter::record::{
    Header, PointCloud2, PointCloud2Config, PointCloud2Decoder, PointField,
};

const NAMES: [&str; 12] = [
    "x",
    "y",
    "z",
    "intensity",
    "ring",
    "t",
    "time",
    "timestamp",
    "sec",
    "nsec",
    "t_sec",
    "t_nsec",
];

fn field() -> impl Strategy<Value = PointField> {
    (0..NAMES.len(), 0u32..40, 0u8..10, 0u32..3).prop_map(|(n, offset, datatype, count)| {
        PointField {
            name: NAMES[n].into(),
            offset,
            datatype,
            count,
        }
    })
}

/// x, y and z as floats at random offsets, then random other fields (so most clouds get past
/// the coordinates and into the point loop).
fn fields() -> impl Strategy<Value = Vec<PointField>> {
    (
        prop::collection::vec((0u32..24, prop_oneof![Just(7u8), Just(8u8)]), 3),
        prop::collection::vec(field(), 0..5),
    )
        .prop_map(|(xyz, extra)| {
            let mut out: Vec<PointField> = xyz
                .into_iter()
                .zip(["x", "y", "z"])
                .map(|((offset, datatype), name)| PointField {
                    name: name.into(),
                    offset,
                    datatype,
                    count: 1,
                })
                .collect();
            out.extend(extra);
            out
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]
    #[test]
    fn random_clouds_are_decoded_or_refused(
        fields in prop_oneof![prop::collection::vec(field(), 0..8), fields()],
        point_step in 0u32..48,
        width in 0u32..20,
        height in 0u32..4,
        row_extra in 0u32..8,
        big_endian in any::<bool>(),
        stamp in prop_oneof![Just(0.0), Just(1.7e9), 0.0f64..100.0],
        seed in any::<u64>(),
        short in 0usize..3,
    ) {
        let row_step = width * point_step + row_extra;
        let len = (row_step * height) as usize;
        let mut state = seed | 1;
        let mut data: Vec<u8> = (0..len)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 24) as u8
            })
            .collect();
        let short = short.min(len);
        data.truncate(len - short);
        let msg = PointCloud2 {
            header: Header { stamp, frame_id: "lidar".into() },
            height,
            width,
            fields,
            is_bigendian: big_endian,
            point_step,
            row_step,
            data: &data,
        };
        let mut decoder = PointCloud2Decoder::new(PointCloud2Config::default());
        if let Ok(decoded) = decoder.decode(&msg) {
            let n = decoded.cloud.len() + decoded.dropped.no_return + decoded.dropped.non_finite;
            prop_assert_eq!(n, (width * height) as usize);
            prop_assert!(short == 0, "a short data array was accepted");
            if let Some(t) = decoded.cloud.time() {
                prop_assert!(t.iter().all(|v| v.abs() <= 0.25 + 1e-6));
            }
        }
    }
}
