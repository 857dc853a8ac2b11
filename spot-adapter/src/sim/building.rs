//! A simulated office building: a ring corridor with rooms on both sides, doors,
//! corridor pilasters, pillars and furniture, as axis-aligned boxes between a floor and a ceiling.
//!
//! Layout (plan view, x east, y north, origin at the outer south-west corner):
//!
//! ```text
//! +------+--------+------+-----+   outer band: rooms between the outer wall and the corridor
//! |      |        |      |     |
//! +--D---+---D----+--D---+--D--+
//! |  ring corridor (loop)      |
//! |  +---D---+---D----+---+    |
//! |  | core rooms (two rows) | |
//! |  +---D---+---D----+---+    |
//! +--D---+---D----+--D---+--D--+
//! |      |        |      |     |
//! +------+--------+------+-----+
//! ```
//!
//! Every room has one door onto the corridor, so the free space is connected. Pillars and
//! furniture never stand in the corridor or in front of a door.
//!
//! Obstacles can be added and removed after the building was made ([`Building::add_box`],
//! [`Building::remove_box`]); the LiDAR sees them and the floor plan counts them.

use nalgebra::{Point3, Vector2, Vector3};

use crate::sim::SimError;
use crate::sim::ray_cast::{BoxGrid, HitTarget, RayHit};
use crate::sim::solid_box::{BoxId, SolidBox};
use crate::sim::staircase::Staircase;

/// A room: its rectangle between wall centre lines and its door onto the corridor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Room {
    /// South-west corner (wall centre lines, metres).
    pub min: Vector2<f64>,
    /// North-east corner (wall centre lines, metres).
    pub max: Vector2<f64>,
    /// Centre of the door opening, on the wall shared with the corridor.
    pub door: Vector2<f64>,
    /// Unit vector from the door into the room.
    pub inward: Vector2<f64>,
}

impl Room {
    /// A point 1 m inside the room straight through the door; it is always free floor.
    #[must_use]
    pub fn entry_point(&self) -> Vector2<f64> {
        self.door + self.inward
    }
}

/// The generated building: boxes, rooms, the corridor loop and a ray-casting index.
///
/// ```
/// use nalgebra::{Point3, Vector3};
/// use spot_adapter::sim::{Building, BuildingConfig, HitTarget};
///
/// let building = Building::generate(42, &BuildingConfig::default())?;
/// let corner = building.corridor_loop()[0];
/// assert!(!building.is_obstacle(corner), "the corridor is free");
/// assert!(building.is_obstacle(nalgebra::Vector2::new(0.05, 5.0)), "the outer wall is not");
///
/// // Straight down from 0.8 m: the floor, 0.8 m away.
/// let origin = Point3::new(corner.x, corner.y, 0.8);
/// let hit = building.cast_ray(&origin, &-Vector3::z(), 100.0).unwrap();
/// assert_eq!(hit.target, HitTarget::Floor);
/// assert!((hit.range - 0.8).abs() < 1e-12);
///
/// // The ground-truth occupancy grid at 10 cm agrees.
/// let grid = building.occupancy_grid(0.1)?;
/// let (x, y) = grid.geometry().cell_coords(corner);
/// assert!(grid.is_free_signed(x, y));
/// # Ok::<(), spot_adapter::sim::SimError>(())
/// ```
#[derive(Clone, Debug)]
pub struct Building {
    pub(crate) boxes: Vec<SolidBox>,
    pub(crate) rooms: Vec<Room>,
    pub(crate) size: Vector2<f64>,
    pub(crate) ceiling_height: f64,
    pub(crate) corridor_loop: [Vector2<f64>; 4],
    pub(crate) corridor_width: f64,
    pub(crate) index: BoxGrid,
    /// Floors (1 to 3), each `storey_height` above the one below.
    pub(crate) floors: usize,
    /// Floor-to-floor height (metres): the ceiling height plus the slab.
    pub(crate) storey_height: f64,
    /// The flight from floor `k` to floor `k + 1` at index `k`.
    pub(crate) staircases: Vec<Staircase>,
    /// The rooms of floor `k + 1` at index `k`.
    pub(crate) upper_rooms: Vec<Vec<Room>>,
    /// Boxes of the generated structure; those after it were added, with the ids in `added`.
    generated: usize,
    added: Vec<BoxId>,
    next_id: u64,
}

impl Building {
    /// The building from the generator's parts, with its ray-casting index.
    pub(crate) fn from_generated(
        boxes: Vec<SolidBox>,
        rooms: Vec<Room>,
        size: Vector2<f64>,
        ceiling_height: f64,
        corridor_loop: [Vector2<f64>; 4],
        corridor_width: f64,
    ) -> Self {
        let index = BoxGrid::new(&boxes, 1.0);
        Self {
            generated: boxes.len(),
            boxes,
            rooms,
            size,
            ceiling_height,
            corridor_loop,
            corridor_width,
            index,
            floors: 1,
            storey_height: ceiling_height,
            staircases: Vec::new(),
            upper_rooms: Vec::new(),
            added: Vec::new(),
            next_id: 0,
        }
    }

    /// Place `solid` in the building (a dropped box, a person standing): from now on the LiDAR
    /// sees it, [`Building::is_obstacle`] and [`Building::clearance`] count it when its bottom
    /// is below [`OBSTACLE_HEIGHT`](crate::sim::OBSTACLE_HEIGHT), and so does a commanded
    /// robot's collision check. Returns the handle to remove it with.
    ///
    /// # Errors
    /// [`SimError::InvalidBox`] unless every corner coordinate is finite and `min < max` on
    /// every axis.
    pub fn add_box(&mut self, solid: SolidBox) -> Result<BoxId, SimError> {
        if !solid.is_proper() {
            return Err(SimError::InvalidBox);
        }
        let id = BoxId(self.next_id);
        self.next_id += 1;
        self.boxes.push(solid);
        self.added.push(id);
        self.index = BoxGrid::new(&self.boxes, 1.0);
        Ok(id)
    }

    /// Take the box added as `id` out of the building again; `None` when no such box is there
    /// (never added, or already removed). Boxes added after it move down by one in
    /// [`Building::boxes`].
    pub fn remove_box(&mut self, id: BoxId) -> Option<SolidBox> {
        let k = self.added.iter().position(|&a| a == id)?;
        self.added.remove(k);
        let solid = self.boxes.remove(self.generated + k);
        self.index = BoxGrid::new(&self.boxes, 1.0);
        Some(solid)
    }

    /// Move the box added as `id` to `solid`'s place (a walking person), keeping its handle.
    ///
    /// # Errors
    /// [`SimError::InvalidBox`] for a malformed box or an `id` not in the building.
    pub fn move_box(&mut self, id: BoxId, solid: SolidBox) -> Result<(), SimError> {
        let k = self
            .added
            .iter()
            .position(|&a| a == id)
            .filter(|_| solid.is_proper())
            .ok_or(SimError::InvalidBox)?;
        self.boxes[self.generated + k] = solid;
        self.index = BoxGrid::new(&self.boxes, 1.0);
        Ok(())
    }

    /// The nearest surface along a ray from `origin` in the unit direction `dir`, within
    /// `max_range` metres; `None` when nothing lies that close.
    #[must_use]
    pub fn cast_ray(
        &self,
        origin: &Point3<f64>,
        dir: &Vector3<f64>,
        max_range: f64,
    ) -> Option<RayHit> {
        let mut limit = max_range;
        let mut target = None;
        if dir.z < 0.0 {
            let t = -origin.z / dir.z;
            if t >= 0.0 && t < limit {
                limit = t;
                target = Some(HitTarget::Floor);
            }
        } else if dir.z > 0.0 {
            let t = (self.top_ceiling() - origin.z) / dir.z;
            if t >= 0.0 && t < limit {
                limit = t;
                target = Some(HitTarget::Ceiling);
            }
        }
        if let Some((t, i)) = self.index.cast(origin, dir, limit) {
            return Some(RayHit {
                range: t,
                target: HitTarget::Box(i),
            });
        }
        target.map(|target| RayHit {
            range: limit,
            target,
        })
    }

    /// Every box: the generated walls, lintels, pillars and furniture, then the added ones in
    /// the order they were added.
    #[must_use]
    pub fn boxes(&self) -> &[SolidBox] {
        &self.boxes
    }

    /// The ground floor's rooms, each with its door onto the corridor.
    #[must_use]
    pub fn rooms(&self) -> &[Room] {
        &self.rooms
    }

    /// Floor `floor`'s rooms (its own round the corridor ring, the core's inside it); none for
    /// a floor the building does not have.
    #[must_use]
    pub fn rooms_on(&self, floor: usize) -> &[Room] {
        match floor {
            0 => &self.rooms,
            k if k < self.floors => self
                .upper_rooms
                .get(k - 1)
                .map_or(&self.rooms, Vec::as_slice),
            _ => &[],
        }
    }

    /// Outer size (x, y) in metres; the building spans `[0, size.x] x [0, size.y]`.
    #[must_use]
    pub fn size(&self) -> Vector2<f64> {
        self.size
    }

    /// Ceiling height (metres) above each floor; the ground floor is at z = 0.
    #[must_use]
    pub fn ceiling_height(&self) -> f64 {
        self.ceiling_height
    }

    /// Number of floors, 1 unless [`BuildingConfig::floors`](crate::sim::BuildingConfig)
    /// asked for more.
    #[must_use]
    pub fn floors(&self) -> usize {
        self.floors
    }

    /// Height of floor `k` (metres): `k` storeys (the ceiling height plus a 0.2 m slab) above
    /// the ground floor.
    #[must_use]
    pub fn floor_height(&self, k: usize) -> f64 {
        k as f64 * self.storey_height
    }

    /// The floor nearest height `z` (metres).
    #[must_use]
    pub fn floor_of_height(&self, z: f64) -> usize {
        if self.floors <= 1 || self.storey_height <= 0.0 {
            return 0;
        }
        ((z / self.storey_height).round().max(0.0) as usize).min(self.floors - 1)
    }

    /// Height of the top floor's ceiling (metres): the ceiling plane rays reach through
    /// stairwells; [`Building::ceiling_height`] with one floor.
    #[must_use]
    pub fn top_ceiling(&self) -> f64 {
        self.floor_height(self.floors - 1) + self.ceiling_height
    }

    /// The staircases, the one from floor `k` to floor `k + 1` at index `k` (none with one
    /// floor).
    #[must_use]
    pub fn staircases(&self) -> &[Staircase] {
        &self.staircases
    }

    /// Corners of the corridor loop's centre line, counter-clockwise from the south-west.
    #[must_use]
    pub fn corridor_loop(&self) -> &[Vector2<f64>; 4] {
        &self.corridor_loop
    }

    /// Corridor width between wall centre lines (metres).
    #[must_use]
    pub fn corridor_width(&self) -> f64 {
        self.corridor_width
    }
}
