//! Why one message of a bag (or one cloud) cannot be used.

use thiserror::Error;

use crate::record::TimeUnit;

/// Why one message of a bag (or one cloud) cannot be used.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum MessageError {
    /// The payload ends before a field it declares.
    #[error("payload truncated: {needed} bytes needed at offset {offset}, {left} left")]
    Truncated {
        /// Byte offset in the payload.
        offset: usize,
        /// Bytes the field needs.
        needed: usize,
        /// Bytes left.
        left: usize,
    },
    /// A CDR payload whose encapsulation is not plain CDR.
    #[error("CDR encapsulation {kind:?} is not plain little- or big-endian CDR")]
    Encapsulation {
        /// The first two header bytes.
        kind: [u8; 2],
    },
    /// A string is not UTF-8 (or, in CDR, lacks its terminating NUL).
    #[error("invalid string at offset {offset}")]
    InvalidString {
        /// Byte offset of its length.
        offset: usize,
    },
    /// The topic carries another message type than the reader needs there.
    #[error("message type {found:?} where {expected} is needed")]
    UnknownType {
        /// The type the bag names.
        found: String,
        /// The type needed.
        expected: &'static str,
    },
    /// A point cloud lacks a coordinate field.
    #[error("the cloud has no {axis:?} field (fields: {})", .fields.join(","))]
    MissingCoordinate {
        /// `x`, `y` or `z`.
        axis: &'static str,
        /// The fields it has.
        fields: Vec<String>,
    },
    /// A point field has a datatype code outside `sensor_msgs/PointField`'s, or one unfit for
    /// its role (a coordinate that is not a float).
    #[error("field {field:?}: datatype {datatype} cannot be read as {role}")]
    UnsupportedDatatype {
        /// The field's name.
        field: String,
        /// Its datatype code.
        datatype: u8,
        /// What it was to be read as.
        role: &'static str,
    },
    /// A point field does not fit inside one point.
    #[error(
        "field {field:?} (offset {offset}, {size} bytes) does not fit in a point of {point_step} bytes"
    )]
    FieldOutsidePoint {
        /// The field's name.
        field: String,
        /// Its offset.
        offset: u32,
        /// Its size in bytes.
        size: usize,
        /// Bytes per point.
        point_step: u32,
    },
    /// `width`, `height`, `point_step`, `row_step` and the data's length disagree.
    #[error(
        "cloud shape: {width} x {height} points of {point_step} bytes, rows of {row_step} bytes, \
         {data_len} bytes of data"
    )]
    CloudShape {
        /// Points per row.
        width: u32,
        /// Rows.
        height: u32,
        /// Bytes per point.
        point_step: u32,
        /// Bytes per row.
        row_step: u32,
        /// Bytes of data.
        data_len: usize,
    },
    /// No unit makes the per-point times fit in one scan period after the header stamp (or more
    /// than one does).
    #[error(
        "per-point time {field:?} in [{min}, {max}] (stamp {stamp} s): {problem} within a scan \
         period of {period} s"
    )]
    TimeUnit {
        /// The time field (or fields).
        field: String,
        /// Smallest raw value.
        min: f64,
        /// Largest raw value.
        max: f64,
        /// The header stamp (seconds).
        stamp: f64,
        /// The longest scan period allowed (seconds).
        period: f64,
        /// Why no one unit can be taken.
        problem: TimeUnitProblem,
    },
    /// A pose with a non-finite value or a quaternion far from unit length.
    #[error("{what} is not a valid pose (non-finite or non-unit quaternion)")]
    InvalidPose {
        /// Which pose.
        what: &'static str,
    },
    /// The frame tree does not join two frames.
    #[error("no transform from {parent:?} to {child:?} at {stamp} s in the tf messages")]
    MissingTransform {
        /// The frame looked up from.
        parent: String,
        /// The frame looked up.
        child: String,
        /// The time (seconds).
        stamp: f64,
    },
}

/// Why the unit of per-point times cannot be decided (see [`MessageError::TimeUnit`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum TimeUnitProblem {
    /// A time is not finite.
    #[error("a time is not finite")]
    NotFinite,
    /// No unit puts the times within a scan period of the stamp.
    #[error("no unit (s or ns, absolute or since the stamp) fits")]
    NoUnitFits,
    /// Two units fit as well as each other, placing the points at different times.
    #[error("both {} and {} fit", .first.name(), .second.name())]
    TwoUnitsFit {
        /// The unit that spreads the points most.
        first: TimeUnit,
        /// Another that fits.
        second: TimeUnit,
    },
    /// The unit decided on an earlier cloud does not fit this one.
    #[error("the unit decided earlier ({}) does not fit", .unit.name())]
    DecidedUnitDoesNotFit {
        /// The unit decided.
        unit: TimeUnit,
    },
    /// The cloud's channels differ in length (a reader fault).
    #[error("the cloud's channels differ in length")]
    ChannelLengths,
}
