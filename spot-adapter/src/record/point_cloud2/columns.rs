//! A cloud's data read a channel at a time: each column in a pass of its own, its type decided
//! once per pass rather than once per point.

use nalgebra::Point3;
use slam_core::io::Scalar;

use crate::record::point_cloud2::layout::FieldSlot;

/// The points of a cloud's data, row by row (the shape checked by the decoder's
/// `checked_row_bytes`).
pub(super) struct Rows<'a> {
    pub(super) data: &'a [u8],
    /// Rows to walk.
    pub(super) height: usize,
    pub(super) row_step: usize,
    /// Bytes of points in a row (the rest of `row_step` is padding).
    pub(super) row_bytes: usize,
    pub(super) step: usize,
    pub(super) big_endian: bool,
    /// Points in all.
    pub(super) len: usize,
}

impl Rows<'_> {
    /// `out` (one entry per point) filled with `f` of each point's bytes. Row by row, the
    /// points and their entries zipped, so the loop has no bounds or capacity checks.
    #[inline]
    fn fill<T>(&self, out: &mut [T], mut f: impl FnMut(&[u8]) -> T) {
        let width = self.row_bytes / self.step;
        for (row, dst) in out
            .chunks_exact_mut(width.max(1))
            .take(self.height)
            .enumerate()
        {
            let start = row * self.row_step;
            let points = self.data[start..start + self.row_bytes].chunks_exact(self.step);
            for (p, d) in points.zip(dst) {
                *d = f(p);
            }
        }
    }

    /// The values of field `slot` (inside every point: checked by the layout) over all points,
    /// each passed through `to`.
    // Every integer type up to 64 bits is read as f64, as `Scalar::read` does.
    #[allow(clippy::cast_lossless)]
    pub(super) fn column<T: Copy + Default>(
        &self,
        slot: &FieldSlot,
        to: impl Fn(f64) -> T,
    ) -> Vec<T> {
        let mut out = vec![T::default(); self.len];
        let (o, be) = (slot.offset, self.big_endian);
        macro_rules! typed {
            ($t:ty) => {{
                const N: usize = std::mem::size_of::<$t>();
                self.fill(&mut out, |p| {
                    let mut a = [0u8; N];
                    a.copy_from_slice(&p[o..o + N]);
                    let v = if be {
                        <$t>::from_be_bytes(a)
                    } else {
                        <$t>::from_le_bytes(a)
                    };
                    to(v as f64)
                });
            }};
        }
        match slot.scalar {
            Scalar::I8 => typed!(i8),
            Scalar::U8 => typed!(u8),
            Scalar::I16 => typed!(i16),
            Scalar::U16 => typed!(u16),
            Scalar::I32 => typed!(i32),
            Scalar::U32 => typed!(u32),
            Scalar::I64 => typed!(i64),
            Scalar::U64 => typed!(u64),
            Scalar::F32 => typed!(f32),
            Scalar::F64 => typed!(f64),
        }
        out
    }

    /// The points' coordinates, the common layout (little-endian float32) in one pass.
    pub(super) fn coordinates(&self, xyz: &[FieldSlot; 3]) -> Vec<Point3<f32>> {
        let [x, y, z] = xyz;
        if self.big_endian || xyz.iter().any(|f| f.scalar != Scalar::F32) {
            let to = |v: f64| v as f32;
            let (xs, ys, zs) = (self.column(x, to), self.column(y, to), self.column(z, to));
            return xs
                .into_iter()
                .zip(ys)
                .zip(zs)
                .map(|((x, y), z)| Point3::new(x, y, z))
                .collect();
        }
        let f32_at = |p: &[u8], o: usize| {
            let mut a = [0u8; 4];
            a.copy_from_slice(&p[o..o + 4]);
            f32::from_le_bytes(a)
        };
        let mut out = vec![Point3::origin(); self.len];
        let (ox, oy, oz) = (x.offset, y.offset, z.offset);
        self.fill(&mut out, |p| {
            Point3::new(f32_at(p, ox), f32_at(p, oy), f32_at(p, oz))
        });
        out
    }
}

#[cfg(test)]
mod tests {
    use crate::record::no_return::{DroppedPoints, PointKind, ReturnFilter};
    use crate::record::point_cloud2::layout::scalar_of_code;
    use crate::record::point_cloud2::test_clouds::{Rng, field};
    use crate::record::point_cloud2::{PointCloud2Config, PointCloud2Decoder};
    use crate::record::ros_messages::{Header, PointCloud2, PointField};

    use super::*;

    /// A random cloud layout: x y z as float32 or float64, maybe a ring of either width, an
    /// intensity of any type, a time in one field (float seconds or integer nanoseconds) or
    /// split, in a shuffled order with padding; several rows with padding at their ends.
    /// Fields, point step, width, height, row step.
    fn random_cloud(rng: &mut Rng) -> (Vec<PointField>, u32, u32, u32, u32) {
        let float = |r: u64| if r.is_multiple_of(2) { 7u8 } else { 8 };
        let mut specs: Vec<(&str, u8)> = vec![
            ("x", float(rng.next())),
            ("y", float(rng.next())),
            ("z", float(rng.next())),
        ];
        if rng.below(3) > 0 {
            specs.push(("ring", [2, 4][rng.below(2) as usize]));
        }
        if rng.below(3) > 0 {
            specs.push(("intensity", 1 + rng.below(8) as u8));
        }
        match rng.below(4) {
            0 => specs.extend([("t_sec", 6), ("t_nsec", 6)]),
            1 => specs.push(("time", 6)), // integer nanoseconds
            2 => specs.push(("time", float(rng.next()))),
            _ => {}
        }
        for k in (1..specs.len()).rev() {
            specs.swap(k, rng.below(k as u64 + 1) as usize);
        }
        let mut fields = Vec::new();
        let mut offset = 0u32;
        for &(name, code) in &specs {
            offset += rng.below(3) as u32; // padding
            fields.push(field(name, offset, code));
            offset += scalar_of_code(code).map_or(0, Scalar::size) as u32;
        }
        let point_step = offset + rng.below(4) as u32;
        let (width, height) = (1 + rng.below(40) as u32, 1 + rng.below(3) as u32);
        let row_step = width * point_step + rng.below(5) as u32;
        (fields, point_step, width, height, row_step)
    }

    /// `v` as `code`'s type, in the byte order asked for.
    fn encode(code: u8, v: f64, be: bool) -> Vec<u8> {
        macro_rules! bytes {
            ($x:expr) => {
                if be {
                    $x.to_be_bytes().to_vec()
                } else {
                    $x.to_le_bytes().to_vec()
                }
            };
        }
        match code {
            1 => bytes!(v as i8),
            2 => bytes!(v as u8),
            3 => bytes!(v as i16),
            4 => bytes!(v as u16),
            5 => bytes!(v as i32),
            6 => bytes!(v as u32),
            7 => bytes!(v as f32),
            _ => bytes!(v),
        }
    }

    /// Field `name`'s value for point `i`; `drop` 0 makes a no-return, 1 a NaN.
    fn value(name: &str, i: u32, drop: u64, ns: bool) -> f64 {
        match name {
            "x" | "y" | "z" if drop == 0 => 0.0,
            "x" if drop == 1 => f64::NAN,
            "x" => 1.0 + f64::from(i) * 0.37,
            "y" => -2.0 - f64::from(i) * 0.11,
            "z" => 0.25 * f64::from(i % 7),
            "ring" => f64::from(i % 16),
            "intensity" => f64::from(i % 100),
            "time" if !ns => f64::from(i) * 1e-4,
            "t_sec" => 1_700_000_000.0,
            _ => f64::from(i) * 1e5, // nanoseconds
        }
    }

    /// A cloud's channels (empty when it has none) and what was dropped.
    struct PointByPoint {
        points: Vec<Point3<f32>>,
        rings: Vec<u16>,
        intensities: Vec<f32>,
        times: Vec<f32>,
        dropped: DroppedPoints,
    }

    /// The cloud as read point by point with `Scalar::read`: points, rings, intensities,
    /// times in seconds since `stamp`, and what was dropped.
    fn read_point_by_point(msg: &PointCloud2<'_>, ns: bool) -> PointByPoint {
        let read = |p: &[u8], name: &str| {
            msg.fields.iter().find(|f| f.name == name).map(|f| {
                let scalar = scalar_of_code(f.datatype).unwrap();
                scalar.read(&p[f.offset as usize..], !msg.is_bigendian)
            })
        };
        let (mut points, mut rings, mut intensities, mut times) = (vec![], vec![], vec![], vec![]);
        let mut dropped = DroppedPoints::default();
        for row in 0..msg.height {
            for col in 0..msg.width {
                let base = (row * msg.row_step + col * msg.point_step) as usize;
                let p = &msg.data[base..base + msg.point_step as usize];
                let xyz = ["x", "y", "z"].map(|a| read(p, a).unwrap() as f32);
                let point = Point3::new(xyz[0], xyz[1], xyz[2]);
                match ReturnFilter::default().classify(&point) {
                    PointKind::Return => {}
                    PointKind::NonFinite => {
                        dropped.non_finite += 1;
                        continue;
                    }
                    PointKind::NoReturn => {
                        dropped.no_return += 1;
                        continue;
                    }
                }
                points.push(point);
                rings.extend(read(p, "ring").map(|v| v as u16));
                intensities.extend(read(p, "intensity").map(|v| v as f32));
                let t = match (read(p, "time"), read(p, "t_sec"), read(p, "t_nsec")) {
                    (Some(t), _, _) if ns => Some(t * 1e-9),
                    (Some(t), _, _) => Some(t),
                    (None, Some(s), Some(n)) => Some(s + n * 1e-9 - msg.header.stamp),
                    _ => None,
                };
                times.extend(t.map(|t| t as f32));
            }
        }
        PointByPoint {
            points,
            rings,
            intensities,
            times,
            dropped,
        }
    }

    /// Every layout decodes as a point-by-point reading with `Scalar::read` does: 200
    /// random layouts (see [`random_cloud`]) in either byte order, with no-returns and NaNs
    /// among the points.
    #[test]
    fn every_layout_decodes_as_a_point_by_point_reading() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        for case in 0..200 {
            let be = case % 2 == 1;
            let (fields, point_step, width, height, row_step) = random_cloud(&mut rng);
            let ns = fields.iter().any(|f| f.name == "time" && f.datatype == 6);
            let mut data: Vec<u8> = (0..row_step * height).map(|_| rng.next() as u8).collect();
            for row in 0..height {
                for col in 0..width {
                    let drop = rng.below(10);
                    let base = (row * row_step + col * point_step) as usize;
                    for f in &fields {
                        let v = value(&f.name, row * width + col, drop, ns);
                        let bytes = encode(f.datatype, v, be);
                        let at = base + f.offset as usize;
                        data[at..at + bytes.len()].copy_from_slice(&bytes);
                    }
                }
            }
            let msg = PointCloud2 {
                header: Header {
                    stamp: 1_700_000_000.0,
                    frame_id: "lidar".into(),
                },
                height,
                width,
                fields,
                is_bigendian: be,
                point_step,
                row_step,
                data: &data,
            };
            let got = PointCloud2Decoder::new(PointCloud2Config::default())
                .decode(&msg)
                .unwrap();
            let PointByPoint {
                points,
                rings,
                intensities,
                times,
                dropped,
            } = read_point_by_point(&msg, ns);
            assert_eq!(got.dropped, dropped, "case {case}");
            assert_eq!(got.cloud.points(), &points[..], "case {case}");
            assert_eq!(got.cloud.ring().unwrap_or(&[]), &rings[..], "case {case}");
            assert_eq!(
                got.cloud.intensity().unwrap_or(&[]),
                &intensities[..],
                "case {case}"
            );
            let got_times = got.cloud.time().unwrap_or(&[]);
            assert_eq!(got_times.len(), times.len(), "case {case}");
            for (a, b) in got_times.iter().zip(&times) {
                assert!((a - b).abs() < 1e-6, "case {case}: {a} vs {b}");
            }
        }
    }
}
