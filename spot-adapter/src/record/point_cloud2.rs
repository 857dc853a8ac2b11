//! `sensor_msgs/PointCloud2` to [`PointCloud`], in any field layout: coordinates as float32 or
//! float64 at any offset (padding between fields is skipped), intensity of any numeric type,
//! ring as uint8 or uint16, and a per-point time under its common names, read as float or
//! integer, in one field or split into seconds and nanoseconds. Big-endian data is read as such.
//!
//! Drivers disagree on the time's unit: Velodyne writes float seconds since the header stamp,
//! Ouster and Livox integer nanoseconds since it, Hesai float absolute seconds, some split
//! absolute time in two fields. The unit is decided from the values: the one (seconds or
//! nanoseconds, absolute or relative to the stamp) under which every point lies within one scan
//! period of the stamp. It is decided once per topic, on the first cloud whose times are not all
//! equal, and every later cloud is checked against it; a cloud that fits no unit, or two units
//! at once, is an error rather than a guess.

use std::fmt;

use nalgebra::Point3;
use slam_core::PointCloud;
use slam_core::io::Scalar;

use crate::error::MessageError;
use crate::record::no_return::{DroppedPoints, PointKind, ReturnFilter};
use crate::record::ros_messages::{PointCloud2, PointField};

/// Names a per-point time goes by, tried in this order.
const TIME_NAMES: [&str; 5] = ["time", "t", "timestamp", "offset_time", "time_offset"];
/// The least spread (seconds) of per-point times that differ.
const MIN_SPREAD: f64 = 1e-5;
/// Names a ring (laser index) goes by.
const RING_NAMES: [&str; 2] = ["ring", "line"];

/// The scalar type of a `sensor_msgs/PointField` datatype code (1 INT8 to 8 FLOAT64).
fn scalar_of_code(code: u8) -> Option<Scalar> {
    Some(match code {
        1 => Scalar::I8,
        2 => Scalar::U8,
        3 => Scalar::I16,
        4 => Scalar::U16,
        5 => Scalar::I32,
        6 => Scalar::U32,
        7 => Scalar::F32,
        8 => Scalar::F64,
        _ => return None,
    })
}

/// The ROS name of a datatype.
fn scalar_name(scalar: Scalar) -> &'static str {
    match scalar {
        Scalar::I8 => "int8",
        Scalar::U8 => "uint8",
        Scalar::I16 => "int16",
        Scalar::U16 => "uint16",
        Scalar::I32 => "int32",
        Scalar::U32 => "uint32",
        Scalar::I64 => "int64",
        Scalar::U64 => "uint64",
        Scalar::F32 => "float32",
        Scalar::F64 => "float64",
    }
}

/// One field's place in a point.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FieldSlot {
    /// The field's name.
    pub name: String,
    /// Byte offset in the point.
    pub offset: usize,
    /// Its type.
    pub scalar: Scalar,
}

impl FieldSlot {
    /// The value in `point` (at least `offset + size` bytes, checked when the layout was made).
    #[inline]
    fn read(&self, point: &[u8], big_endian: bool) -> f64 {
        self.scalar.read(&point[self.offset..], !big_endian)
    }
}

/// Where a cloud's per-point time is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum TimeFields {
    /// One field.
    Single(FieldSlot),
    /// Whole seconds and nanoseconds in two fields (`sec`/`nsec`, `t_sec`/`t_nsec`, ...).
    Split {
        /// The seconds.
        seconds: FieldSlot,
        /// The nanoseconds.
        nanoseconds: FieldSlot,
    },
}

impl TimeFields {
    #[inline]
    fn read(&self, point: &[u8], big_endian: bool) -> f64 {
        match self {
            Self::Single(f) => f.read(point, big_endian),
            Self::Split {
                seconds,
                nanoseconds,
            } => seconds.read(point, big_endian) + nanoseconds.read(point, big_endian) * 1e-9,
        }
    }

    fn name(&self) -> String {
        match self {
            Self::Single(f) => f.name.clone(),
            Self::Split {
                seconds,
                nanoseconds,
            } => format!("{}+{}", seconds.name, nanoseconds.name),
        }
    }
}

/// The unit of a per-point time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimeUnit {
    /// Seconds since the header stamp (Velodyne).
    SecondsRelative,
    /// Nanoseconds since the header stamp (Ouster, Livox).
    NanosecondsRelative,
    /// Seconds on the same clock as the header stamp (Hesai; split sec + nsec fields).
    SecondsAbsolute,
    /// Nanoseconds on the same clock as the header stamp.
    NanosecondsAbsolute,
}

impl TimeUnit {
    /// Preference when units tie (all times equal): relative before absolute, seconds first.
    const ALL: [Self; 4] = [
        Self::SecondsRelative,
        Self::NanosecondsRelative,
        Self::SecondsAbsolute,
        Self::NanosecondsAbsolute,
    ];

    /// Seconds after `stamp` of a raw value `v`.
    #[must_use]
    pub fn offset(self, v: f64, stamp: f64) -> f64 {
        match self {
            Self::SecondsRelative => v,
            Self::NanosecondsRelative => v * 1e-9,
            Self::SecondsAbsolute => v - stamp,
            Self::NanosecondsAbsolute => v * 1e-9 - stamp,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Self::SecondsRelative => "s since the stamp",
            Self::NanosecondsRelative => "ns since the stamp",
            Self::SecondsAbsolute => "s absolute",
            Self::NanosecondsAbsolute => "ns absolute",
        }
    }
}

/// Where each channel of a cloud is, found from its fields.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CloudLayout {
    /// x, y, z (float32 or float64).
    pub xyz: [FieldSlot; 3],
    /// Intensity, any numeric type.
    pub intensity: Option<FieldSlot>,
    /// Ring, uint8 or uint16.
    pub ring: Option<FieldSlot>,
    /// The per-point time.
    pub time: Option<TimeFields>,
    /// Bytes per point.
    pub point_step: usize,
    /// Whether the data is big-endian.
    pub big_endian: bool,
}

fn slot(field: &PointField, point_step: u32) -> Result<FieldSlot, MessageError> {
    let scalar =
        scalar_of_code(field.datatype).ok_or_else(|| MessageError::UnsupportedDatatype {
            field: field.name.clone(),
            datatype: field.datatype,
            role: "a PointField datatype (1 to 8)",
        })?;
    let size = scalar.size().saturating_mul(field.count.max(1) as usize);
    if u64::from(field.offset) + size as u64 > u64::from(point_step) {
        return Err(MessageError::FieldOutsidePoint {
            field: field.name.clone(),
            offset: field.offset,
            size,
            point_step,
        });
    }
    Ok(FieldSlot {
        name: field.name.clone(),
        offset: field.offset as usize,
        scalar,
    })
}

impl CloudLayout {
    /// The layout of `cloud`'s fields.
    ///
    /// # Errors
    /// [`MessageError::MissingCoordinate`] without x, y or z; [`MessageError::UnsupportedDatatype`]
    /// for a datatype code outside 1 to 8, a coordinate that is not a float or a ring that is not
    /// uint8 or uint16; [`MessageError::FieldOutsidePoint`] for a field past `point_step`.
    pub fn of(cloud: &PointCloud2<'_>) -> Result<Self, MessageError> {
        let field = |name: &str| cloud.fields.iter().find(|f| f.name == name);
        let step = cloud.point_step;
        let coordinate = |axis: &'static str| -> Result<FieldSlot, MessageError> {
            let f = field(axis).ok_or_else(|| MessageError::MissingCoordinate {
                axis,
                fields: cloud
                    .fields
                    .iter()
                    .map(|f| f.name.as_str())
                    .collect::<Vec<_>>()
                    .join(","),
            })?;
            let s = slot(f, step)?;
            if s.scalar.is_integer() {
                return Err(MessageError::UnsupportedDatatype {
                    field: f.name.clone(),
                    datatype: f.datatype,
                    role: "a coordinate (float32 or float64)",
                });
            }
            Ok(s)
        };
        let xyz = [coordinate("x")?, coordinate("y")?, coordinate("z")?];
        let intensity = field("intensity").map(|f| slot(f, step)).transpose()?;
        let ring = match RING_NAMES.iter().find_map(|n| field(n)) {
            Some(f) => {
                let s = slot(f, step)?;
                if !matches!(s.scalar, Scalar::U8 | Scalar::U16) {
                    return Err(MessageError::UnsupportedDatatype {
                        field: f.name.clone(),
                        datatype: f.datatype,
                        role: "a ring (uint8 or uint16)",
                    });
                }
                Some(s)
            }
            None => None,
        };
        let time = if let Some(f) = TIME_NAMES.iter().find_map(|n| field(n)) {
            Some(TimeFields::Single(slot(f, step)?))
        } else {
            // Split fields: `<prefix>nsec` beside `<prefix>sec`.
            let pair = cloud.fields.iter().find_map(|ns| {
                let prefix = ns.name.strip_suffix("nsec")?;
                Some((field(&format!("{prefix}sec"))?, ns))
            });
            match pair {
                Some((s, ns)) => Some(TimeFields::Split {
                    seconds: slot(s, step)?,
                    nanoseconds: slot(ns, step)?,
                }),
                None => None,
            }
        };
        Ok(Self {
            xyz,
            intensity,
            ring,
            time,
            point_step: step as usize,
            big_endian: cloud.is_bigendian,
        })
    }
}

impl fmt::Display for CloudLayout {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [x, y, z] = &self.xyz;
        write!(
            f,
            "x,y,z {}/{}/{} at {},{},{}",
            scalar_name(x.scalar),
            scalar_name(y.scalar),
            scalar_name(z.scalar),
            x.offset,
            y.offset,
            z.offset
        )?;
        if let Some(i) = &self.intensity {
            write!(f, "; intensity {}", scalar_name(i.scalar))?;
        }
        if let Some(r) = &self.ring {
            write!(f, "; {} {}", r.name, scalar_name(r.scalar))?;
        }
        match &self.time {
            Some(TimeFields::Single(t)) => {
                write!(f, "; time {:?} {}", t.name, scalar_name(t.scalar))?;
            }
            Some(TimeFields::Split {
                seconds,
                nanoseconds,
            }) => write!(f, "; time {:?}+{:?}", seconds.name, nanoseconds.name)?,
            None => write!(f, "; no per-point time")?,
        }
        write!(
            f,
            "; {} bytes per point{}",
            self.point_step,
            if self.big_endian { ", big-endian" } else { "" }
        )
    }
}

fn shape_error(msg: &PointCloud2<'_>) -> MessageError {
    MessageError::CloudShape {
        width: msg.width,
        height: msg.height,
        point_step: msg.point_step,
        row_step: msg.row_step,
        data_len: msg.data.len(),
    }
}

/// The bytes of points in one row, once `width`, `height`, `point_step`, `row_step` and the
/// data's length are checked to agree.
fn checked_row_bytes(msg: &PointCloud2<'_>) -> Result<u64, MessageError> {
    let row_points = u64::from(msg.width) * u64::from(msg.point_step);
    if msg.point_step == 0
        || u64::from(msg.row_step) < row_points
        || u64::from(msg.row_step) * u64::from(msg.height) != msg.data.len() as u64
    {
        return Err(shape_error(msg));
    }
    Ok(row_points)
}

/// Settings of [`PointCloud2Decoder`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointCloud2Config {
    /// Which points are returns.
    pub returns: ReturnFilter,
    /// The longest scan period (seconds) per-point times may span; usual value 0.25 s (a 5 Hz
    /// LiDAR's 0.2 s sweep and some margin). Every time must lie within this of the stamp.
    pub max_scan_period: f64,
    /// The time unit, when known; `None` decides it from the first cloud.
    pub time_unit: Option<TimeUnit>,
}

impl Default for PointCloud2Config {
    fn default() -> Self {
        Self {
            returns: ReturnFilter::default(),
            max_scan_period: 0.25,
            time_unit: None,
        }
    }
}

/// Decodes the clouds of one topic, keeping the time unit it decided.
#[derive(Clone, Debug)]
pub struct PointCloud2Decoder {
    config: PointCloud2Config,
    unit: Option<TimeUnit>,
}

/// A cloud decoded, with what was removed from it.
#[derive(Clone, Debug, PartialEq)]
pub struct DecodedCloud {
    /// The returns, times in seconds since the stamp.
    pub cloud: PointCloud,
    /// What was removed.
    pub dropped: DroppedPoints,
    /// The layout read.
    pub layout: CloudLayout,
}

impl PointCloud2Decoder {
    /// A decoder with `config`.
    #[must_use]
    pub fn new(config: PointCloud2Config) -> Self {
        Self {
            unit: config.time_unit,
            config,
        }
    }

    /// The time unit decided so far (or given).
    #[must_use]
    pub fn time_unit(&self) -> Option<TimeUnit> {
        self.unit
    }

    /// Decode `msg`.
    ///
    /// # Errors
    /// As [`CloudLayout::of`]; [`MessageError::CloudShape`] when the sizes disagree;
    /// [`MessageError::TimeUnit`] when the times fit no unit, fit two, or no longer fit the one
    /// decided.
    pub fn decode(&mut self, msg: &PointCloud2<'_>) -> Result<DecodedCloud, MessageError> {
        let layout = CloudLayout::of(msg)?;
        let row_points = checked_row_bytes(msg)?;
        let (step, row_step) = (layout.point_step, msg.row_step as usize);
        let n = msg.width as usize * msg.height as usize;
        let be = layout.big_endian;
        let mut dropped = DroppedPoints::default();
        let mut points = Vec::with_capacity(n);
        let mut ring = layout.ring.as_ref().map(|_| Vec::with_capacity(n));
        let mut intensity = layout.intensity.as_ref().map(|_| Vec::with_capacity(n));
        // Raw times of the kept points, and the range over all points (for the unit).
        let mut raw_time = layout.time.as_ref().map(|_| Vec::with_capacity(n));
        let (mut t_min, mut t_max) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut bad_time = false;
        let [x, y, z] = &layout.xyz;
        // The common layout (little-endian float32 coordinates) read without dispatch.
        let plain = !be && layout.xyz.iter().all(|f| f.scalar == Scalar::F32);
        let f32_at = |p: &[u8], o: usize| {
            let mut a = [0u8; 4];
            a.copy_from_slice(&p[o..o + 4]);
            f32::from_le_bytes(a)
        };
        // A cloud of width 0 has no point whatever its height claims: its empty rows are not
        // walked, so the work stays in proportion to the data.
        let rows = if n == 0 { 0 } else { msg.height as usize };
        for row in 0..rows {
            let start = row * row_step;
            for p in msg.data[start..start + row_points as usize].chunks_exact(step) {
                let t = layout.time.as_ref().map(|f| {
                    let t = f.read(p, be);
                    bad_time |= !t.is_finite();
                    t_min = t_min.min(t);
                    t_max = t_max.max(t);
                    t
                });
                let point = if plain {
                    Point3::new(
                        f32_at(p, x.offset),
                        f32_at(p, y.offset),
                        f32_at(p, z.offset),
                    )
                } else {
                    Point3::new(
                        x.read(p, be) as f32,
                        y.read(p, be) as f32,
                        z.read(p, be) as f32,
                    )
                };
                match self.config.returns.classify(&point) {
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
                if let (Some(v), Some(f)) = (&mut ring, &layout.ring) {
                    v.push(f.read(p, be) as u16);
                }
                if let (Some(v), Some(f)) = (&mut intensity, &layout.intensity) {
                    v.push(f.read(p, be) as f32);
                }
                if let (Some(v), Some(t)) = (&mut raw_time, t) {
                    v.push(t);
                }
            }
        }
        let time = match (&layout.time, raw_time) {
            (Some(fields), Some(raw)) => {
                if bad_time {
                    t_min = f64::NAN;
                }
                let unit = self.time_unit_of(fields, msg.header.stamp, t_min, t_max)?;
                let stamp = msg.header.stamp;
                Some(
                    raw.into_iter()
                        .map(|v| unit.offset(v, stamp) as f32)
                        .collect(),
                )
            }
            _ => None,
        };
        // Every channel has one value per kept point.
        let cloud = PointCloud::from_points(points);
        let with = |c: Result<PointCloud, _>| c.map_err(|_| shape_error(msg));
        let cloud = match ring {
            Some(v) => with(cloud.with_ring(v))?,
            None => cloud,
        };
        let cloud = match intensity {
            Some(v) => with(cloud.with_intensity(v))?,
            None => cloud,
        };
        let cloud = match time {
            Some(v) => with(cloud.with_time(v))?,
            None => cloud,
        };
        Ok(DecodedCloud {
            cloud,
            dropped,
            layout,
        })
    }

    /// `cloud`'s time channel (read from a file as it was stored, relative to the scan's start)
    /// in seconds: kept when it fits seconds, scaled when it fits nanoseconds (Ouster's PCDs),
    /// by the same rule and with the same memory of the unit as [`PointCloud2Decoder::decode`].
    ///
    /// # Errors
    /// [`MessageError::TimeUnit`] when the times fit neither.
    pub fn times_in_seconds(&mut self, cloud: PointCloud) -> Result<PointCloud, MessageError> {
        let Some(time) = cloud.time() else {
            return Ok(cloud);
        };
        let (min, max) = time
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &t| {
                (lo.min(f64::from(t)), hi.max(f64::from(t)))
            });
        let field = TimeFields::Single(FieldSlot {
            name: "t".into(),
            offset: 0,
            scalar: Scalar::F32,
        });
        let min = if time.iter().all(|t| t.is_finite()) {
            min
        } else {
            f64::NAN
        };
        match self.time_unit_of(&field, 0.0, min, max)? {
            TimeUnit::SecondsRelative | TimeUnit::SecondsAbsolute => Ok(cloud),
            TimeUnit::NanosecondsRelative | TimeUnit::NanosecondsAbsolute => {
                let (points, ring, intensity, time) = cloud.into_parts();
                let seconds: Vec<f32> = time
                    .unwrap_or_default()
                    .iter()
                    .map(|&t| (f64::from(t) * 1e-9) as f32)
                    .collect();
                let mut out = PointCloud::from_points(points);
                // The channels keep their lengths, so these cannot fail.
                let bad = |_| MessageError::TimeUnit {
                    field: "t".into(),
                    min,
                    max,
                    stamp: 0.0,
                    period: self.config.max_scan_period,
                    problem: "the cloud's channels differ in length".into(),
                };
                if let Some(r) = ring {
                    out = out.with_ring(r).map_err(bad)?;
                }
                if let Some(i) = intensity {
                    out = out.with_intensity(i).map_err(bad)?;
                }
                out.with_time(seconds).map_err(bad)
            }
        }
    }

    /// The unit of raw times in `[min, max]` (one cloud stamped `stamp`), deciding it on the first
    /// cloud whose times differ.
    // Exactly equal times are the case where nothing can be decided.
    #[allow(clippy::float_cmp)]
    fn time_unit_of(
        &mut self,
        time: &TimeFields,
        stamp: f64,
        min: f64,
        max: f64,
    ) -> Result<TimeUnit, MessageError> {
        let period = self.config.max_scan_period;
        let error = |problem: String| MessageError::TimeUnit {
            field: time.name(),
            min,
            max,
            stamp,
            period,
            problem,
        };
        if min > max {
            // No point: any unit will do.
            return Ok(self.unit.unwrap_or(TimeUnit::SecondsRelative));
        }
        if !(min.is_finite() && max.is_finite()) {
            return Err(error("a time is not finite".into()));
        }
        // A unit fits when it puts every point within one period of the stamp, and spreads
        // differing times over at least 10 us (the 0.04 degrees a 10 Hz LiDAR turns in that
        // time): seconds read as nanoseconds would squeeze a sweep into nanoseconds.
        let fits = |u: TimeUnit| {
            let (lo, hi) = (u.offset(min, stamp), u.offset(max, stamp));
            let spread = hi - lo;
            lo >= -period
                && hi <= period
                && spread <= period
                && (max == min || spread >= MIN_SPREAD)
        };
        if let Some(unit) = self.unit {
            return if fits(unit) {
                Ok(unit)
            } else {
                Err(error(format!(
                    "the unit decided earlier ({}) does not fit",
                    unit.name()
                )))
            };
        }
        let spread = |u: TimeUnit| u.offset(max, stamp) - u.offset(min, stamp);
        let candidates: Vec<TimeUnit> = TimeUnit::ALL.into_iter().filter(|&u| fits(u)).collect();
        // The widest spread; on a tie the first in preference order.
        let Some(best) = candidates
            .iter()
            .copied()
            .reduce(|a, b| if spread(b) > spread(a) { b } else { a })
        else {
            return Err(error(
                "no unit (s or ns, absolute or since the stamp) fits".into(),
            ));
        };
        if spread(best) == 0.0 {
            // All times equal: nothing to decide from; take the preferred unit for this cloud.
            return Ok(candidates[0]);
        }
        // Another unit that spreads the points as widely but places them elsewhere.
        if let Some(other) = candidates.iter().find(|&&u| {
            u != best
                && spread(u) >= 0.1 * spread(best)
                && (u.offset(min, stamp) - best.offset(min, stamp)).abs() > 1e-6
        }) {
            return Err(error(format!(
                "both {} and {} fit",
                best.name(),
                other.name()
            )));
        }
        self.unit = Some(best);
        Ok(best)
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;
    use crate::record::ros_messages::Header;

    fn field(name: &str, offset: u32, datatype: u8) -> PointField {
        PointField {
            name: name.into(),
            offset,
            datatype,
            count: 1,
        }
    }

    /// `n` points of x y z f32 and a time (f32 seconds) at offset 12, 16 bytes each.
    fn cloud(data: &[u8], stamp: f64) -> PointCloud2<'_> {
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

    fn points(times: &[f32]) -> Vec<u8> {
        let mut data = Vec::new();
        for (i, t) in times.iter().enumerate() {
            for v in [1.0 + i as f32, 2.0, 3.0, *t] {
                data.extend_from_slice(&v.to_le_bytes());
            }
        }
        data
    }

    #[test]
    fn shapes_that_disagree_are_errors() {
        let data = points(&[0.0, 0.05]);
        let mut decoder = PointCloud2Decoder::new(PointCloud2Config::default());
        let mut c = cloud(&data, 100.0);
        c.row_step = 16;
        assert!(matches!(
            decoder.decode(&c),
            Err(MessageError::CloudShape { .. })
        ));
        let mut c = cloud(&data[..24], 100.0);
        c.width = 2;
        assert!(matches!(
            decoder.decode(&c),
            Err(MessageError::CloudShape { .. })
        ));
        let mut c = cloud(&data, 100.0);
        c.fields[3].offset = 14;
        assert!(matches!(
            decoder.decode(&c),
            Err(MessageError::FieldOutsidePoint { .. })
        ));
        let mut c = cloud(&data, 100.0);
        c.fields[0].datatype = 9;
        assert!(matches!(
            decoder.decode(&c),
            Err(MessageError::UnsupportedDatatype { .. })
        ));
        let mut c = cloud(&data, 100.0);
        c.fields[1].datatype = 5;
        assert!(matches!(
            decoder.decode(&c),
            Err(MessageError::UnsupportedDatatype { role, .. }) if role.contains("coordinate")
        ));
        let mut c = cloud(&data, 100.0);
        c.fields[3].name = "ring".into();
        assert!(matches!(
            decoder.decode(&c),
            Err(MessageError::UnsupportedDatatype { role, .. }) if role.contains("ring")
        ));
    }

    #[test]
    fn time_units_are_decided_once_and_checked_after() {
        let data = points(&[0.0, 0.05, 0.099]);
        let mut decoder = PointCloud2Decoder::new(PointCloud2Config::default());
        let got = decoder.decode(&cloud(&data, 1.7e9)).unwrap();
        assert_eq!(decoder.time_unit(), Some(TimeUnit::SecondsRelative));
        assert_eq!(got.cloud.time(), Some(&[0.0, 0.05, 0.099][..]));
        // A later cloud spanning 2 s no longer fits the unit decided.
        let data = points(&[0.0, 2.0]);
        assert!(matches!(
            decoder.decode(&cloud(&data, 1.7e9 + 0.1)),
            Err(MessageError::TimeUnit { .. })
        ));
        // Near a zero stamp, absolute and relative seconds both fit and disagree.
        let data = points(&[0.06, 0.1]);
        let mut fresh = PointCloud2Decoder::new(PointCloud2Config::default());
        let err = fresh.decode(&cloud(&data, 0.05)).unwrap_err();
        assert!(
            matches!(&err, MessageError::TimeUnit { problem, .. } if problem.contains("both")),
            "{err}"
        );
        // Equal times decide nothing.
        let data = points(&[0.0, 0.0]);
        let mut fresh = PointCloud2Decoder::new(PointCloud2Config::default());
        fresh.decode(&cloud(&data, 5.0)).unwrap();
        assert_eq!(fresh.time_unit(), None);
    }

    #[test]
    fn no_returns_and_non_finite_points_are_dropped_with_their_channels() {
        let mut data = points(&[0.0, 0.01, 0.02, 0.03]);
        // Point 1 at the origin, point 2 NaN.
        data[16..28].copy_from_slice(&[0; 12]);
        data[32..36].copy_from_slice(&f32::NAN.to_le_bytes());
        let mut decoder = PointCloud2Decoder::new(PointCloud2Config::default());
        let got = decoder.decode(&cloud(&data, 10.0)).unwrap();
        assert_eq!(
            got.dropped,
            DroppedPoints {
                non_finite: 1,
                no_return: 1
            }
        );
        assert_eq!(got.cloud.time(), Some(&[0.0, 0.03][..]));
        assert_eq!(got.cloud.points()[1].x, 4.0);
    }
}
