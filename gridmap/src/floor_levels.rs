//! A walk over several floors split by height: a floor is a level the walk covered some
//! distance on, and the walk's changes of level (the stairs) join the floors.

use std::collections::BTreeMap;

use nalgebra::Point3;
use slam_core::InvalidSetting;

use crate::error::GridMapError;

/// Settings of [`FloorLevels::split`]. Lengths in metres.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct FloorLevelsConfig {
    /// A level is a floor when the walk covers at least this far on it (horizontally), 5 m: a
    /// landing or a pause on the stairs is not a floor.
    pub min_walk: f64,
    /// A pose is on a level when its height is within this of the level's, 0.3 m: a robot's
    /// body sways by centimetres, a stair's rise is 0.15-0.2 m.
    pub tolerance: f64,
    /// Two floors are at least this far apart, 1.5 m (storeys are 2.5-4 m; a raised part of
    /// one floor is not another floor).
    pub min_separation: f64,
}

impl Default for FloorLevelsConfig {
    fn default() -> Self {
        Self {
            min_walk: 5.0,
            tolerance: 0.3,
            min_separation: 1.5,
        }
    }
}

impl FloorLevelsConfig {
    /// Every length finite and positive, and the separation more than twice the tolerance (so
    /// that no pose can be on two levels).
    ///
    /// # Errors
    /// [`InvalidSetting`] naming the first bad setting.
    pub fn validate(&self) -> Result<(), InvalidSetting> {
        for (setting, v) in [
            ("FloorLevelsConfig::min_walk", self.min_walk),
            ("FloorLevelsConfig::tolerance", self.tolerance),
            ("FloorLevelsConfig::min_separation", self.min_separation),
        ] {
            InvalidSetting::check(v.is_finite() && v > 0.0, setting, v, "finite and positive")?;
        }
        InvalidSetting::check(
            self.min_separation > 2.0 * self.tolerance,
            "FloorLevelsConfig::min_separation",
            self.min_separation,
            "more than twice FloorLevelsConfig::tolerance",
        )
    }
}

/// A floor: a level the walk stood on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FloorLevel {
    /// The median height of its poses (the sensor's or the body's, as the poses were given).
    pub height: f64,
    /// How far the walk went on it (metres, horizontally).
    pub walked: f64,
    /// How many poses are on it.
    pub poses: usize,
}

/// The walk going from one floor to another: the poses it left and arrived at, and the walk
/// between them (the stairs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LevelChange {
    /// The floor left (an index into [`FloorLevels::levels`]).
    pub from: usize,
    /// The floor reached.
    pub to: usize,
    /// The last pose on `from` before the change.
    pub left_at: usize,
    /// The first pose on `to`.
    pub arrived_at: usize,
}

/// A walk's poses split into floors by height ([`FloorLevels::split`]).
///
/// ```
/// use gridmap::{FloorLevels, FloorLevelsConfig};
/// use nalgebra::Point3;
///
/// // 20 m at 0.5 m, a flight of stairs up 3 m over 5 m, 20 m at 3.5 m.
/// let mut walk: Vec<Point3<f64>> = (0..=40).map(|i| Point3::new(i as f64 * 0.5, 0.0, 0.5)).collect();
/// walk.extend((1..=10).map(|i| Point3::new(20.0 + i as f64 * 0.5, 0.0, 0.5 + i as f64 * 0.3)));
/// walk.extend((1..=40).map(|i| Point3::new(25.0 - i as f64 * 0.5, 1.0, 3.5)));
/// let floors = FloorLevels::split(&walk, &FloorLevelsConfig::default())?;
/// assert_eq!(floors.levels().len(), 2);
/// assert!((floors.levels()[1].height - 3.5).abs() < 1e-9);
/// assert_eq!(floors.floor_of(0), Some(0));
/// assert_eq!(floors.floor_of(45), None, "on the stairs");
/// assert_eq!(floors.changes()[0].to, 1);
/// # Ok::<(), gridmap::GridMapError>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct FloorLevels {
    levels: Vec<FloorLevel>,
    of_pose: Vec<Option<usize>>,
    tolerance: f64,
}

/// Heights are binned this fine (a share of the tolerance) to find the levels.
const BINS_PER_TOLERANCE: f64 = 3.0;

impl FloorLevels {
    /// Splits the walk through `positions` (in walking order, z up) into floors: the heights
    /// the walk covered at least [`FloorLevelsConfig::min_walk`] on, each step's horizontal
    /// length credited to the height it was taken at, the most walked level first and none
    /// within [`FloorLevelsConfig::min_separation`] of one taken; a pose is on the floor within
    /// [`FloorLevelsConfig::tolerance`] of its height, on none between floors. A walk on one
    /// floor gives one level; a walk that never covers the minimum on any level gives none.
    ///
    /// # Errors
    /// [`GridMapError::InvalidConfig`] for bad settings, [`GridMapError::NonFinitePosition`]
    /// for a position that is not finite.
    pub fn split(
        positions: &[Point3<f64>],
        config: &FloorLevelsConfig,
    ) -> Result<Self, GridMapError> {
        config.validate()?;
        if let Some(index) = positions
            .iter()
            .position(|p| !p.iter().all(|v| v.is_finite()))
        {
            return Err(GridMapError::NonFinitePosition { index });
        }
        let bin = config.tolerance / BINS_PER_TOLERANCE;
        // Per height bin: the walk at it and the walk-weighted sum of its heights.
        let mut walked_at: BTreeMap<i64, (f64, f64)> = BTreeMap::new();
        for step in positions.windows(2) {
            let (a, b) = (step[0], step[1]);
            let length = (b.xy() - a.xy()).norm();
            let z = 0.5 * (a.z + b.z);
            // Finite heights over a positive bin: the cast saturates at worst.
            let e = walked_at
                .entry((z / bin).floor() as i64)
                .or_insert((0.0, 0.0));
            e.0 += length;
            e.1 += length * z;
        }
        let reach = (BINS_PER_TOLERANCE).ceil() as i64;
        let mut peaks: Vec<(i64, f64)> = walked_at.iter().map(|(&k, &(w, _))| (k, w)).collect();
        peaks.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        let mut heights: Vec<(f64, f64)> = Vec::new();
        for (key, _) in peaks {
            let (walked, weighted) = walked_at
                .range(key.saturating_sub(reach)..=key.saturating_add(reach))
                .fold((0.0, 0.0), |(w, s), (_, &(wb, sb))| (w + wb, s + sb));
            if walked < config.min_walk {
                // Peaks come most walked first: no later window can reach the minimum alone
                // unless its neighbours carry it, so keep looking.
                continue;
            }
            let height = weighted / walked;
            if heights
                .iter()
                .all(|&(h, _)| (h - height).abs() >= config.min_separation)
            {
                heights.push((height, walked));
            }
        }
        heights.sort_by(|a, b| a.0.total_cmp(&b.0));
        let of_pose: Vec<Option<usize>> = positions
            .iter()
            .map(|p| {
                heights
                    .iter()
                    .position(|&(h, _)| (p.z - h).abs() <= config.tolerance)
            })
            .collect();
        // Each floor's height: the median of its poses' (robust to the stairs' first steps,
        // which the window found it with also holds).
        let levels = heights
            .iter()
            .enumerate()
            .map(|(k, &(found, walked))| {
                let mut zs: Vec<f64> = positions
                    .iter()
                    .zip(&of_pose)
                    .filter(|(_, f)| **f == Some(k))
                    .map(|(p, _)| p.z)
                    .collect();
                zs.sort_by(f64::total_cmp);
                FloorLevel {
                    height: zs.get(zs.len() / 2).copied().unwrap_or(found),
                    walked,
                    poses: zs.len(),
                }
            })
            .collect();
        Ok(Self {
            levels,
            of_pose,
            tolerance: config.tolerance,
        })
    }

    /// The floors, lowest first.
    #[must_use]
    pub fn levels(&self) -> &[FloorLevel] {
        &self.levels
    }

    /// The floor pose `index` is on; `None` between floors (on the stairs) or past the walk.
    #[must_use]
    pub fn floor_of(&self, index: usize) -> Option<usize> {
        self.of_pose.get(index).copied().flatten()
    }

    /// The floor at `height` (within the tolerance of its height, as a pose of the walk is);
    /// `None` between floors.
    #[must_use]
    pub fn floor_at(&self, height: f64) -> Option<usize> {
        self.levels
            .iter()
            .position(|l| (height - l.height).abs() <= self.tolerance)
    }

    /// Each time the walk went from one floor to another, in walking order.
    #[must_use]
    pub fn changes(&self) -> Vec<LevelChange> {
        let mut changes = Vec::new();
        let mut last: Option<(usize, usize)> = None;
        for (i, floor) in self.of_pose.iter().enumerate() {
            let Some(floor) = *floor else { continue };
            if let Some((from, left_at)) = last
                && from != floor
            {
                changes.push(LevelChange {
                    from,
                    to: floor,
                    left_at,
                    arrived_at: i,
                });
            }
            last = Some((floor, i));
        }
        changes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A walk of `n` steps of 0.5 m along x at height `z`, from `x0`.
    fn flat(x0: f64, n: usize, z: f64) -> Vec<Point3<f64>> {
        (0..n)
            .map(|i| {
                // A body's sway of a few centimetres.
                let sway = 0.02 * ((i as f64) * 1.3).sin();
                Point3::new(x0 + i as f64 * 0.5, 0.0, z + sway)
            })
            .collect()
    }

    #[test]
    fn three_floors_up_and_back_down() {
        let storey = 3.02;
        let mut walk = flat(0.0, 100, 0.6);
        for k in 0..2_u32 {
            // 16 steps of 0.28 m run and storey / 16 rise.
            let base = walk.last().copied().unwrap_or(Point3::origin());
            walk.extend((1..=16_u32).map(|i| {
                Point3::new(
                    base.x + 0.28 * f64::from(i),
                    0.0,
                    0.6 + f64::from(k) * storey + storey * f64::from(i) / 16.0,
                )
            }));
            let x = walk.last().map_or(0.0, |p| p.x);
            walk.extend(flat(x, 60, 0.6 + f64::from(k + 1) * storey));
        }
        let top = walk.len() - 1;
        // Down both storeys in one flight of 32 steps, then on along the ground floor.
        let base = walk[top];
        walk.extend((1..=32_u32).map(|i| {
            Point3::new(
                base.x + 0.28 * f64::from(i),
                0.0,
                base.z - storey * f64::from(i) / 16.0,
            )
        }));
        let x = walk.last().map_or(0.0, |p| p.x);
        walk.extend(flat(x, 20, 0.6));
        let floors = FloorLevels::split(&walk, &FloorLevelsConfig::default()).unwrap();
        let heights: Vec<f64> = floors.levels().iter().map(|l| l.height).collect();
        assert_eq!(heights.len(), 3, "{heights:?}");
        for (k, h) in heights.iter().enumerate() {
            assert!((h - (0.6 + k as f64 * storey)).abs() < 0.01, "{heights:?}");
        }
        // The oracle: the height each pose was made at, against the floors' true heights.
        let tolerance = FloorLevelsConfig::default().tolerance;
        let mut counts = [0; 3];
        for (i, p) in walk.iter().enumerate() {
            let k = ((p.z - 0.6) / storey).round();
            let on_floor = ((p.z - 0.6) - k * storey).abs() <= tolerance;
            assert_eq!(
                floors.floor_of(i),
                on_floor.then_some(k as usize),
                "pose {i}"
            );
            if on_floor {
                counts[k as usize] += 1;
            }
        }
        let poses: Vec<usize> = floors.levels().iter().map(|l| l.poses).collect();
        assert_eq!(poses, counts);
        assert_eq!(floors.floor_of(top), Some(2));
        assert_eq!(floors.floor_at(0.6 + 2.0 * storey + 0.1), Some(2));
        assert_eq!(floors.floor_at(0.6 + 1.5 * storey), None);
        let changes: Vec<(usize, usize)> =
            floors.changes().iter().map(|c| (c.from, c.to)).collect();
        // The flight down passes the middle floor's height: a step on it is on it.
        assert_eq!(changes, [(0, 1), (1, 2), (2, 1), (1, 0)]);
        // 99 + 19 steps of 0.5 m on the ground floor, and the flights' first and last steps.
        assert!(
            (floors.levels()[0].walked - 59.0).abs() < 1.2,
            "{:?}",
            floors.levels()
        );
    }

    #[test]
    fn one_floor_is_one_level_and_a_short_walk_none() {
        let floors =
            FloorLevels::split(&flat(0.0, 40, 0.5), &FloorLevelsConfig::default()).unwrap();
        assert_eq!(floors.levels().len(), 1);
        assert_eq!(floors.changes(), []);
        let short = FloorLevels::split(&flat(0.0, 5, 0.5), &FloorLevelsConfig::default()).unwrap();
        assert!(short.levels().is_empty());
        assert_eq!(short.floor_of(0), None);
        assert_eq!(short.floor_of(99), None);
        let empty = FloorLevels::split(&[], &FloorLevelsConfig::default()).unwrap();
        assert!(empty.levels().is_empty());
    }

    #[test]
    fn bad_settings_and_positions_are_refused_by_name() {
        for (config, setting) in [
            (
                FloorLevelsConfig {
                    min_walk: f64::NAN,
                    ..FloorLevelsConfig::default()
                },
                "FloorLevelsConfig::min_walk",
            ),
            (
                FloorLevelsConfig {
                    tolerance: 0.0,
                    ..FloorLevelsConfig::default()
                },
                "FloorLevelsConfig::tolerance",
            ),
            (
                FloorLevelsConfig {
                    min_separation: -1.0,
                    ..FloorLevelsConfig::default()
                },
                "FloorLevelsConfig::min_separation",
            ),
            (
                FloorLevelsConfig {
                    min_separation: 0.5,
                    ..FloorLevelsConfig::default()
                },
                "FloorLevelsConfig::min_separation",
            ),
        ] {
            match FloorLevels::split(&flat(0.0, 40, 0.5), &config) {
                Err(GridMapError::InvalidConfig(e)) => assert_eq!(e.setting, setting),
                other => panic!("{setting}: {other:?}"),
            }
        }
        let mut walk = flat(0.0, 10, 0.5);
        walk[4].z = f64::INFINITY;
        assert!(matches!(
            FloorLevels::split(&walk, &FloorLevelsConfig::default()),
            Err(GridMapError::NonFinitePosition { index: 4 })
        ));
    }
}
