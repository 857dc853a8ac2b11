//! A robot's frame tree at one instant (Spot's `FrameTreeSnapshot`: each frame's pose in its
//! parent) and the `a_T_b` lookup between any two of its frames.

use std::collections::HashMap;

use nalgebra::{Quaternion, Translation3, UnitQuaternion};
use slam_core::Pose3;
use thiserror::Error;

use crate::grpc::api;

/// Why a frame lookup failed.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum FrameError {
    /// The snapshot has no frame of this name.
    #[error("the frame tree has no frame {frame:?}")]
    UnknownFrame {
        /// The frame asked for.
        frame: String,
    },
    /// The two frames are in separate trees: no chain of transforms joins them.
    #[error("frames {a:?} and {b:?} are not connected in the frame tree")]
    Disconnected {
        /// The first frame.
        a: String,
        /// The second frame.
        b: String,
    },
    /// Following parents from this frame comes back to it.
    #[error("the frame tree has a cycle through {frame:?}")]
    Cycle {
        /// A frame on the cycle.
        frame: String,
    },
    /// A frame's pose in its parent is missing, non-finite or has a zero quaternion.
    #[error("frame {frame:?} has no valid pose in its parent")]
    BadTransform {
        /// The child frame of the bad edge.
        frame: String,
    },
}

/// Frames and their parents: `parent_T_child` per child; a frame with an empty parent name (or
/// only named as a parent) is a root.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameTree {
    parent_of: HashMap<String, (String, Pose3)>,
}

impl FrameTree {
    /// An empty tree.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Add (or replace) `child` with its pose in `parent`; an empty `parent` makes it a root.
    pub fn insert(
        &mut self,
        child: impl Into<String>,
        parent: impl Into<String>,
        parent_t_child: Pose3,
    ) {
        self.parent_of
            .insert(child.into(), (parent.into(), parent_t_child));
    }

    /// Whether the tree names `frame` (as a child or a parent).
    #[must_use]
    pub fn contains(&self, frame: &str) -> bool {
        self.parent_of.contains_key(frame) || self.parent_of.values().any(|(p, _)| p == frame)
    }

    /// The pose of frame `b` in frame `a` (`a_T_b`: maps points in `b` to `a`).
    ///
    /// # Errors
    /// [`FrameError::UnknownFrame`] for a frame the tree does not name,
    /// [`FrameError::Disconnected`] when they have different roots, [`FrameError::Cycle`] when
    /// the parents loop.
    pub fn a_t_b(&self, a: &str, b: &str) -> Result<Pose3, FrameError> {
        let (root_a, root_t_a) = self.root_t(a)?;
        let (root_b, root_t_b) = self.root_t(b)?;
        if root_a != root_b {
            return Err(FrameError::Disconnected {
                a: a.to_owned(),
                b: b.to_owned(),
            });
        }
        Ok(root_t_a.inverse() * root_t_b)
    }

    /// The root above `frame` and `frame`'s pose in it.
    fn root_t<'a>(&'a self, frame: &'a str) -> Result<(&'a str, Pose3), FrameError> {
        if !self.contains(frame) {
            return Err(FrameError::UnknownFrame {
                frame: frame.to_owned(),
            });
        }
        let mut root_t_frame = Pose3::identity();
        let mut current = frame;
        // A chain longer than the number of edges must revisit a frame.
        for _ in 0..=self.parent_of.len() {
            match self.parent_of.get(current) {
                Some((parent, parent_t_child)) if !parent.is_empty() => {
                    root_t_frame = parent_t_child * root_t_frame;
                    current = parent;
                }
                _ => return Ok((current, root_t_frame)),
            }
        }
        Err(FrameError::Cycle {
            frame: frame.to_owned(),
        })
    }

    /// The tree a snapshot describes.
    pub(crate) fn from_snapshot(snapshot: &api::FrameTreeSnapshot) -> Result<Self, FrameError> {
        let mut tree = Self::new();
        for (child, edge) in &snapshot.child_to_parent_edge_map {
            let pose = if edge.parent_frame_name.is_empty() {
                Pose3::identity()
            } else {
                edge.parent_tform_child
                    .as_ref()
                    .and_then(pose_from_wire)
                    .ok_or_else(|| FrameError::BadTransform {
                        frame: child.clone(),
                    })?
            };
            tree.insert(child.clone(), edge.parent_frame_name.clone(), pose);
        }
        Ok(tree)
    }
}

/// An `SE3Pose` as a pose: finite numbers and a non-zero quaternion (normalised here), or none.
pub(crate) fn pose_from_wire(pose: &api::Se3Pose) -> Option<Pose3> {
    let p = pose.position.unwrap_or_default();
    let q = pose.rotation.unwrap_or_default();
    let values = [p.x, p.y, p.z, q.w, q.x, q.y, q.z];
    if values.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let quaternion = Quaternion::new(q.w, q.x, q.y, q.z);
    if quaternion.norm() < 1e-9 {
        return None;
    }
    Some(Pose3::from_parts(
        Translation3::new(p.x, p.y, p.z),
        UnitQuaternion::from_quaternion(quaternion),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn pose(x: f64, y: f64, yaw: f64) -> Pose3 {
        Pose3::new(Vector3::new(x, y, 0.0), Vector3::new(0.0, 0.0, yaw))
    }

    /// body is the root; odom and the LiDAR hang below it, vision below odom.
    fn spot_like() -> FrameTree {
        let odom_t_body = pose(1.0, 2.0, 0.3);
        let mut tree = FrameTree::new();
        tree.insert("body", "", Pose3::identity());
        tree.insert("odom", "body", odom_t_body.inverse());
        tree.insert("vision", "odom", pose(0.5, -0.25, 0.1));
        tree.insert("velodyne", "body", pose(-0.05, 0.0, 0.0));
        tree
    }

    #[test]
    fn a_lookup_composes_the_chain_through_the_common_root() {
        let tree = spot_like();
        let odom_t_body = tree.a_t_b("odom", "body").unwrap();
        assert!((odom_t_body.translation.vector - Vector3::new(1.0, 2.0, 0.0)).norm() < 1e-12);
        // vision_T_velodyne = (odom_T_vision)^-1 * odom_T_body * body_T_velodyne
        let expected =
            pose(0.5, -0.25, 0.1).inverse() * pose(1.0, 2.0, 0.3) * pose(-0.05, 0.0, 0.0);
        let got = tree.a_t_b("vision", "velodyne").unwrap();
        assert!((got.to_homogeneous() - expected.to_homogeneous()).norm() < 1e-12);
        let back = tree.a_t_b("velodyne", "vision").unwrap();
        assert!(
            ((back * got).to_homogeneous() - Pose3::identity().to_homogeneous()).norm() < 1e-12
        );
        let same = tree.a_t_b("odom", "odom").unwrap();
        assert!((same.to_homogeneous() - Pose3::identity().to_homogeneous()).norm() < 1e-12);
    }

    #[test]
    fn unknown_disconnected_and_cyclic_frames_are_named_errors() {
        let mut tree = spot_like();
        assert_eq!(
            tree.a_t_b("odom", "hand"),
            Err(FrameError::UnknownFrame {
                frame: "hand".into()
            })
        );
        tree.insert("dock", "station", Pose3::identity());
        assert_eq!(
            tree.a_t_b("odom", "dock"),
            Err(FrameError::Disconnected {
                a: "odom".into(),
                b: "dock".into()
            })
        );
        tree.insert("a", "b", Pose3::identity());
        tree.insert("b", "a", Pose3::identity());
        assert!(matches!(
            tree.a_t_b("a", "odom"),
            Err(FrameError::Cycle { .. })
        ));
    }

    #[test]
    fn a_snapshot_with_a_zero_quaternion_is_refused() {
        let mut snapshot = api::FrameTreeSnapshot::default();
        snapshot.child_to_parent_edge_map.insert(
            "odom".into(),
            api::frame_tree_snapshot::ParentEdge {
                parent_frame_name: "body".into(),
                parent_tform_child: Some(api::Se3Pose::default()),
            },
        );
        assert_eq!(
            FrameTree::from_snapshot(&snapshot),
            Err(FrameError::BadTransform {
                frame: "odom".into()
            })
        );
    }
}
