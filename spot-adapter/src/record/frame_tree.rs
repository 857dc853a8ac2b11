//! The tf frame tree of a bag: fixed transforms from `/tf_static` and time series of moving ones
//! (from `/tf`, or a `nav_msgs/Odometry` topic), looked up between any two frames at a stamp
//! with linear interpolation of translations and spherical of rotations. A pose asked for at a
//! stamp that a series holds exactly is returned as stored.

use std::collections::{HashMap, VecDeque};

use slam_core::Pose3;

/// Stamped poses of one moving transform, in increasing stamp order.
#[derive(Clone, Debug, Default)]
pub struct PoseSeries {
    poses: VecDeque<(f64, Pose3)>,
    /// The first stamp ever pushed (kept when older poses are pruned).
    first: Option<f64>,
}

impl PoseSeries {
    /// Append a pose; one not after the last is ignored (tf's own rule for out-of-order data is
    /// to drop it too).
    pub fn push(&mut self, stamp: f64, pose: Pose3) {
        if self.poses.back().is_none_or(|&(last, _)| stamp > last) {
            self.poses.push_back((stamp, pose));
            self.first.get_or_insert(stamp);
        }
    }

    /// The first stamp ever pushed.
    #[must_use]
    pub fn first_stamp(&self) -> Option<f64> {
        self.first
    }

    /// The newest stamp.
    #[must_use]
    pub fn last_stamp(&self) -> Option<f64> {
        self.poses.back().map(|p| p.0)
    }

    /// The pose at `stamp`, interpolated between the two around it; `None` outside the series.
    #[must_use]
    pub fn at(&self, stamp: f64) -> Option<Pose3> {
        let i = self.poses.partition_point(|p| p.0 < stamp);
        let &(t1, p1) = self.poses.get(i)?;
        // A stamp held exactly gives the stored pose, bit for bit.
        #[allow(clippy::float_cmp)]
        if t1 == stamp {
            return Some(p1);
        }
        let &(t0, p0) = self.poses.get(i.checked_sub(1)?)?;
        Some(interpolate(&p0, &p1, (stamp - t0) / (t1 - t0)))
    }

    /// Forget poses not needed for stamps from `stamp` on (one before it is kept).
    pub fn prune_before(&mut self, stamp: f64) {
        while self.poses.len() > 1 && self.poses[1].0 <= stamp {
            self.poses.pop_front();
        }
    }
}

/// `a` moved a fraction `s` (0 to 1) of the way to `b`.
fn interpolate(a: &Pose3, b: &Pose3, s: f64) -> Pose3 {
    let t = a.translation.vector.lerp(&b.translation.vector, s);
    let r = a.rotation.slerp(&b.rotation, s);
    Pose3::from_parts(t.into(), r)
}

/// One edge of the tree: the parent and how the child is held.
#[derive(Clone, Debug)]
enum Edge {
    Fixed(Pose3),
    Moving(PoseSeries),
}

/// Frames joined by transforms, each child with one parent.
#[derive(Clone, Debug, Default)]
pub struct FrameTree {
    /// child -> (parent, `parent_T_child`)
    edges: HashMap<String, (String, Edge)>,
}

impl FrameTree {
    /// Set the fixed `parent_T_child`.
    pub fn set_fixed(&mut self, parent: &str, child: &str, parent_t_child: Pose3) {
        self.edges.insert(
            child.to_owned(),
            (parent.to_owned(), Edge::Fixed(parent_t_child)),
        );
    }

    /// Add a moving `parent_T_child` at `stamp`. A child that changes parent starts afresh.
    pub fn push_moving(&mut self, parent: &str, child: &str, stamp: f64, parent_t_child: Pose3) {
        let entry = self
            .edges
            .entry(child.to_owned())
            .or_insert_with(|| (parent.to_owned(), Edge::Moving(PoseSeries::default())));
        if entry.0 != parent || !matches!(entry.1, Edge::Moving(_)) {
            *entry = (parent.to_owned(), Edge::Moving(PoseSeries::default()));
        }
        if let Edge::Moving(series) = &mut entry.1 {
            series.push(stamp, parent_t_child);
        }
    }

    /// The frames from `frame` up to its root, each with its parent edge.
    fn chain<'a>(&'a self, frame: &'a str) -> Vec<(&'a str, Option<&'a (String, Edge)>)> {
        let mut out = vec![];
        let mut at = frame;
        // A malformed tree may loop; a chain never holds more frames than the tree.
        for _ in 0..=self.edges.len() {
            let edge = self.edges.get(at);
            out.push((at, edge));
            match edge {
                Some((parent, _)) => at = parent,
                None => break,
            }
        }
        out
    }

    /// `root_T_frame` along `chain` up to (not including) index `end`.
    fn compose(chain: &[(&str, Option<&(String, Edge)>)], end: usize, stamp: f64) -> Option<Pose3> {
        let mut pose = Pose3::identity();
        for (_, edge) in &chain[..end] {
            let (_, edge) = (*edge)?;
            let step = match edge {
                Edge::Fixed(p) => *p,
                Edge::Moving(s) => s.at(stamp)?,
            };
            pose = step * pose;
        }
        Some(pose)
    }

    /// The chains up from `child` and `parent`, and how many edges of each lie below their
    /// nearest common ancestor; `None` when they are not joined.
    #[allow(clippy::type_complexity)]
    fn joined<'a>(
        &'a self,
        parent: &'a str,
        child: &'a str,
    ) -> Option<(
        Vec<(&'a str, Option<&'a (String, Edge)>)>,
        usize,
        Vec<(&'a str, Option<&'a (String, Edge)>)>,
        usize,
    )> {
        let up_child = self.chain(child);
        let up_parent = self.chain(parent);
        let (i, j) = up_child
            .iter()
            .enumerate()
            .find_map(|(i, (f, _))| up_parent.iter().position(|(g, _)| g == f).map(|j| (i, j)))?;
        Some((up_child, i, up_parent, j))
    }

    /// `parent_T_child` at `stamp` through the tree (any two frames with a common ancestor);
    /// `None` when they are not joined or a moving edge does not cover `stamp`.
    #[must_use]
    pub fn lookup(&self, parent: &str, child: &str, stamp: f64) -> Option<Pose3> {
        if parent == child {
            return Some(Pose3::identity());
        }
        let (up_child, i, up_parent, j) = self.joined(parent, child)?;
        // ancestor_T_child and ancestor_T_parent.
        let a_t_child = Self::compose(&up_child, i, stamp)?;
        let a_t_parent = Self::compose(&up_parent, j, stamp)?;
        Some(a_t_parent.inverse() * a_t_child)
    }

    /// Whether a chain of edges (fixed or moving, whatever the stamps they cover) joins `a` and
    /// `b`; a frame is joined to itself.
    #[must_use]
    pub fn is_joined(&self, a: &str, b: &str) -> bool {
        a == b || self.joined(a, b).is_some()
    }

    /// Whether `parent` and `child` are joined by fixed edges only.
    #[must_use]
    pub fn is_fixed_between(&self, parent: &str, child: &str) -> bool {
        parent == child
            || self.joined(parent, child).is_some_and(|(c, i, p, j)| {
                c[..i]
                    .iter()
                    .chain(&p[..j])
                    .all(|(_, e)| matches!(e, Some((_, Edge::Fixed(_)))))
            })
    }

    /// The child frames of moving edges whose parent is `parent`.
    #[must_use]
    pub fn moving_children(&self, parent: &str) -> Vec<&str> {
        let mut out: Vec<&str> = self
            .edges
            .iter()
            .filter(|(_, (p, e))| p == parent && matches!(e, Edge::Moving(_)))
            .map(|(c, _)| c.as_str())
            .collect();
        out.sort_unstable();
        out
    }

    /// The fixed edges: (parent, child, `parent_T_child`).
    pub fn fixed_edges(&self) -> impl Iterator<Item = (&str, &str, Pose3)> {
        self.edges
            .iter()
            .filter_map(|(child, (parent, edge))| match edge {
                Edge::Fixed(p) => Some((parent.as_str(), child.as_str(), *p)),
                Edge::Moving(_) => None,
            })
    }

    /// The moving edges: (parent, child).
    pub fn moving_edges(&self) -> impl Iterator<Item = (&str, &str)> {
        self.edges
            .iter()
            .filter(|(_, (_, edge))| matches!(edge, Edge::Moving(_)))
            .map(|(child, (parent, _))| (parent.as_str(), child.as_str()))
    }

    /// Forget moving poses not needed from `stamp` on.
    pub fn prune_before(&mut self, stamp: f64) {
        for (_, edge) in self.edges.values_mut() {
            if let Edge::Moving(s) = edge {
                s.prune_before(stamp);
            }
        }
    }

    /// The stamps from which and up to which every moving edge between `parent` and `child` is
    /// known (`(-inf, inf)` when none moves); `None` when they are not joined.
    #[must_use]
    pub fn known_span(&self, parent: &str, child: &str) -> Option<(f64, f64)> {
        let (c, i, p, j) = self.joined(parent, child)?;
        let (mut from, mut until) = (f64::NEG_INFINITY, f64::INFINITY);
        for (_, edge) in c[..i].iter().chain(&p[..j]) {
            if let Some((_, Edge::Moving(s))) = edge {
                from = from.max(s.first_stamp().unwrap_or(f64::INFINITY));
                until = until.min(s.last_stamp().unwrap_or(f64::NEG_INFINITY));
            }
        }
        Some((from, until))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    fn pose(x: f64, yaw: f64) -> Pose3 {
        Pose3::from_parts(
            Translation3::new(x, 0.0, 0.0),
            UnitQuaternion::from_euler_angles(0.0, 0.0, yaw),
        )
    }

    #[test]
    fn lookups_compose_and_interpolate() {
        let mut tree = FrameTree::default();
        tree.set_fixed("base_link", "lidar", pose(0.1, 0.0));
        tree.push_moving("odom", "base_link", 1.0, pose(0.0, 0.0));
        tree.push_moving("odom", "base_link", 2.0, pose(2.0, 1.0));
        // Exact stamps come back as stored; between them, halfway.
        let at2 = tree.lookup("odom", "base_link", 2.0).unwrap();
        assert_eq!(at2, pose(2.0, 1.0));
        let mid = tree.lookup("odom", "lidar", 1.5).unwrap();
        let expect = pose(1.0, 0.5) * pose(0.1, 0.0);
        assert!((mid.translation.vector - expect.translation.vector).norm() < 1e-12);
        assert!(mid.rotation.angle_to(&expect.rotation) < 1e-12);
        // The inverse direction, through the common ancestor.
        let back = tree.lookup("lidar", "odom", 1.5).unwrap();
        assert!((back * mid).translation.vector.norm() < 1e-12);
        assert!(tree.lookup("odom", "base_link", 2.5).is_none());
        assert!(tree.lookup("odom", "camera", 1.5).is_none());
        assert!(tree.is_joined("lidar", "odom") && tree.is_joined("camera", "camera"));
        assert!(!tree.is_joined("odom", "camera"));
        assert_eq!(
            tree.moving_edges().collect::<Vec<_>>(),
            vec![("odom", "base_link")]
        );
        tree.prune_before(1.8);
        assert_eq!(tree.known_span("odom", "lidar"), Some((1.0, 2.0)));
        assert!(tree.is_fixed_between("lidar", "base_link"));
        assert!(!tree.is_fixed_between("odom", "lidar"));
        assert_eq!(tree.moving_children("odom"), vec!["base_link"]);
    }
}
