//! The frames a bag holds, as an error or a note names them when two frames it needs are not
//! joined: every transform of `/tf` and `/tf_static` (and whether those topics are in the bag at
//! all), each odometry topic's `frame_id -> child_frame_id` and each IMU topic's `frame_id`.

use std::fmt;

/// The frames a bag holds, gathered from the topics that name frames.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BagFrames {
    /// Whether the bag has a `/tf` topic.
    pub has_tf: bool,
    /// `(parent, child)` of every transform on `/tf`, sorted.
    pub tf: Vec<(String, String)>,
    /// Whether the bag has a `/tf_static` topic.
    pub has_tf_static: bool,
    /// `(parent, child)` of every transform on `/tf_static`, sorted.
    pub tf_static: Vec<(String, String)>,
    /// `(topic, frame_id, child_frame_id)` of each `nav_msgs/Odometry` topic (its first message).
    pub odometry: Vec<(String, String, String)>,
    /// `(topic, frame_id)` of each `sensor_msgs/Imu` topic (its first message).
    pub imu: Vec<(String, String)>,
}

/// `"a" -> "b", "c" -> "d"`, or `none`.
fn edges(f: &mut fmt::Formatter<'_>, edges: &[(String, String)]) -> fmt::Result {
    if edges.is_empty() {
        return write!(f, "none");
    }
    for (i, (parent, child)) in edges.iter().enumerate() {
        let sep = if i == 0 { "" } else { ", " };
        write!(f, "{sep}{parent:?} -> {child:?}")?;
    }
    Ok(())
}

impl fmt::Display for BagFrames {
    /// One line: `frames in the bag (looked at /tf, /tf_static and the odometry and IMU topics):
    /// /tf: "odom" -> "base_link"; /tf_static: not in the bag; odometry /odom: "odom" ->
    /// "base_link"; IMU /imu: "imu_link"`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "frames in the bag (looked at /tf, /tf_static and the odometry and IMU topics): /tf: "
        )?;
        if self.has_tf {
            edges(f, &self.tf)?;
        } else {
            write!(f, "not in the bag")?;
        }
        write!(f, "; /tf_static: ")?;
        if self.has_tf_static {
            edges(f, &self.tf_static)?;
        } else {
            write!(f, "not in the bag")?;
        }
        if self.odometry.is_empty() {
            write!(f, "; no odometry topic")?;
        }
        for (topic, frame, child) in &self.odometry {
            write!(f, "; odometry {topic}: {frame:?} -> {child:?}")?;
        }
        for (topic, frame) in &self.imu {
            write!(f, "; IMU {topic}: {frame:?}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absent_topics_and_empty_frames_are_said() {
        let frames = BagFrames {
            has_tf: true,
            tf: vec![("world".into(), "robot2d".into())],
            odometry: vec![("/gt".into(), "map".into(), String::new())],
            ..BagFrames::default()
        };
        assert_eq!(
            frames.to_string(),
            "frames in the bag (looked at /tf, /tf_static and the odometry and IMU topics): \
             /tf: \"world\" -> \"robot2d\"; /tf_static: not in the bag; odometry /gt: \"map\" -> \"\""
        );
    }
}
