//! Where each channel of a `sensor_msgs/PointCloud2` point is, found from its fields:
//! coordinates as float32 or float64 at any offset (padding between fields is skipped),
//! intensity of any numeric type, ring as uint8 or uint16, and a per-point time under its common
//! names, in one field or split into seconds and nanoseconds.

use std::fmt;

use slam_core::io::Scalar;

use crate::record::MessageError;
use crate::record::ros_messages::{PointCloud2, PointField};

/// Names a per-point time goes by, tried in this order.
const TIME_NAMES: [&str; 5] = ["time", "t", "timestamp", "offset_time", "time_offset"];
/// Names a ring (laser index) goes by.
const RING_NAMES: [&str; 2] = ["ring", "line"];

/// The scalar type of a `sensor_msgs/PointField` datatype code (1 INT8 to 8 FLOAT64).
pub(super) fn scalar_of_code(code: u8) -> Option<Scalar> {
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
    /// The field's name, or `seconds+nanoseconds` for split fields.
    pub(super) fn name(&self) -> String {
        match self {
            Self::Single(f) => f.name.clone(),
            Self::Split {
                seconds,
                nanoseconds,
            } => format!("{}+{}", seconds.name, nanoseconds.name),
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
                fields: cloud.fields.iter().map(|f| f.name.clone()).collect(),
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
