//! Settings of the occupancy-grid builder.

/// Settings of [`OccupancyGridBuilder`](crate::OccupancyGridBuilder). Lengths in metres.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct OccupancyGridConfig {
    /// Cell side (thesis: 0.15 m chosen; 0.10 m default here).
    pub resolution: f64,
    /// The slice starts this far below the LiDAR height (0.2 m).
    pub slice_below: f64,
    /// ... and ends this far above it (0.2 m).
    pub slice_above: f64,
    /// A cell is occupied when at least this many slice points fall in it (noise filter; 1 keeps
    /// every hit).
    pub min_points: u32,
    /// Free margin added around the points' extent, metres.
    pub margin: f64,
    /// The largest grid the builder will allocate, in cells (guards against a stray far point).
    pub max_cells: u64,
}

impl Default for OccupancyGridConfig {
    fn default() -> Self {
        Self {
            resolution: 0.10,
            slice_below: 0.2,
            slice_above: 0.2,
            min_points: 1,
            margin: 0.5,
            max_cells: 200_000_000,
        }
    }
}
