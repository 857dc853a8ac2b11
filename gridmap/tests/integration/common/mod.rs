//! A box world for the tests: a floor, a ceiling and axis-aligned boxes, seen by a 16-ring LiDAR
//! model (exact ray casting, no noise unless asked for).
#![allow(dead_code)]

use nalgebra::{Point3, Vector3};
use slam_core::{PointCloud, Pose3};

/// An axis-aligned box, metres.
#[derive(Clone, Copy, Debug)]
pub struct Block {
    pub min: Point3<f64>,
    pub max: Point3<f64>,
}

pub fn block(x0: f64, y0: f64, z0: f64, x1: f64, y1: f64, z1: f64) -> Block {
    Block {
        min: Point3::new(x0, y0, z0),
        max: Point3::new(x1, y1, z1),
    }
}

/// A floor at `floor` m, a ceiling at `ceiling` m and boxes.
#[derive(Clone, Debug)]
pub struct World {
    pub floor: f64,
    pub ceiling: f64,
    pub blocks: Vec<Block>,
}

impl World {
    /// Distance along unit `dir` from `o` to the first surface (at most `max_range`).
    pub fn cast(&self, o: Point3<f64>, dir: Vector3<f64>, max_range: f64) -> Option<f64> {
        let mut best = max_range;
        if dir.z < 0.0 {
            best = best.min((self.floor - o.z) / dir.z);
        }
        if dir.z > 0.0 {
            best = best.min((self.ceiling - o.z) / dir.z);
        }
        for b in &self.blocks {
            let (mut t0, mut t1) = (0.0f64, best);
            let mut hit = true;
            for k in 0..3 {
                if dir[k].abs() < 1e-12 {
                    if o[k] < b.min[k] || o[k] > b.max[k] {
                        hit = false;
                        break;
                    }
                } else {
                    let (a, c) = ((b.min[k] - o[k]) / dir[k], (b.max[k] - o[k]) / dir[k]);
                    t0 = t0.max(a.min(c));
                    t1 = t1.min(a.max(c));
                }
            }
            if hit && t0 <= t1 && t0 > 1e-9 {
                best = best.min(t0);
            }
        }
        (best < max_range).then_some(best)
    }

    /// A VLP-16-like scan from `sensor` (level, identity rotation): 16 rings from -15 to +15
    /// degrees, `columns` azimuths, points in the sensor frame.
    pub fn scan(&self, sensor: Point3<f64>, columns: usize) -> (Pose3, PointCloud) {
        let mut points = Vec::with_capacity(16 * columns);
        for ring in 0..16 {
            let el = (-15.0 + 2.0 * f64::from(ring)).to_radians();
            for c in 0..columns {
                let az = c as f64 / columns as f64 * std::f64::consts::TAU;
                let dir = Vector3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
                if let Some(t) = self.cast(sensor, dir, 30.0) {
                    let p = dir * t;
                    points.push(Point3::new(p.x as f32, p.y as f32, p.z as f32));
                }
            }
        }
        (
            Pose3::translation(sensor.x, sensor.y, sensor.z),
            PointCloud::from_points(points),
        )
    }

    /// Points sampled on every surface (top and four sides of each box, the floor and the
    /// ceiling inside `[x0, x1] x [y0, y1]`) every `step` metres: a dense map cloud.
    pub fn surface_cloud(&self, x0: f64, y0: f64, x1: f64, y1: f64, step: f64) -> PointCloud {
        let mut pts = Vec::new();
        let range = |a: f64, b: f64| {
            let n = ((b - a) / step).ceil() as usize;
            (0..=n).map(move |i| (a + i as f64 * step).min(b))
        };
        let mut push = |x: f64, y: f64, z: f64| pts.push(Point3::new(x as f32, y as f32, z as f32));
        for x in range(x0, x1) {
            for y in range(y0, y1) {
                let covered = self.blocks.iter().any(|b| {
                    b.min.z <= self.floor + 1e-6
                        && x > b.min.x
                        && x < b.max.x
                        && y > b.min.y
                        && y < b.max.y
                });
                if !covered {
                    push(x, y, self.floor);
                }
                push(x, y, self.ceiling);
            }
        }
        for b in &self.blocks {
            let (zlo, zhi) = (b.min.z.max(self.floor), b.max.z.min(self.ceiling));
            for x in range(b.min.x, b.max.x) {
                for y in range(b.min.y, b.max.y) {
                    push(x, y, zhi);
                    if b.min.z > self.floor {
                        push(x, y, zlo);
                    }
                }
                for z in range(zlo, zhi) {
                    push(x, b.min.y, z);
                    push(x, b.max.y, z);
                }
            }
            for y in range(b.min.y, b.max.y) {
                for z in range(zlo, zhi) {
                    push(b.min.x, y, z);
                    push(b.max.x, y, z);
                }
            }
        }
        PointCloud::from_points(pts)
    }
}

/// A 12 m x 6 m room (floor at `floor`, ceiling 2.5 m above it) with a 0.56 m crate, a 0.72 m
/// desk top (on four legs), a wall with a door (lintel at 2.1 m) and 0.15 m walls.
pub fn room(floor: f64) -> World {
    let z = |h: f64| floor + h;
    World {
        floor,
        ceiling: z(2.5),
        blocks: vec![
            // Outer walls.
            block(-0.15, -0.15, z(0.0), 12.15, 0.0, z(2.5)),
            block(-0.15, 6.0, z(0.0), 12.15, 6.15, z(2.5)),
            block(-0.15, 0.0, z(0.0), 0.0, 6.0, z(2.5)),
            block(12.0, 0.0, z(0.0), 12.15, 6.0, z(2.5)),
            // A cross wall at x = 8 m with a 0.9 m door from y = 2.55 to 3.45 m, lintel 2.1 m.
            block(8.0, 0.0, z(0.0), 8.15, 2.55, z(2.5)),
            block(8.0, 3.45, z(0.0), 8.15, 6.0, z(2.5)),
            block(8.0, 2.55, z(2.1), 8.15, 3.45, z(2.5)),
            // The crate: 0.5 m square, 0.56 m tall.
            block(2.0, 4.0, z(0.0), 2.5, 4.5, z(0.56)),
            // The desk: a 1.2 x 0.6 m top from 0.70 to 0.72 m on four 4 cm legs.
            block(5.0, 4.6, z(0.70), 6.2, 5.2, z(0.72)),
            block(5.0, 4.6, z(0.0), 5.04, 4.64, z(0.70)),
            block(6.16, 4.6, z(0.0), 6.2, 4.64, z(0.70)),
            block(5.0, 5.16, z(0.0), 5.04, 5.2, z(0.70)),
            block(6.16, 5.16, z(0.0), 6.2, 5.2, z(0.70)),
        ],
    }
}
