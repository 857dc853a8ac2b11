//! Clouds for the tests: hand-built fields and messages, and a small generator for random
//! layouts.

use crate::record::ros_messages::{Header, PointCloud2, PointField};

/// A field of one value.
pub(crate) fn field(name: &str, offset: u32, datatype: u8) -> PointField {
    PointField {
        name: name.into(),
        offset,
        datatype,
        count: 1,
    }
}

/// `n` points of x y z f32 and a time (f32 seconds) at offset 12, 16 bytes each.
pub(crate) fn cloud(data: &[u8], stamp: f64) -> PointCloud2<'_> {
    PointCloud2 {
        header: Header {
            stamp,
            frame_id: "lidar".into(),
        },
        height: 1,
        width: (data.len() / 16) as u32,
        fields: vec![
            field("x", 0, 7),
            field("y", 4, 7),
            field("z", 8, 7),
            field("time", 12, 7),
        ],
        is_bigendian: false,
        point_step: 16,
        row_step: data.len() as u32,
        data,
    }
}

/// The data of points (1 + i, 2, 3) with these times, laid out as [`cloud`] reads them.
pub(crate) fn points(times: &[f32]) -> Vec<u8> {
    let mut data = Vec::new();
    for (i, t) in times.iter().enumerate() {
        for v in [1.0 + i as f32, 2.0, 3.0, *t] {
            data.extend_from_slice(&v.to_le_bytes());
        }
    }
    data
}

/// A small xorshift generator.
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    pub(crate) fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    pub(crate) fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}
