//! Numeric field types shared by the PCD and PLY readers.

use crate::error::FormatError;

/// A scalar type of a binary record field (PCD, PLY, and the fields of a ROS
/// `sensor_msgs/PointCloud2`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(missing_docs)] // the variants are the Rust primitive types they name
pub enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl Scalar {
    /// Size in bytes.
    #[must_use]
    pub fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::I64 | Self::U64 | Self::F64 => 8,
        }
    }

    /// Whether the type is an integer type.
    #[must_use]
    pub fn is_integer(self) -> bool {
        !matches!(self, Self::F32 | Self::F64)
    }

    /// Decode one value at the start of `b` as f64.
    ///
    /// # Panics
    /// If `b` is shorter than [`Scalar::size`].
    #[inline]
    #[must_use]
    pub fn read(self, b: &[u8], little_endian: bool) -> f64 {
        macro_rules! get {
            ($t:ty, $n:expr) => {{
                let mut a = [0u8; $n];
                a.copy_from_slice(&b[..$n]);
                if little_endian {
                    <$t>::from_le_bytes(a)
                } else {
                    <$t>::from_be_bytes(a)
                }
            }};
        }
        match self {
            Self::I8 => f64::from(b[0] as i8),
            Self::U8 => f64::from(b[0]),
            Self::I16 => f64::from(get!(i16, 2)),
            Self::U16 => f64::from(get!(u16, 2)),
            Self::I32 => f64::from(get!(i32, 4)),
            Self::U32 => f64::from(get!(u32, 4)),
            Self::I64 => get!(i64, 8) as f64,
            Self::U64 => get!(u64, 8) as f64,
            Self::F32 => f64::from(get!(f32, 4)),
            Self::F64 => get!(f64, 8),
        }
    }
}

/// Parse a decimal token of a text format, with the line number for errors.
pub(crate) fn parse_f64(token: &str, line: usize, what: &str) -> Result<f64, FormatError> {
    token.parse::<f64>().map_err(|_| FormatError::Line {
        line,
        message: format!("{what}: {token:?} is not a number"),
    })
}

/// A ring value from a decoded number: a whole number in `0..=u16::MAX`.
pub(crate) fn ring_value(v: f64) -> Option<u16> {
    (v.fract() == 0.0 && (0.0..=f64::from(u16::MAX)).contains(&v)).then_some(v as u16)
}

/// Which cloud channel a field name feeds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Channel {
    X,
    Y,
    Z,
    Intensity,
    Ring,
    Time,
}

impl Channel {
    /// The channel's field name in the files (the first of its aliases).
    pub(crate) fn name(self) -> &'static str {
        match self {
            Self::X => "x",
            Self::Y => "y",
            Self::Z => "z",
            Self::Intensity => "intensity",
            Self::Ring => "ring",
            Self::Time => "t",
        }
    }

    /// The channel a field or property of this name holds, if any.
    pub(crate) fn from_name(name: &str) -> Option<Self> {
        Some(match name {
            "x" => Self::X,
            "y" => Self::Y,
            "z" => Self::Z,
            "intensity" | "scalar_intensity" | "reflectance" => Self::Intensity,
            "ring" | "laser_id" | "channel" => Self::Ring,
            "t" | "time" | "timestamp" => Self::Time,
            _ => return None,
        })
    }
}

/// Collects decoded values per channel and builds the cloud.
/// One field's values in binary records: the `scalar` at `offset` of each `stride`-byte record
/// of `data`.
pub(crate) struct Column<'a> {
    pub(crate) data: &'a [u8],
    pub(crate) stride: usize,
    pub(crate) offset: usize,
    pub(crate) scalar: Scalar,
}

impl Column<'_> {
    /// Calls `put(record, value)` for the first `n` records, stopping at the first error (the
    /// record's index); one loop per type, not a match per value.
    // Every integer type up to 64 bits is read as f64, as `Scalar::read` does.
    #[allow(clippy::cast_lossless)]
    fn for_each(
        &self,
        n: usize,
        little_endian: bool,
        mut put: impl FnMut(usize, f64) -> Result<(), usize>,
    ) -> Result<(), usize> {
        let offset = self.offset;
        macro_rules! column {
            ($t:ty) => {{
                const N: usize = std::mem::size_of::<$t>();
                for (r, b) in self.data.chunks_exact(self.stride).take(n).enumerate() {
                    let mut a = [0u8; N];
                    a.copy_from_slice(&b[offset..offset + N]);
                    let v = if little_endian {
                        <$t>::from_le_bytes(a)
                    } else {
                        <$t>::from_be_bytes(a)
                    };
                    put(r, v as f64)?;
                }
            }};
        }
        match self.scalar {
            Scalar::I8 => column!(i8),
            Scalar::U8 => column!(u8),
            Scalar::I16 => column!(i16),
            Scalar::U16 => column!(u16),
            Scalar::I32 => column!(i32),
            Scalar::U32 => column!(u32),
            Scalar::I64 => column!(i64),
            Scalar::U64 => column!(u64),
            Scalar::F32 => column!(f32),
            Scalar::F64 => column!(f64),
        }
        Ok(())
    }
}

#[derive(Default)]
pub(crate) struct ChannelSink {
    pub(crate) xyz: Vec<nalgebra::Point3<f32>>,
    pub(crate) ring: Option<Vec<u16>>,
    pub(crate) intensity: Option<Vec<f32>>,
    pub(crate) time: Option<Vec<f32>>,
}

impl ChannelSink {
    /// A sink for `n` points with the given optional channels.
    pub(crate) fn new(n: usize, ring: bool, intensity: bool, time: bool) -> Self {
        Self {
            xyz: Vec::with_capacity(n),
            ring: ring.then(|| Vec::with_capacity(n)),
            intensity: intensity.then(|| Vec::with_capacity(n)),
            time: time.then(|| Vec::with_capacity(n)),
        }
    }

    /// Appends `n` points read a column at a time, each channel from its `Column` (values of
    /// channels the sink does not hold are skipped); the index of the first point whose ring is
    /// not a whole number in `0..=65535`. Every column holds `n` values.
    pub(crate) fn extend_columns(
        &mut self,
        n: usize,
        columns: &[(Channel, Column<'_>)],
        little_endian: bool,
    ) -> Result<(), usize> {
        let first = self.xyz.len();
        self.xyz
            .resize(first + n, nalgebra::Point3::new(0.0, 0.0, 0.0));
        for (channel, column) in columns {
            match channel {
                Channel::X | Channel::Y | Channel::Z => {
                    let axis = match channel {
                        Channel::X => 0,
                        Channel::Y => 1,
                        _ => 2,
                    };
                    let xyz = &mut self.xyz[first..];
                    column.for_each(n, little_endian, |r, v| {
                        xyz[r][axis] = v as f32;
                        Ok(())
                    })?;
                }
                Channel::Intensity | Channel::Time => {
                    let out = if *channel == Channel::Time {
                        self.time.as_mut()
                    } else {
                        self.intensity.as_mut()
                    };
                    if let Some(out) = out {
                        column.for_each(n, little_endian, |_, v| {
                            out.push(v as f32);
                            Ok(())
                        })?;
                    }
                }
                Channel::Ring => {
                    if let Some(out) = self.ring.as_mut() {
                        column.for_each(n, little_endian, |r, v| {
                            out.push(ring_value(v).ok_or(r)?);
                            Ok(())
                        })?;
                    }
                }
            }
        }
        Ok(())
    }

    /// The finished cloud.
    pub(crate) fn finish(self) -> Result<crate::PointCloud, FormatError> {
        let mut c = crate::PointCloud::from_points(self.xyz);
        if let Some(r) = self.ring {
            c = c.with_ring(r)?;
        }
        if let Some(i) = self.intensity {
            c = c.with_intensity(i)?;
        }
        if let Some(t) = self.time {
            c = c.with_time(t)?;
        }
        Ok(c)
    }
}

/// Read a whole file, naming it in the error.
pub(crate) fn read_file(path: &std::path::Path) -> Result<Vec<u8>, FormatError> {
    std::fs::read(path).map_err(|source| FormatError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Create a file for writing, naming it in the error.
pub(crate) fn create_file(
    path: &std::path::Path,
) -> Result<std::io::BufWriter<std::fs::File>, FormatError> {
    std::fs::File::create(path)
        .map(std::io::BufWriter::new)
        .map_err(|source| FormatError::Io {
            path: path.to_path_buf(),
            source,
        })
}
