//! The ranges the building generator draws from, and their checks.

use crate::sim::SimError;

/// The most floors a building may have.
pub const MAX_FLOORS: usize = 3;

/// Ranges the generator draws from (metres). Defaults give realistic office scales.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct BuildingConfig {
    /// Corridor width between wall centre lines, e.g. 1.8..2.6 m (1.6..2.4 m free).
    pub corridor_width: (f64, f64),
    /// Depth of the rooms between the outer wall and the corridor, e.g. 4..6 m.
    pub outer_room_depth: (f64, f64),
    /// Length of the corridor loop's centre line along x, e.g. 34..44 m.
    pub loop_length_x: (f64, f64),
    /// Length of the corridor loop's centre line along y, e.g. 16..20 m.
    pub loop_length_y: (f64, f64),
    /// Room widths along a corridor, e.g. 3..8 m.
    pub room_width: (f64, f64),
    /// Ceiling height, e.g. 2.5..3.0 m.
    pub ceiling_height: (f64, f64),
    /// Wall thickness, usually 0.2 m.
    pub wall_thickness: f64,
    /// Door width, e.g. 1.0..1.2 m.
    pub door_width: (f64, f64),
    /// Door height, usually 2.1 m.
    pub door_height: f64,
    /// Spacing of the pilasters along the corridor's inner wall, e.g. 4..8 m; they break up the
    /// long featureless corridor walls as real buildings do.
    pub pilaster_spacing: (f64, f64),
    /// Furniture pieces per room, e.g. 1..=3.
    pub furniture_per_room: (usize, usize),
    /// Perceptual aliasing along the south corridor: its rooms on both sides are copies of one
    /// room each (the same width, door and furniture, repeated every few metres), and so are
    /// the pilasters on its inner wall. A robot walking that corridor sees the same place again
    /// and again, as in a hotel or an office floor of identical cells. Default false.
    pub repeated_rooms: bool,
    /// A blank north corridor: the doors along it are shut and its inner wall has no
    /// pilasters, so that its walls are flat from end to end, as in a service corridor. Only
    /// the corridor's far ends tell a LiDAR how far it walked along it: registration that
    /// keeps every PCA normal slips there (a LiDAR-only lap ends 1.34 m off), registration on
    /// plane-like normals does not (1.1 cm). The rooms behind the shut doors are left out of
    /// [`Building::rooms`](crate::sim::Building::rooms). Default false.
    pub blank_corridor: bool,
    /// Floors, 1 (the default) to 3. Above one, the floors stand on slabs, each floor with the
    /// ground floor's corridor ring and core (the rooms inside the ring, where the staircases
    /// stand) but rooms of its own round the ring and its own furniture; a straight staircase
    /// (with a landing midway on a tall storey, where its room is deep enough) joins each floor
    /// to the next through a stairwell in the slab above it (see
    /// [`Staircase`](crate::sim::Staircase)). The ground floor is the one-floor building of
    /// the same seed.
    pub floors: usize,
    /// Every floor a copy of the ground floor's plan (the same rooms and furniture), the hard
    /// case for mapping: floors told apart only by height and the stairs. Default false.
    pub repeat_floor_plan: bool,
}

impl Default for BuildingConfig {
    fn default() -> Self {
        Self {
            corridor_width: (1.8, 2.6),
            outer_room_depth: (4.0, 6.0),
            loop_length_x: (34.0, 44.0),
            loop_length_y: (16.0, 20.0),
            room_width: (3.0, 8.0),
            ceiling_height: (2.5, 3.0),
            wall_thickness: 0.2,
            door_width: (1.0, 1.2),
            door_height: 2.1,
            pilaster_spacing: (4.0, 8.0),
            furniture_per_room: (1, 3),
            repeated_rooms: false,
            blank_corridor: false,
            floors: 1,
            repeat_floor_plan: false,
        }
    }
}

impl BuildingConfig {
    /// About the smallest building the generator makes: a 10 m x 10 m corridor loop with
    /// shallow rooms round it and a core of rooms inside (about 17 m x 17 m, 14-16 rooms, one
    /// piece of furniture each). An exploration of it takes seconds, not minutes: the tests'
    /// and the mission's small building.
    #[must_use]
    pub fn small() -> Self {
        Self {
            loop_length_x: (10.0, 10.0),
            loop_length_y: (10.0, 10.0),
            outer_room_depth: (2.5, 3.0),
            corridor_width: (1.8, 2.0),
            room_width: (4.5, 6.0),
            furniture_per_room: (1, 1),
            ..Self::default()
        }
    }

    /// A floor four times the default's or more (the exploration issue's large building): a
    /// 100-110 m x 44-50 m corridor loop with rooms 3-7 m wide on both sides and a core of rooms
    /// inside, about 115 m x 57 m and 100-110 rooms in all.
    #[must_use]
    pub fn large() -> Self {
        Self {
            loop_length_x: (100.0, 110.0),
            loop_length_y: (44.0, 50.0),
            room_width: (3.0, 7.0),
            ..Self::default()
        }
    }

    /// The floor count: 1 to [`MAX_FLOORS`].
    fn validate_floors(&self) -> Result<(), SimError> {
        if (1..=MAX_FLOORS).contains(&self.floors) {
            return Ok(());
        }
        Err(SimError::invalid(
            "floors",
            self.floors as f64,
            "1, 2 or 3 (a building has at least one floor; the tour and the tests go to 3)",
        ))
    }

    pub(crate) fn validate(&self) -> Result<(), SimError> {
        // (name of the range's low end, of its high end, the range, its floor, the requirement)
        let ranges = [
            (
                "corridor_width.0",
                "corridor_width.1",
                self.corridor_width,
                1.0,
                "finite, ordered, at least 1 m",
            ),
            (
                "outer_room_depth.0",
                "outer_room_depth.1",
                self.outer_room_depth,
                2.5,
                "finite, ordered, at least 2.5 m",
            ),
            (
                "loop_length_x.0",
                "loop_length_x.1",
                self.loop_length_x,
                10.0,
                "finite, ordered, at least 10 m",
            ),
            (
                "loop_length_y.0",
                "loop_length_y.1",
                self.loop_length_y,
                10.0,
                "finite, ordered, at least 10 m",
            ),
            (
                "room_width.0",
                "room_width.1",
                self.room_width,
                2.5,
                "finite, ordered, at least 2.5 m",
            ),
            (
                "ceiling_height.0",
                "ceiling_height.1",
                self.ceiling_height,
                2.2,
                "finite, ordered, at least 2.2 m",
            ),
            (
                "door_width.0",
                "door_width.1",
                self.door_width,
                0.6,
                "finite, ordered, at least 0.6 m",
            ),
            (
                "pilaster_spacing.0",
                "pilaster_spacing.1",
                self.pilaster_spacing,
                1.0,
                "finite, ordered, at least 1 m",
            ),
        ];
        for (low, high, (lo, hi), floor, expected) in ranges {
            if !(lo.is_finite() && lo >= floor) {
                return Err(SimError::invalid(low, lo, expected));
            }
            if !(hi.is_finite() && hi >= lo) {
                return Err(SimError::invalid(high, hi, expected));
            }
        }
        let t = self.wall_thickness;
        if !(t.is_finite() && t > 0.0 && t < 0.5 * self.corridor_width.0) {
            return Err(SimError::invalid(
                "wall_thickness",
                t,
                "positive and below half the corridor width (metres)",
            ));
        }
        if !(self.door_height.is_finite()
            && self.door_height > 1.0
            && self.door_height < self.ceiling_height.0)
        {
            return Err(SimError::invalid(
                "door_height",
                self.door_height,
                "between 1 m and the lowest ceiling",
            ));
        }
        if self.door_width.1 + 1.2 > self.room_width.0 {
            return Err(SimError::invalid(
                "door_width.1",
                self.door_width.1,
                "at least 1.2 m below room_width.0",
            ));
        }
        self.validate_floors()?;
        if self.furniture_per_room.0 > self.furniture_per_room.1 {
            return Err(SimError::invalid(
                "furniture_per_room.0",
                self.furniture_per_room.0 as f64,
                "at most furniture_per_room.1",
            ));
        }
        Ok(())
    }
}
