//! Connected-component labels of a grid, so that an unreachable goal is answered without a
//! search. Under the no-corner-cutting rule a diagonal step needs both orthogonal neighbours free,
//! so 8-connected reachability equals 4-connected reachability.

use slam_core::{BitGrid, Cell};

/// Label per cell; blocked cells have [`Components::BLOCKED`].
#[derive(Clone, Debug)]
pub struct Components {
    width: u32,
    labels: Vec<u32>,
    count: u32,
}

impl Components {
    /// Label of blocked cells.
    pub const BLOCKED: u32 = u32::MAX;

    /// Label the free cells of `grid` (linear time, a flood fill per component).
    #[must_use]
    pub fn new(grid: &BitGrid) -> Self {
        Self::labelled_in(Vec::new(), grid)
    }

    /// These labels replaced by those of `grid` (the same as [`Components::new`]), in the same
    /// memory when it has room.
    pub(crate) fn relabel(&mut self, grid: &BitGrid) {
        let labels = std::mem::take(&mut self.labels);
        *self = Self::labelled_in(labels, grid);
    }

    /// The labels of `grid`'s free cells written into `labels` (its contents do not matter).
    fn labelled_in(mut labels: Vec<u32>, grid: &BitGrid) -> Self {
        let (w, h) = (grid.width() as usize, grid.height() as usize);
        labels.clear();
        labels.resize(w * h, Self::BLOCKED);
        let mut count = 0u32;
        let mut stack: Vec<usize> = Vec::new();
        for start in 0..w * h {
            if labels[start] != Self::BLOCKED {
                continue;
            }
            let (sx, sy) = ((start % w) as u32, (start / w) as u32);
            if grid.is_blocked(Cell::new(sx, sy)) {
                continue;
            }
            labels[start] = count;
            stack.push(start);
            while let Some(i) = stack.pop() {
                let (x, y) = (i % w, i / w);
                let mut visit = |j: usize, nx: usize, ny: usize| {
                    if labels[j] == Self::BLOCKED
                        && !grid.is_blocked(Cell::new(nx as u32, ny as u32))
                    {
                        labels[j] = count;
                        stack.push(j);
                    }
                };
                if x + 1 < w {
                    visit(i + 1, x + 1, y);
                }
                if x > 0 {
                    visit(i - 1, x - 1, y);
                }
                if y + 1 < h {
                    visit(i + w, x, y + 1);
                }
                if y > 0 {
                    visit(i - w, x, y - 1);
                }
            }
            count += 1;
        }
        Self {
            width: grid.width(),
            labels,
            count,
        }
    }

    /// The component of `cell` ([`Components::BLOCKED`] for blocked cells).
    ///
    /// # Panics
    /// If `cell` is off the grid.
    #[must_use]
    pub fn label(&self, cell: Cell) -> u32 {
        self.labels[cell.y as usize * self.width as usize + cell.x as usize]
    }

    /// Whether `a` and `b` are free cells of the same component.
    ///
    /// # Panics
    /// If a cell is off the grid.
    #[must_use]
    pub fn connected(&self, a: Cell, b: Cell) -> bool {
        let la = self.label(a);
        la != Self::BLOCKED && la == self.label(b)
    }

    /// Number of components.
    #[must_use]
    pub fn count(&self) -> u32 {
        self.count
    }
}
