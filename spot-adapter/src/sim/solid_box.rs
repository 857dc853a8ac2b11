//! The solid boxes a simulated building is made of.

use nalgebra::Point3;
use nalgebra::Vector2;

/// What a box of the building is (for statistics and pictures; ray casting treats all alike).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum BoxKind {
    /// A wall segment, floor to ceiling.
    Wall,
    /// The wall above a door, from the door's top to the ceiling.
    Lintel,
    /// A free-standing pillar or a pilaster against a corridor wall, floor to ceiling.
    Pillar,
    /// A desk, table, cabinet or crate standing on the floor.
    Furniture,
    /// An obstacle placed after the building was made ([`Building::add_box`]): a dropped box,
    /// a person.
    ///
    /// [`Building::add_box`]: crate::sim::Building::add_box
    Obstacle,
    /// The concrete slab between two floors (the ceiling below, the floor above), with a
    /// stairwell left open.
    Slab,
    /// A step of a staircase, solid down to the floor it stands on.
    Step,
}

/// An axis-aligned solid box (metres, world frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolidBox {
    /// Smallest corner.
    pub min: Point3<f64>,
    /// Largest corner.
    pub max: Point3<f64>,
    /// What it is.
    pub kind: BoxKind,
}

impl SolidBox {
    /// Whether the plan-view point `p` lies inside the box's footprint (borders included).
    #[must_use]
    pub fn contains_xy(&self, p: Vector2<f64>) -> bool {
        p.x >= self.min.x && p.x <= self.max.x && p.y >= self.min.y && p.y <= self.max.y
    }

    /// Whether every corner coordinate is finite and `min < max` on every axis.
    #[must_use]
    pub fn is_proper(&self) -> bool {
        (0..3).all(|k| {
            self.min[k].is_finite() && self.max[k].is_finite() && self.min[k] < self.max[k]
        })
    }
}

/// The handle of a box added to a building after it was made, for removing it again.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BoxId(pub(crate) u64);
