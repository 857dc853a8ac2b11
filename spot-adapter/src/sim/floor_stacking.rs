//! A building of several floors: the floors stacked (the generated ground floor, and above it
//! either floors of their own round the same corridor ring and core, or copies of the ground
//! floor), a slab between the floors with a stairwell, and a straight staircase (with a landing
//! midway where the storey is tall and the room deep) from each floor to the next in a core
//! room.

use nalgebra::{Point3, Vector2};

use crate::sim::SimError;
use crate::sim::building::{Building, Room};
use crate::sim::solid_box::{BoxKind, SolidBox};
use crate::sim::staircase::{STAIR_WIDTH, STAIRWELL_MARGIN, Staircase};

/// Thickness of the slab between two floors (metres): the storey height is the ceiling height
/// plus this.
pub const SLAB_THICKNESS: f64 = 0.2;
/// From the door's wall to the first step (metres): room to come in and turn onto the flight.
pub(crate) const STAIR_APPROACH: f64 = 1.2;
/// From the last step to the far wall (metres): room to step off and turn on the upper floor.
const STAIR_LANDING: f64 = 0.9;
/// Free width beside the stairwell (metres), for walking back to the door upstairs.
const FREE_LANE: f64 = 1.0;

impl Building {
    /// This single-floor building stacked into `floors` floors (itself when `floors` is 1),
    /// with the furniture and pillars taken out of the rooms the staircases stand in. Floor
    /// `k` above the ground has the boxes and rooms `upper[k - 1]` (at ground level, lifted
    /// here); with `upper` empty every floor is a copy of the ground floor.
    ///
    /// # Errors
    /// [`SimError::NoRoomForStairs`] when fewer core rooms than staircases can hold one.
    pub(crate) fn stack_floors(
        self,
        floors: usize,
        wall_thickness: f64,
        upper: &[(Vec<SolidBox>, Vec<Room>)],
    ) -> Result<Self, SimError> {
        if floors <= 1 {
            return Ok(self);
        }
        let storey = self.ceiling_height + SLAB_THICKNESS;
        let mut fitting: Vec<(f64, Room)> = self
            .rooms
            .iter()
            .filter(|room| self.is_core(room))
            .filter_map(|room| {
                let flight = place_flight(room, 0.0, storey, wall_thickness)?;
                Some((
                    (room.max - room.min).dot(&room.inward.abs()) - flight.run(),
                    *room,
                ))
            })
            .collect();
        // The deepest rooms first: the most landing space.
        fitting.sort_by(|a, b| b.0.total_cmp(&a.0));
        let needed = floors - 1;
        if fitting.len() < needed {
            return Err(SimError::NoRoomForStairs {
                floors,
                needed,
                found: fitting.len(),
            });
        }
        let staircases: Vec<Staircase> = fitting[..needed]
            .iter()
            .enumerate()
            .filter_map(|(k, (_, room))| {
                place_flight(room, k as f64 * storey, storey, wall_thickness)
            })
            .collect();
        let in_stair_room = |b: &SolidBox| {
            matches!(b.kind, BoxKind::Furniture | BoxKind::Pillar)
                && staircases.iter().any(|s| {
                    let (lo, hi) = (s.room.min, s.room.max);
                    b.min.x >= lo.x && b.max.x <= hi.x && b.min.y >= lo.y && b.max.y <= hi.y
                })
        };
        let plans: Vec<(&[SolidBox], &[Room])> = (0..floors)
            .map(|k| match upper.get(k.wrapping_sub(1)) {
                Some((boxes, rooms)) if k > 0 => (boxes.as_slice(), rooms.as_slice()),
                _ => (self.boxes.as_slice(), self.rooms.as_slice()),
            })
            .collect();
        let mut boxes = Vec::with_capacity(self.boxes.len() * floors + 64);
        for (k, (plan, _)) in plans.iter().enumerate() {
            let dz = k as f64 * storey;
            boxes.extend(plan.iter().filter(|b| !in_stair_room(b)).map(|b| SolidBox {
                min: b.min + nalgebra::Vector3::z() * dz,
                max: b.max + nalgebra::Vector3::z() * dz,
                kind: b.kind,
            }));
        }
        let upper_rooms = plans[1..].iter().map(|(_, r)| r.to_vec()).collect();
        for (k, flight) in staircases.iter().enumerate() {
            boxes.extend(flight.step_boxes());
            let top = (k + 1) as f64 * storey;
            boxes.extend(slab_around(
                self.size,
                flight.stairwell(),
                top - SLAB_THICKNESS,
                top,
            ));
        }
        let mut building = Self::from_generated(
            boxes,
            self.rooms,
            self.size,
            self.ceiling_height,
            self.corridor_loop,
            self.corridor_width,
        );
        building.floors = floors;
        building.upper_rooms = upper_rooms;
        building.storey_height = storey;
        building.staircases = staircases;
        Ok(building)
    }

    /// Whether `room` lies inside the corridor loop (a core room, its door on the loop).
    fn is_core(&self, room: &Room) -> bool {
        let [c0, _, c2, _] = self.corridor_loop;
        room.min.x > c0.x && room.max.x < c2.x && room.min.y > c0.y && room.max.y < c2.y
    }
}

/// The flight in `room` from `base_z`, or `None` when the room is too shallow or too narrow.
/// It stands against the side wall farther from the door, its foot [`STAIR_APPROACH`] in from
/// the door's wall, climbing away from the door. A tall storey's flight has a landing midway
/// when the room is deep enough for it, and is one run otherwise.
fn place_flight(room: &Room, base_z: f64, storey: f64, wall: f64) -> Option<Staircase> {
    let inward = room.inward;
    let across = Vector2::new(inward.y.abs(), inward.x.abs());
    let extent = room.max - room.min;
    let fits =
        |f: &Staircase| extent.dot(&inward.abs()) >= STAIR_APPROACH + f.run() + STAIR_LANDING;
    let probe = Staircase::new(*room, Vector2::zeros(), inward, base_z, storey);
    let probe = if fits(&probe) {
        probe
    } else {
        probe.without_landing()
    };
    let wide = extent.dot(&across) >= wall + STAIR_WIDTH + STAIRWELL_MARGIN + FREE_LANE;
    if !(fits(&probe) && wide) {
        return None;
    }
    let (lo, hi) = (room.min.dot(&across), room.max.dot(&across));
    let door = room.door.dot(&across);
    let centre = if door - lo >= hi - door {
        lo + 0.5 * wall + 0.5 * STAIR_WIDTH
    } else {
        hi - 0.5 * wall - 0.5 * STAIR_WIDTH
    };
    let foot = across * centre + inward * (room.door.dot(&inward) + STAIR_APPROACH);
    Some(Staircase { foot, ..probe })
}

/// The slab from `z0` to `z1` over the building's `size`, around the `hole` (min, max): four
/// boxes, south, north, west and east of it.
fn slab_around(
    size: Vector2<f64>,
    (lo, hi): (Vector2<f64>, Vector2<f64>),
    z0: f64,
    z1: f64,
) -> Vec<SolidBox> {
    let slab = |x0: f64, y0: f64, x1: f64, y1: f64| SolidBox {
        min: Point3::new(x0, y0, z0),
        max: Point3::new(x1, y1, z1),
        kind: BoxKind::Slab,
    };
    let (lo, hi) = (lo.sup(&Vector2::zeros()), hi.inf(&size));
    [
        slab(0.0, 0.0, size.x, lo.y),
        slab(0.0, hi.y, size.x, size.y),
        slab(0.0, lo.y, lo.x, hi.y),
        slab(hi.x, lo.y, size.x, hi.y),
    ]
    .into_iter()
    .filter(SolidBox::is_proper)
    .collect()
}
