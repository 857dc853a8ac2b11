//! Frontiers: known-free cells next to unknown ones, clustered into the edges of what is mapped
//! (Yamauchi, "A frontier-based approach for autonomous exploration", CIRA 1997).

use gridmap::{CellState, OccupancyGrid};
use nalgebra::Vector2;
use slam_core::Cell;

/// One frontier: a connected run of frontier cells (8-connected).
#[derive(Clone, Debug, PartialEq)]
pub struct Frontier {
    /// Its cells, in scan order (row by row).
    pub cells: Vec<Cell>,
    /// The mean of its cell centres (metres, map frame).
    pub centroid: Vector2<f64>,
    /// Its cell nearest the centroid: where it is, for a frontier that bends round a corner.
    pub middle: Cell,
}

impl Frontier {
    /// Its length in cells.
    #[must_use]
    pub fn size(&self) -> usize {
        self.cells.len()
    }
}

/// Whether `cell` is a frontier cell of `grid`: known free with an unknown 4-neighbour (off the
/// grid counts as unknown: nothing was seen there).
#[must_use]
pub fn is_frontier_cell(grid: &OccupancyGrid, cell: Cell) -> bool {
    if grid.state(cell) != CellState::Free {
        return false;
    }
    let (x, y) = (i64::from(cell.x), i64::from(cell.y));
    [(1, 0), (-1, 0), (0, 1), (0, -1)]
        .into_iter()
        .any(|(dx, dy)| state_signed(grid, x + dx, y + dy) == CellState::Unknown)
}

/// The frontiers of `grid` with at least `min_cells` cells, largest first (ties in scan order
/// of their first cell). One pass over the grid, then a flood fill per frontier.
#[must_use]
pub fn find_frontiers(grid: &OccupancyGrid, min_cells: usize) -> Vec<Frontier> {
    let (w, h) = (grid.width() as usize, grid.height() as usize);
    let mut marked = frontier_cells(grid);
    let mut frontiers = Vec::new();
    let mut stack = Vec::new();
    for start in 0..marked.len() {
        if !marked[start] {
            continue;
        }
        marked[start] = false;
        stack.push(start);
        let mut cells = Vec::new();
        while let Some(k) = stack.pop() {
            let (x, y) = ((k % w) as i64, (k / w) as i64);
            cells.push(Cell::new(x as u32, y as u32));
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let (nx, ny) = (x + dx, y + dy);
                    if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                        continue;
                    }
                    let n = ny as usize * w + nx as usize;
                    if marked[n] {
                        marked[n] = false;
                        stack.push(n);
                    }
                }
            }
        }
        if cells.len() >= min_cells {
            cells.sort_unstable_by_key(|c| (c.y, c.x));
            frontiers.push(frontier_of(grid, cells));
        }
    }
    // A stable sort: equal sizes stay in the scan order of their first cell.
    frontiers.sort_by_key(|f| std::cmp::Reverse(f.size()));
    frontiers
}

/// [`is_frontier_cell`] of every cell, row-major, 64 cells at a time: a free cell's word
/// against the unknown words of its row shifted a column each way and of the rows above and
/// below (the grid's outside unknown). A large building's grid holds 700,000 cells, and
/// testing them one by one cost a tenth of an explorer's decision.
fn frontier_cells(grid: &OccupancyGrid) -> Vec<bool> {
    let (w, h) = (grid.width() as usize, grid.height() as usize);
    let (occupied, free) = (grid.occupied(), grid.known_free());
    let stride = occupied.stride_words();
    // Bits past the width: set in both bit grids (their padding), here read as unknown.
    let tail = w % 64;
    let padding = if tail == 0 { 0 } else { !0u64 << tail };
    let unknown_row = |y: usize| -> Vec<u64> {
        let (o, f) = (occupied.row_words(y as u32), free.row_words(y as u32));
        let mut u: Vec<u64> = o.iter().zip(f).map(|(o, f)| !(o | f)).collect();
        if let Some(last) = u.last_mut() {
            *last |= padding;
        }
        u
    };
    let outside = vec![!0u64; stride];
    let mut marked = vec![false; w * h];
    let mut below = outside.clone();
    let mut here = if h > 0 { unknown_row(0) } else { Vec::new() };
    for y in 0..h {
        let above = if y + 1 < h {
            unknown_row(y + 1)
        } else {
            outside.clone()
        };
        let free_words = free.row_words(y as u32);
        let occupied_words = occupied.row_words(y as u32);
        for i in 0..stride {
            // Free: the free bit without the occupied one (and not padding).
            let mut f = free_words[i] & !occupied_words[i];
            if i + 1 == stride {
                f &= !padding;
            }
            if f == 0 {
                continue;
            }
            // West neighbour of column x is bit x - 1: shifted up, the word before's top bit
            // carried in (off the grid's west edge: unknown).
            let west_carry = if i == 0 { 1 } else { here[i - 1] >> 63 };
            let east_carry = if i + 1 == stride { 1 } else { here[i + 1] & 1 };
            let west = (here[i] << 1) | west_carry;
            let east = (here[i] >> 1) | (east_carry << 63);
            let mut hits = f & (west | east | below[i] | above[i]);
            while hits != 0 {
                let bit = hits.trailing_zeros() as usize;
                marked[y * w + i * 64 + bit] = true;
                hits &= hits - 1;
            }
        }
        below = here;
        here = above;
    }
    marked
}

fn frontier_of(grid: &OccupancyGrid, cells: Vec<Cell>) -> Frontier {
    let geometry = grid.geometry();
    let sum: Vector2<f64> = cells.iter().map(|&c| geometry.cell_center(c)).sum();
    let centroid = sum / cells.len() as f64;
    let middle = cells
        .iter()
        .copied()
        .min_by(|&a, &b| {
            let da = (geometry.cell_center(a) - centroid).norm_squared();
            let db = (geometry.cell_center(b) - centroid).norm_squared();
            da.total_cmp(&db)
        })
        .unwrap_or(Cell::new(0, 0));
    Frontier {
        cells,
        centroid,
        middle,
    }
}

fn state_signed(grid: &OccupancyGrid, x: i64, y: i64) -> CellState {
    match (u32::try_from(x), u32::try_from(y)) {
        (Ok(x), Ok(y)) => grid.state(Cell::new(x, y)),
        _ => CellState::Unknown,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use slam_core::GridGeometry;
    use std::collections::{BTreeMap, BTreeSet};

    /// A grid from rows of `.` (free), `#` (occupied) and `?` (unknown), the first row at the
    /// top (largest y).
    fn grid(rows: &[&str]) -> OccupancyGrid {
        let h = rows.len() as u32;
        let w = rows[0].len() as u32;
        let geometry = GridGeometry::try_new(Vector2::zeros(), 0.1).unwrap();
        let mut g = OccupancyGrid::new(w, h, geometry, CellState::Unknown).unwrap();
        for (r, row) in rows.iter().enumerate() {
            for (x, ch) in row.chars().enumerate() {
                let state = match ch {
                    '.' => CellState::Free,
                    '#' => CellState::Occupied,
                    _ => CellState::Unknown,
                };
                g.set(Cell::new(x as u32, h - 1 - r as u32), state).unwrap();
            }
        }
        g
    }

    /// The oracle: every pair of frontier cells tested for adjacency, components by repeated
    /// relabelling until nothing changes.
    fn brute_force(g: &OccupancyGrid) -> BTreeSet<BTreeSet<(u32, u32)>> {
        let mut cells = Vec::new();
        for y in 0..g.height() {
            for x in 0..g.width() {
                let free = g.state(Cell::new(x, y)) == CellState::Free;
                let unknown_next =
                    [(1i64, 0i64), (-1, 0), (0, 1), (0, -1)]
                        .iter()
                        .any(|(dx, dy)| {
                            let (nx, ny) = (i64::from(x) + dx, i64::from(y) + dy);
                            nx < 0
                                || ny < 0
                                || nx >= i64::from(g.width())
                                || ny >= i64::from(g.height())
                                || g.state(Cell::new(nx as u32, ny as u32)) == CellState::Unknown
                        });
                if free && unknown_next {
                    cells.push((x, y));
                }
            }
        }
        let mut label: Vec<usize> = (0..cells.len()).collect();
        loop {
            let mut changed = false;
            for i in 0..cells.len() {
                for j in 0..cells.len() {
                    let (a, b) = (cells[i], cells[j]);
                    if a.0.abs_diff(b.0) <= 1 && a.1.abs_diff(b.1) <= 1 && label[j] < label[i] {
                        label[i] = label[j];
                        changed = true;
                    }
                }
            }
            if !changed {
                break;
            }
        }
        let mut groups: BTreeMap<usize, BTreeSet<(u32, u32)>> = BTreeMap::new();
        for (k, &c) in cells.iter().enumerate() {
            groups.entry(label[k]).or_default().insert(c);
        }
        groups.into_values().collect()
    }

    fn found(g: &OccupancyGrid) -> BTreeSet<BTreeSet<(u32, u32)>> {
        find_frontiers(g, 1)
            .into_iter()
            .map(|f| f.cells.iter().map(|c| (c.x, c.y)).collect())
            .collect()
    }

    /// Word by word, every cell marked as the cell-by-cell definition marks it, on random grids
    /// whose widths cross the 64-cell words.
    #[test]
    fn frontier_cells_word_by_word_are_the_cells_one_by_one() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for (w, h) in [
            (1, 1),
            (63, 3),
            (64, 2),
            (65, 5),
            (130, 7),
            (200, 1),
            (1, 40),
        ] {
            for _ in 0..20 {
                let geometry = GridGeometry::try_new(Vector2::zeros(), 0.1).unwrap();
                let mut g = OccupancyGrid::new(w, h, geometry, CellState::Unknown).unwrap();
                let unknown_share = next() % 4;
                for y in 0..h {
                    for x in 0..w {
                        let r = next() % 8;
                        let state = if r < unknown_share {
                            CellState::Unknown
                        } else if r == 7 {
                            CellState::Occupied
                        } else {
                            CellState::Free
                        };
                        g.set(Cell::new(x, y), state).unwrap();
                    }
                }
                let marked = frontier_cells(&g);
                for y in 0..h {
                    for x in 0..w {
                        let want = is_frontier_cell(&g, Cell::new(x, y));
                        assert_eq!(marked[(y * w + x) as usize], want, "{w}x{h} at ({x}, {y})");
                    }
                }
            }
        }
    }

    #[test]
    fn a_room_seen_through_its_door_has_one_frontier_per_open_edge() {
        let g = grid(&[
            "??????????",
            "??######??",
            "??#....#??",
            "??#.....??",
            "??#....#??",
            "??##.###??",
            "????.?????",
            "????.?????",
        ]);
        let frontiers = find_frontiers(&g, 1);
        assert_eq!(found(&g), brute_force(&g));
        // The corridor's two cells below the door (unknown on both sides), then the open east
        // side (one cell): largest first.
        assert_eq!(frontiers.len(), 2, "{frontiers:?}");
        assert_eq!(frontiers[0].size(), 2);
        assert_eq!(frontiers[1].cells, [Cell::new(7, 4)]);
        let large = find_frontiers(&g, 2);
        assert_eq!(large, frontiers[..1]);
    }

    #[test]
    fn frontiers_match_the_brute_force_oracle_on_random_grids() {
        // A small LCG: the same grids every run.
        let mut next = crate::nav::test_lcg::lcg(0x2545_f491_4f6c_dd1du64);
        for _ in 0..200 {
            let (w, h) = (1 + next() % 12, 1 + next() % 12);
            let geometry = GridGeometry::try_new(Vector2::new(-1.0, 2.0), 0.2).unwrap();
            let mut g = OccupancyGrid::new(w, h, geometry, CellState::Unknown).unwrap();
            for y in 0..h {
                for x in 0..w {
                    let state = match next() % 5 {
                        0 => CellState::Occupied,
                        1 => CellState::Unknown,
                        _ => CellState::Free,
                    };
                    g.set(Cell::new(x, y), state).unwrap();
                }
            }
            assert_eq!(found(&g), brute_force(&g));
            let frontiers = find_frontiers(&g, 1);
            for f in &frontiers {
                let mean = f
                    .cells
                    .iter()
                    .map(|&c| geometry.cell_center(c))
                    .sum::<Vector2<f64>>()
                    / f.size() as f64;
                assert!((mean - f.centroid).norm() < 1e-9);
                assert!(f.cells.contains(&f.middle));
            }
            assert!(frontiers.windows(2).all(|p| p[0].size() >= p[1].size()));
        }
    }
}
