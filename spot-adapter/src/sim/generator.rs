//! The building generator: ring corridor, rooms with doors, pilasters, pillars and furniture
//! drawn from a seed (the layout is drawn in [`Building`]'s documentation).

use nalgebra::{Point3, Vector2};

use crate::sim::SimError;
use crate::sim::building::{Building, Room};
use crate::sim::building_config::BuildingConfig;
use crate::sim::rng::SimRng;
use crate::sim::solid_box::{BoxKind, SolidBox};

/// Accumulates boxes while the generator runs.
struct Draft<'a> {
    cfg: &'a BuildingConfig,
    boxes: Vec<SolidBox>,
    ceiling: f64,
}

impl Draft<'_> {
    fn push(&mut self, min: [f64; 3], max: [f64; 3], kind: BoxKind) {
        self.boxes.push(SolidBox {
            min: Point3::from(min),
            max: Point3::from(max),
            kind,
        });
    }

    /// A wall along x (`horizontal`) at y = `c` from x = `a` to `b`, or along y at x = `c`, with
    /// door openings given as (centre, width) along the wall. Walls overrun their ends by half
    /// a thickness so that corners close.
    fn wall(&mut self, horizontal: bool, c: f64, a: f64, b: f64, doors: &[(f64, f64)]) {
        let h = 0.5 * self.cfg.wall_thickness;
        let top = self.ceiling;
        let mut doors = doors.to_vec();
        doors.sort_by(|p, q| p.0.total_cmp(&q.0));
        let mut start = a - h;
        let mut spans = Vec::new();
        for &(centre, width) in &doors {
            spans.push((start, centre - 0.5 * width, 0.0, top, BoxKind::Wall));
            spans.push((
                centre - 0.5 * width,
                centre + 0.5 * width,
                self.cfg.door_height,
                top,
                BoxKind::Lintel,
            ));
            start = centre + 0.5 * width;
        }
        spans.push((start, b + h, 0.0, top, BoxKind::Wall));
        for (s0, s1, z0, z1, kind) in spans {
            if s1 - s0 < 1e-6 {
                continue;
            }
            if horizontal {
                self.push([s0, c - h, z0], [s1, c + h, z1], kind);
            } else {
                self.push([c - h, s0, z0], [c + h, s1, z1], kind);
            }
        }
    }
}

/// The repeated stretch of [`BuildingConfig::repeated_rooms`]: the core's south side cut into
/// `rooms` equal rooms of `pitch`, from `x0`; each room's door (and the outer band's, opposite)
/// and the corridor's pilaster at the same offset from the room's west wall.
#[derive(Clone, Copy, Debug)]
struct Repetition {
    x0: f64,
    pitch: f64,
    rooms: usize,
    door_width: f64,
    /// Door centre from the west wall: core rooms, outer-band rooms.
    core_door: f64,
    outer_door: f64,
    /// Pilaster centre from the west wall, clear of the core door.
    pilaster: f64,
}

impl Repetition {
    fn draw(rng: &mut SimRng, config: &BuildingConfig, kx0: f64, kx1: f64) -> Self {
        let mean = 0.5 * (config.room_width.0 + config.room_width.1);
        // At least three rooms, so that the outer band keeps an end room on each side.
        let rooms = (((kx1 - kx0) / mean).round() as usize).max(3);
        let pitch = (kx1 - kx0) / rooms as f64;
        let t = config.wall_thickness;
        let door_width = rng.range(config.door_width.0, config.door_width.1);
        let core_door = door_on(rng, t, 0.0, pitch, door_width);
        let outer_door = door_on(rng, t, 0.0, pitch, door_width);
        // Half a pitch from the door: clear of it whatever the room width (>= 2.5 m).
        let pilaster = (core_door + 0.5 * pitch) % pitch;
        Self {
            x0: kx0,
            pitch,
            rooms,
            door_width,
            core_door,
            outer_door,
            pilaster,
        }
    }

    /// The west wall of room `j` (`j = rooms`: the east end).
    fn x(&self, j: usize) -> f64 {
        self.x0 + self.pitch * j as f64
    }
}

/// Split `[lo, hi]` into rooms about `width` wide: returns the inner cut positions.
fn cuts(rng: &mut SimRng, lo: f64, hi: f64, width: (f64, f64)) -> Vec<f64> {
    let len = hi - lo;
    let mean = 0.5 * (width.0 + width.1);
    let n = ((len / mean).round() as usize).max(1);
    let sizes: Vec<f64> = (0..n).map(|_| rng.range(0.75, 1.25)).collect();
    let total: f64 = sizes.iter().sum();
    let mut at = lo;
    let mut out = Vec::with_capacity(n.saturating_sub(1));
    for s in &sizes[..n - 1] {
        at += len * s / total;
        out.push(at);
    }
    out
}

/// A door centre on `[a, b]` of a wall, clear of the side walls (thickness `t`) by 0.3 m.
fn door_on(rng: &mut SimRng, t: f64, a: f64, b: f64, width: f64) -> f64 {
    let m = 0.5 * width + 0.5 * t + 0.3;
    rng.range(a + m, (b - m).max(a + m))
}

/// Axis-aligned rectangles overlap (with a margin added to the first).
fn overlaps(a: (Vector2<f64>, Vector2<f64>), b: (Vector2<f64>, Vector2<f64>), margin: f64) -> bool {
    a.0.x - margin < b.1.x
        && b.0.x < a.1.x + margin
        && a.0.y - margin < b.1.y
        && b.0.y < a.1.y + margin
}

impl Building {
    /// Generate the building for `seed`.
    ///
    /// # Errors
    /// [`SimError::InvalidConfig`] when a range in `config` is not usable.
    pub fn generate(seed: u64, config: &BuildingConfig) -> Result<Self, SimError> {
        config.validate()?;
        let mut rng = SimRng::new(seed, 0xb111_d146);
        let draw = |rng: &mut SimRng, r: (f64, f64)| rng.range(r.0, r.1);
        let cw = draw(&mut rng, config.corridor_width);
        let band = draw(&mut rng, config.outer_room_depth);
        let lx = draw(&mut rng, config.loop_length_x);
        let ly = draw(&mut rng, config.loop_length_y);
        let ceiling = draw(&mut rng, config.ceiling_height);
        let (w, h) = (lx + cw + 2.0 * band, ly + cw + 2.0 * band);
        let mut d = Draft {
            cfg: config,
            boxes: Vec::new(),
            ceiling,
        };
        // The corridor's outer walls with the doors of the outer-band rooms.
        let (cx0, cx1, cy0, cy1) = (band, w - band, band, h - band);
        let core = [cx0 + cw, cx1 - cw, cy0 + cw, cy1 - cw];
        let repeat = config
            .repeated_rooms
            .then(|| Repetition::draw(&mut rng, config, core[0], core[1]));
        let ring = Ring {
            size: (w, h),
            corridor: (cx0, cx1, cy0, cy1),
            repeat,
        };
        let (mut rooms, mut copies) = ring.outer_rooms(&mut d, &mut rng);

        // The core inside the loop: two rows of rooms, doors onto the corridor's inner walls.
        // The same on every floor (the staircases stand in it).
        let (core_boxes, core_rooms_at) = (d.boxes.len(), rooms.len());
        let (south_doors, north_doors) =
            core_rooms(&mut d, &mut rng, core, &mut rooms, repeat, &mut copies);
        pilasters(&mut d, &mut rng, core, &south_doors, &north_doors, repeat);
        let core_part = CorePart {
            boxes: d.boxes[core_boxes..].to_vec(),
            rooms: rooms[core_rooms_at..].to_vec(),
            copies: copies
                .iter()
                .filter(|c| c.0 >= core_rooms_at)
                .map(|&(t, c, dx)| (t - core_rooms_at, c - core_rooms_at, dx))
                .collect(),
        };

        furnish_rooms(&mut d, &mut rng, &rooms, &copies);
        let open_rooms = |mut rooms: Vec<Room>| {
            if config.blank_corridor {
                // The rooms behind the shut doors: those whose door is on the north corridor's
                // walls (the west and east rooms' doors face along x).
                rooms.retain(|r| r.inward.x != 0.0 || r.door.y < core[3] - 1e-9);
            }
            rooms
        };
        let rooms = open_rooms(rooms);
        // Each floor above its own rooms round the corridor and its own furniture, drawn from
        // a stream of its own (the ground floor stays the one-floor building of the seed).
        let upper: Vec<(Vec<SolidBox>, Vec<Room>)> = if config.repeat_floor_plan {
            Vec::new()
        } else {
            (1..config.floors)
                .map(|k| {
                    let mut rng = SimRng::new(seed, 0xb111_d146 ^ (k as u64) << 32);
                    let mut f = Draft {
                        cfg: config,
                        boxes: Vec::new(),
                        ceiling,
                    };
                    let (mut rooms, mut copies) = ring.outer_rooms(&mut f, &mut rng);
                    core_part.add_to(&mut f, &mut rooms, &mut copies);
                    furnish_rooms(&mut f, &mut rng, &rooms, &copies);
                    (f.boxes, open_rooms(rooms))
                })
                .collect()
        };

        let building = Self::from_generated(
            d.boxes,
            rooms,
            Vector2::new(w, h),
            ceiling,
            [
                Vector2::new(cx0 + 0.5 * cw, cy0 + 0.5 * cw),
                Vector2::new(cx1 - 0.5 * cw, cy0 + 0.5 * cw),
                Vector2::new(cx1 - 0.5 * cw, cy1 - 0.5 * cw),
                Vector2::new(cx0 + 0.5 * cw, cy1 - 0.5 * cw),
            ],
            cw,
        );
        building.stack_floors(config.floors, config.wall_thickness, &upper)
    }
}

/// The corridor ring of a floor: the building's outline, the corridor's outer walls and the
/// repeated stretch, which every floor shares.
struct Ring {
    /// Building width and depth.
    size: (f64, f64),
    /// The corridor loop's outer walls: x0, x1, y0, y1.
    corridor: (f64, f64, f64, f64),
    repeat: Option<Repetition>,
}

impl Ring {
    /// The outer walls and the rooms between them and the corridor (the south and north
    /// bands, the west and east sides), their walls and doors drawn from `rng`: the rooms and
    /// the furnished rooms to copy (template, copy, x shift).
    #[allow(clippy::type_complexity)]
    fn outer_rooms(
        &self,
        d: &mut Draft<'_>,
        rng: &mut SimRng,
    ) -> (Vec<Room>, Vec<(usize, usize, f64)>) {
        let config = d.cfg;
        let (w, h) = self.size;
        let (cx0, cx1, cy0, cy1) = self.corridor;
        let t = config.wall_thickness;
        d.wall(true, 0.0, 0.0, w, &[]);
        d.wall(true, h, 0.0, w, &[]);
        d.wall(false, 0.0, 0.0, h, &[]);
        d.wall(false, w, 0.0, h, &[]);
        let mut rooms = Vec::new();
        let mut copies: Vec<(usize, usize, f64)> = Vec::new();
        for south in [true, false] {
            let plan = Band {
                south,
                size: self.size,
                corridor: self.corridor,
                repeat: self.repeat.filter(|_| south),
            };
            plan.build(d, rng, &mut rooms, &mut copies);
        }
        for west in [true, false] {
            let mut ys = vec![cy0];
            ys.extend(cuts(rng, cy0, cy1, config.room_width));
            ys.push(cy1);
            let (x_wall, x_out) = if west { (cx0, 0.0) } else { (cx1, w) };
            let mut doors = Vec::new();
            for pair in ys.windows(2) {
                let (a, b) = (pair[0], pair[1]);
                let width = rng.range(config.door_width.0, config.door_width.1);
                let c = door_on(rng, t, a, b, width);
                doors.push((c, width));
                rooms.push(Room {
                    min: Vector2::new(x_out.min(x_wall), a),
                    max: Vector2::new(x_out.max(x_wall), b),
                    door: Vector2::new(x_wall, c),
                    inward: Vector2::new(if west { -1.0 } else { 1.0 }, 0.0),
                });
                if b < cy1 {
                    d.wall(true, b, x_out.min(x_wall), x_out.max(x_wall), &[]);
                }
            }
            d.wall(false, x_wall, cy0, cy1, &doors);
        }
        (rooms, copies)
    }
}

/// The core of the ground floor (its walls, pilasters and rooms, unfurnished), which every
/// floor repeats.
struct CorePart {
    boxes: Vec<SolidBox>,
    rooms: Vec<Room>,
    /// Furnished rooms to copy, as indices into `rooms`.
    copies: Vec<(usize, usize, f64)>,
}

impl CorePart {
    /// The core added to a floor's draft, rooms and copies.
    fn add_to(
        &self,
        d: &mut Draft<'_>,
        rooms: &mut Vec<Room>,
        copies: &mut Vec<(usize, usize, f64)>,
    ) {
        let at = rooms.len();
        d.boxes.extend(self.boxes.iter().copied());
        rooms.extend(self.rooms.iter().copied());
        copies.extend(self.copies.iter().map(|&(t, c, dx)| (t + at, c + at, dx)));
    }
}

/// The core's two rows of rooms inside `[x0, x1, y0, y1]`; returns the doors of the south and
/// north walls as (centre, width).
#[allow(clippy::type_complexity)]
fn core_rooms(
    d: &mut Draft<'_>,
    rng: &mut SimRng,
    [kx0, kx1, ky0, ky1]: [f64; 4],
    rooms: &mut Vec<Room>,
    repeat: Option<Repetition>,
    copies: &mut Vec<(usize, usize, f64)>,
) -> (Vec<(f64, f64)>, Vec<(f64, f64)>) {
    let config = d.cfg;
    let ymid = 0.5 * (ky0 + ky1);
    d.wall(true, ymid, kx0, kx1, &[]);
    d.wall(false, kx0, ky0, ky1, &[]);
    d.wall(false, kx1, ky0, ky1, &[]);
    let mut inner_doors = [Vec::new(), Vec::new()];
    for (row, south) in [true, false].into_iter().enumerate() {
        let repeated = repeat.filter(|_| south);
        let xs: Vec<f64> = if let Some(r) = repeated {
            (0..=r.rooms).map(|j| r.x(j)).collect()
        } else {
            let mut xs = vec![kx0];
            xs.extend(cuts(rng, kx0, kx1, config.room_width));
            xs.push(kx1);
            xs
        };
        let (y_wall, y_far) = if south { (ky0, ymid) } else { (ky1, ymid) };
        let template = rooms.len();
        for (k, pair) in xs.windows(2).enumerate() {
            let (a, b) = (pair[0], pair[1]);
            let (c, width) = if let Some(r) = repeated {
                if k > 0 {
                    copies.push((template, rooms.len(), a - kx0));
                }
                (a + r.core_door, r.door_width)
            } else {
                let width = rng.range(config.door_width.0, config.door_width.1);
                (door_on(rng, config.wall_thickness, a, b, width), width)
            };
            inner_doors[row].push((c, width));
            rooms.push(Room {
                min: Vector2::new(a, y_wall.min(y_far)),
                max: Vector2::new(b, y_wall.max(y_far)),
                door: Vector2::new(c, y_wall),
                inward: Vector2::new(0.0, if south { 1.0 } else { -1.0 }),
            });
            if b < kx1 {
                d.wall(false, b, y_wall.min(y_far), y_wall.max(y_far), &[]);
            }
        }
    }
    let [south_doors, north_doors] = inner_doors;
    d.wall(true, ky0, kx0, kx1, &south_doors);
    d.wall(
        true,
        ky1,
        kx0,
        kx1,
        shut_if(config.blank_corridor, &north_doors),
    );
    (south_doors, north_doors)
}

/// Pilasters on the corridor side of the core's walls (`[x0, x1, y0, y1]`), clear of doors.
fn pilasters(
    d: &mut Draft<'_>,
    rng: &mut SimRng,
    [kx0, kx1, ky0, ky1]: [f64; 4],
    south_doors: &[(f64, f64)],
    north_doors: &[(f64, f64)],
    repeat: Option<Repetition>,
) {
    let config = d.cfg;
    let (t, ceiling) = (config.wall_thickness, d.ceiling);
    let draw = |rng: &mut SimRng, r: (f64, f64)| rng.range(r.0, r.1);
    // Pilasters on the corridor side of the core's walls, clear of doors and corners.
    let depth = 0.25;
    let half = 0.2;
    for (horizontal, c, a, b, sign, doors) in [
        (true, ky0, kx0, kx1, -1.0, south_doors),
        (true, ky1, kx0, kx1, 1.0, north_doors),
        (false, kx0, ky0, ky1, -1.0, &[][..]),
        (false, kx1, ky0, ky1, 1.0, &[][..]),
    ] {
        // The repeated stretch has one pilaster per room, at the same place in each.
        let repeated = repeat.filter(|_| horizontal && sign < 0.0);
        let mut s = match repeated {
            Some(r) => a + r.pilaster,
            None => a + draw(rng, config.pilaster_spacing) * 0.5,
        };
        while s < b - 1.0 {
            let clear = doors
                .iter()
                .all(|&(dc, dw)| (s - dc).abs() > 0.5 * dw + half + 0.3);
            let blank = config.blank_corridor && horizontal && sign > 0.0;
            if clear && !blank {
                let face = c + sign * 0.5 * t;
                let (f0, f1) = if sign < 0.0 {
                    (face - depth, face)
                } else {
                    (face, face + depth)
                };
                if horizontal {
                    d.push(
                        [s - half, f0, 0.0],
                        [s + half, f1, ceiling],
                        BoxKind::Pillar,
                    );
                } else {
                    d.push(
                        [f0, s - half, 0.0],
                        [f1, s + half, ceiling],
                        BoxKind::Pillar,
                    );
                }
            }
            s += match repeated {
                Some(r) => r.pitch,
                None => draw(rng, config.pilaster_spacing),
            };
        }
    }
}

/// Pillars in large rooms, furniture against room walls; nothing in front of a door. A copy
/// (`copies`: template room, copy room, x shift) gets its template's furniture moved along.
fn furnish_rooms(
    d: &mut Draft<'_>,
    rng: &mut SimRng,
    rooms: &[Room],
    copies: &[(usize, usize, f64)],
) {
    for (i, room) in rooms.iter().enumerate() {
        if copies.iter().any(|&(_, copy, _)| copy == i) {
            continue;
        }
        let before = d.boxes.len();
        furnish(d, rng, room);
        let added = before..d.boxes.len();
        for &(_, _, dx) in copies.iter().filter(|&&(template, _, _)| template == i) {
            for k in added.clone() {
                let mut b = d.boxes[k];
                b.min.x += dx;
                b.max.x += dx;
                d.boxes.push(b);
            }
        }
    }
}

/// The south or north band of rooms between the outer wall and the corridor, spanning the full
/// width.
struct Band {
    south: bool,
    /// Building width and depth.
    size: (f64, f64),
    /// The corridor loop's outer walls: x0, x1, y0, y1.
    corridor: (f64, f64, f64, f64),
    /// The repeated stretch, on the south band when asked for.
    repeat: Option<Repetition>,
}

impl Band {
    /// Rooms, their side walls and the corridor wall with their doors.
    fn build(
        &self,
        d: &mut Draft<'_>,
        rng: &mut SimRng,
        rooms: &mut Vec<Room>,
        copies: &mut Vec<(usize, usize, f64)>,
    ) {
        let config = d.cfg;
        let t = config.wall_thickness;
        let (w, h) = self.size;
        let (cx0, cx1, cy0, cy1) = self.corridor;
        let south = self.south;
        // The end rooms must reach the corridor by at least 2.5 m so that their door fits.
        let (first, last) = if let Some(r) = self.repeat {
            (r.x(1), r.x(r.rooms - 1))
        } else {
            (cx0 + rng.range(2.5, 3.5), cx1 - rng.range(2.5, 3.5))
        };
        let mut xs = vec![0.0, first];
        if let Some(r) = self.repeat {
            xs.extend((2..r.rooms - 1).map(|j| r.x(j)));
        } else {
            xs.extend(cuts(rng, first, last, config.room_width));
        }
        xs.extend([last, w]);
        let (y_wall, y_out) = if south { (cy0, 0.0) } else { (cy1, h) };
        let mut doors = Vec::new();
        let template = rooms.len() + 1;
        for (k, pair) in xs.windows(2).enumerate() {
            let (a, b) = (pair[0], pair[1]);
            let inner = k > 0 && k + 2 < xs.len();
            let (c, width) = if let Some(r) = self.repeat.filter(|_| inner) {
                if k > 1 {
                    copies.push((template, rooms.len(), a - r.x(1)));
                }
                (a + r.outer_door, r.door_width)
            } else {
                let width = rng.range(config.door_width.0, config.door_width.1);
                (door_on(rng, t, a.max(cx0), b.min(cx1), width), width)
            };
            doors.push((c, width));
            let inward = Vector2::new(0.0, if south { -1.0 } else { 1.0 });
            rooms.push(Room {
                min: Vector2::new(a, y_out.min(y_wall)),
                max: Vector2::new(b, y_out.max(y_wall)),
                door: Vector2::new(c, y_wall),
                inward,
            });
            if b < w {
                d.wall(false, b, y_out.min(y_wall), y_out.max(y_wall), &[]);
            }
        }
        d.wall(
            true,
            y_wall,
            0.0,
            w,
            shut_if(config.blank_corridor && !south, &doors),
        );
    }
}

/// No door openings when `shut`, else `doors`: the doors' places are drawn either way, so that
/// the rest of the building stays the same.
fn shut_if(shut: bool, doors: &[(f64, f64)]) -> &[(f64, f64)] {
    if shut { &[] } else { doors }
}

/// Put furniture (and in large rooms a pillar) into `room`.
fn furnish(d: &mut Draft<'_>, rng: &mut SimRng, room: &Room) {
    let t = d.cfg.wall_thickness;
    let inner = (
        room.min + Vector2::repeat(0.5 * t),
        room.max - Vector2::repeat(0.5 * t),
    );
    // Keep a 1.6 m deep, door-wide-plus-margin zone in front of the door free.
    let across = Vector2::new(room.inward.y.abs(), room.inward.x.abs());
    let door_a = room.door - across * 1.0;
    let door_b = room.door + across * 1.0 + room.inward * 1.6;
    let door_zone = (
        Vector2::new(door_a.x.min(door_b.x), door_a.y.min(door_b.y)),
        Vector2::new(door_a.x.max(door_b.x), door_a.y.max(door_b.y)),
    );
    let mut placed: Vec<(Vector2<f64>, Vector2<f64>)> = vec![door_zone];
    let size = inner.1 - inner.0;
    if size.x * size.y > 35.0 && size.x > 4.0 && size.y > 4.0 {
        for _ in 0..10 {
            let c = Vector2::new(
                rng.range(inner.0.x + 1.5, inner.1.x - 1.5),
                rng.range(inner.0.y + 1.5, inner.1.y - 1.5),
            );
            let fp = (c - Vector2::repeat(0.2), c + Vector2::repeat(0.2));
            if placed.iter().all(|&p| !overlaps(fp, p, 0.8)) {
                d.push(
                    [fp.0.x, fp.0.y, 0.0],
                    [fp.1.x, fp.1.y, d.ceiling],
                    BoxKind::Pillar,
                );
                placed.push(fp);
                break;
            }
        }
    }
    let (lo, hi) = d.cfg.furniture_per_room;
    let count = lo + rng.index(hi - lo + 1);
    for _ in 0..count {
        // Desk, cabinet or crate: (length along the wall, depth, height) ranges.
        let (len, depth, height) = match rng.index(3) {
            0 => (
                rng.range(1.2, 1.6),
                rng.range(0.6, 0.8),
                rng.range(0.72, 0.76),
            ),
            1 => (
                rng.range(0.8, 1.2),
                rng.range(0.4, 0.6),
                rng.range(1.8, 2.0),
            ),
            _ => (
                rng.range(0.5, 0.8),
                rng.range(0.5, 0.8),
                rng.range(0.5, 1.0),
            ),
        };
        for _ in 0..20 {
            let side = rng.index(4);
            let along_x = side < 2;
            let (sx, sy) = if along_x { (len, depth) } else { (depth, len) };
            if sx > size.x - 0.2 || sy > size.y - 0.2 {
                continue;
            }
            let gap = 0.05;
            let (x0, y0) = match side {
                0 => (rng.range(inner.0.x, inner.1.x - sx), inner.0.y + gap),
                1 => (rng.range(inner.0.x, inner.1.x - sx), inner.1.y - gap - sy),
                2 => (inner.0.x + gap, rng.range(inner.0.y, inner.1.y - sy)),
                _ => (inner.1.x - gap - sx, rng.range(inner.0.y, inner.1.y - sy)),
            };
            let fp = (Vector2::new(x0, y0), Vector2::new(x0 + sx, y0 + sy));
            if placed.iter().all(|&p| !overlaps(fp, p, 0.3)) {
                d.push(
                    [fp.0.x, fp.0.y, 0.0],
                    [fp.1.x, fp.1.y, height],
                    BoxKind::Furniture,
                );
                placed.push(fp);
                break;
            }
        }
    }
}
