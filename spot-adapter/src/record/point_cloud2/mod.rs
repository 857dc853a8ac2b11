//! `sensor_msgs/PointCloud2` to [`PointCloud`](slam_core::PointCloud), in any field layout:
//! coordinates as float32 or float64 at any offset (padding between fields is skipped),
//! intensity of any numeric type, ring as uint8 or uint16, and a per-point time under its common
//! names, read as float or integer, in one field or split into seconds and nanoseconds.
//! Big-endian data is read as such.
//!
//! The layout is found from the fields ([`CloudLayout`]), the data read a column at a time
//! (`columns`), and the decoder ([`PointCloud2Decoder`]) removes the no-returns and puts the
//! times in seconds since the stamp, in the unit decided for the topic from the values
//! ([`TimeUnit`], shared with the PCD/PLY folder reader).

mod columns;
mod decoder;
mod layout;
#[cfg(test)]
pub(super) mod test_clouds;

pub use crate::record::time_unit::TimeUnit;
pub use decoder::{DecodedCloud, PointCloud2Config, PointCloud2Decoder};
pub use layout::{CloudLayout, FieldSlot, TimeFields};
