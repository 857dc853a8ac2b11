//! The ROS messages a recording is made of, decoded from either wire ([`WireReader`]):
//! `sensor_msgs/PointCloud2`, `nav_msgs/Odometry`, `tf2_msgs/TFMessage`, `sensor_msgs/Imu`.
//! Field order follows the message definitions (identical in ROS 1 and ROS 2 but for the
//! `std_msgs/Header`, which lost its sequence number and got a signed second in ROS 2).

use nalgebra::{Translation3, Vector3};
use slam_core::{Pose3, quaternion_from_xyzw};

use crate::record::MessageError;
use crate::record::wire::{Wire, WireReader};

/// The message types a bag reader understands, by their ROS name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RosMessageType {
    /// `sensor_msgs/PointCloud2`.
    PointCloud2,
    /// `nav_msgs/Odometry`.
    Odometry,
    /// `tf2_msgs/TFMessage` (on `/tf` and `/tf_static`).
    TfMessage,
    /// `sensor_msgs/Imu`.
    Imu,
}

impl RosMessageType {
    /// The type named `name`, in ROS 1 (`sensor_msgs/PointCloud2`) or ROS 2
    /// (`sensor_msgs/msg/PointCloud2`) spelling; `None` for any other.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        match name.replace("/msg/", "/").as_str() {
            "sensor_msgs/PointCloud2" => Some(Self::PointCloud2),
            "nav_msgs/Odometry" => Some(Self::Odometry),
            "tf2_msgs/TFMessage" => Some(Self::TfMessage),
            "sensor_msgs/Imu" => Some(Self::Imu),
            _ => None,
        }
    }

    /// The ROS 1 name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::PointCloud2 => "sensor_msgs/PointCloud2",
            Self::Odometry => "nav_msgs/Odometry",
            Self::TfMessage => "tf2_msgs/TFMessage",
            Self::Imu => "sensor_msgs/Imu",
        }
    }
}

/// `std_msgs/Header` without the ROS 1 sequence number.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    /// Seconds (`sec + nanosec * 1e-9`).
    pub stamp: f64,
    /// The frame the data is in.
    pub frame_id: String,
}

impl Header {
    pub(crate) fn decode(r: &mut WireReader<'_>) -> Result<Self, MessageError> {
        let stamp = if r.is_ros1() {
            let _seq = r.u32()?;
            f64::from(r.u32()?) + f64::from(r.u32()?) * 1e-9
        } else {
            f64::from(r.i32()?) + f64::from(r.u32()?) * 1e-9
        };
        Ok(Self {
            stamp,
            frame_id: r.string()?,
        })
    }
}

/// `sensor_msgs/PointField`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PointField {
    /// The field's name (`x`, `intensity`, `t`, ...).
    pub name: String,
    /// Byte offset inside a point.
    pub offset: u32,
    /// Datatype code: 1 INT8, 2 UINT8, 3 INT16, 4 UINT16, 5 INT32, 6 UINT32, 7 FLOAT32,
    /// 8 FLOAT64.
    pub datatype: u8,
    /// Elements (1 for a scalar).
    pub count: u32,
}

/// `sensor_msgs/PointCloud2` with its data borrowed from the payload.
#[derive(Clone, Debug, PartialEq)]
pub struct PointCloud2<'a> {
    /// Stamp and frame.
    pub header: Header,
    /// Rows (1 for an unordered cloud).
    pub height: u32,
    /// Points per row.
    pub width: u32,
    /// The fields of one point.
    pub fields: Vec<PointField>,
    /// Byte order of the data.
    pub is_bigendian: bool,
    /// Bytes per point.
    pub point_step: u32,
    /// Bytes per row.
    pub row_step: u32,
    /// The points, row after row.
    pub data: &'a [u8],
}

impl<'a> PointCloud2<'a> {
    /// The message serialised in `data` (one bag payload) in `wire`'s serialisation, its point
    /// data borrowed from `data`. Bytes after the message are ignored.
    ///
    /// # Errors
    /// [`MessageError::Truncated`] when `data` ends inside the message or a count claims more
    /// than it holds, [`MessageError::InvalidString`] for a name that is not UTF-8 (or a CDR
    /// string without its NUL), [`MessageError::Encapsulation`] for a CDR header that is not
    /// plain CDR.
    pub fn parse(data: &'a [u8], wire: Wire) -> Result<Self, MessageError> {
        Self::decode(&mut WireReader::new(data, wire)?)
    }

    pub(crate) fn decode(r: &mut WireReader<'a>) -> Result<Self, MessageError> {
        let header = Header::decode(r)?;
        let height = r.u32()?;
        let width = r.u32()?;
        // A field takes at least 13 bytes on either wire.
        let n = r.count(13)?;
        let mut fields = Vec::with_capacity(n);
        for _ in 0..n {
            fields.push(PointField {
                name: r.string()?,
                offset: r.u32()?,
                datatype: r.u8()?,
                count: r.u32()?,
            });
        }
        Ok(Self {
            header,
            height,
            width,
            fields,
            is_bigendian: r.bool()?,
            point_step: r.u32()?,
            row_step: r.u32()?,
            data: r.byte_sequence()?,
        })
    }
}

/// A `geometry_msgs/Pose` or `Transform` (translation then xyzw quaternion).
fn decode_pose(r: &mut WireReader<'_>, what: &'static str) -> Result<Pose3, MessageError> {
    let t = r.f64_array::<3>()?;
    let q = r.f64_array::<4>()?;
    let rotation = quaternion_from_xyzw(q).ok_or(MessageError::InvalidPose { what })?;
    if !t.iter().all(|v| v.is_finite()) {
        return Err(MessageError::InvalidPose { what });
    }
    Ok(Pose3::from_parts(
        Translation3::new(t[0], t[1], t[2]),
        rotation,
    ))
}

/// `nav_msgs/Odometry`: the pose part (covariance and twist are not used).
#[derive(Clone, Debug, PartialEq)]
pub struct Odometry {
    /// Stamp and the odometry frame (`header.frame_id`, e.g. `odom`).
    pub header: Header,
    /// The body frame (e.g. `base_link`).
    pub child_frame_id: String,
    /// `odom_T_body`.
    pub pose: Pose3,
}

impl Odometry {
    /// The message serialised in `data` in `wire`'s serialisation (the pose part; covariance and
    /// twist after it are not read).
    ///
    /// # Errors
    /// As [`PointCloud2::parse`]; [`MessageError::InvalidPose`] for a non-finite translation or
    /// a quaternion that cannot be normalised.
    pub fn parse(data: &[u8], wire: Wire) -> Result<Self, MessageError> {
        Self::decode(&mut WireReader::new(data, wire)?)
    }

    pub(crate) fn decode(r: &mut WireReader<'_>) -> Result<Self, MessageError> {
        Ok(Self {
            header: Header::decode(r)?,
            child_frame_id: r.string()?,
            pose: decode_pose(r, "odometry pose")?,
        })
    }
}

/// `geometry_msgs/TransformStamped`: `parent_T_child`.
#[derive(Clone, Debug, PartialEq)]
pub struct TransformStamped {
    /// Stamp and the parent frame.
    pub header: Header,
    /// The child frame.
    pub child_frame_id: String,
    /// `parent_T_child`.
    pub transform: Pose3,
}

impl TransformStamped {
    /// The transforms of the `tf2_msgs/TFMessage` serialised in `data` in `wire`'s
    /// serialisation.
    ///
    /// # Errors
    /// As [`Odometry::parse`].
    pub fn parse_tf_message(data: &[u8], wire: Wire) -> Result<Vec<Self>, MessageError> {
        decode_tf_message(&mut WireReader::new(data, wire)?)
    }
}

/// `tf2_msgs/TFMessage`: its transforms.
pub(crate) fn decode_tf_message(
    r: &mut WireReader<'_>,
) -> Result<Vec<TransformStamped>, MessageError> {
    // A transform takes at least 7 doubles.
    let n = r.count(56)?;
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        out.push(TransformStamped {
            header: Header::decode(r)?,
            child_frame_id: r.string()?,
            transform: decode_pose(r, "tf transform")?,
        });
    }
    Ok(out)
}

/// `sensor_msgs/Imu`: its angular velocity gives the samples' gyro orientation
/// ([`GyroIntegrator`](crate::record::GyroIntegrator)); the rest is decoded for later use.
#[derive(Clone, Debug, PartialEq)]
pub struct ImuReading {
    /// Seconds.
    pub stamp: f64,
    /// The IMU's frame.
    pub frame_id: String,
    /// Orientation `[qx, qy, qz, qw]`, `None` when the message marks it unknown (covariance
    /// element 0 is -1).
    pub orientation: Option<[f64; 4]>,
    /// Angular velocity (rad/s) in the IMU frame.
    pub angular_velocity: Vector3<f64>,
    /// Linear acceleration (m/s^2) in the IMU frame.
    pub linear_acceleration: Vector3<f64>,
}

impl ImuReading {
    /// The message serialised in `data` in `wire`'s serialisation.
    ///
    /// # Errors
    /// As [`PointCloud2::parse`].
    pub fn parse(data: &[u8], wire: Wire) -> Result<Self, MessageError> {
        Self::decode(&mut WireReader::new(data, wire)?)
    }

    pub(crate) fn decode(r: &mut WireReader<'_>) -> Result<Self, MessageError> {
        let header = Header::decode(r)?;
        let q = r.f64_array::<4>()?;
        let q_cov = r.f64_array::<9>()?;
        let w = r.f64_array::<3>()?;
        let _w_cov = r.f64_array::<9>()?;
        let a = r.f64_array::<3>()?;
        // sensor_msgs/Imu marks an unknown orientation by exactly -1 in its covariance.
        #[allow(clippy::float_cmp)]
        let known = q_cov[0] != -1.0;
        Ok(Self {
            stamp: header.stamp,
            frame_id: header.frame_id,
            orientation: known.then_some(q),
            angular_velocity: Vector3::from(w),
            linear_acceleration: Vector3::from(a),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn type_names_in_both_spellings() {
        assert_eq!(
            RosMessageType::from_name("sensor_msgs/msg/PointCloud2"),
            Some(RosMessageType::PointCloud2)
        );
        assert_eq!(
            RosMessageType::from_name("tf2_msgs/TFMessage"),
            Some(RosMessageType::TfMessage)
        );
        assert_eq!(RosMessageType::from_name("std_msgs/String"), None);
    }

    #[test]
    fn ros1_odometry_with_a_bad_quaternion_is_an_error() {
        let mut data = vec![1, 0, 0, 0, 5, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0];
        data.extend_from_slice(&[0, 0, 0, 0]); // child_frame_id ""
        for v in [0.0f64, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0] {
            data.extend_from_slice(&v.to_le_bytes());
        }
        let mut r = WireReader::new(&data, Wire::Ros1).unwrap();
        assert!(matches!(
            Odometry::decode(&mut r),
            Err(MessageError::InvalidPose { .. })
        ));
    }
}
