//! Tests of `grid.rs`.

use super::*;
use proptest::prelude::*;

fn oracle_grid(width: u32, height: u32, bits: &[bool]) -> BitGrid {
    BitGrid::from_fn(width, height, |x, y| bits[(y * width + x) as usize]).unwrap()
}

fn dims() -> impl Strategy<Value = (u32, u32)> {
    prop_oneof![
        Just((1, 1)),
        Just((63, 65)),
        Just((1025, 3)),
        Just((64, 64)),
        Just((65, 1)),
        (1u32..200, 1u32..200),
    ]
}

proptest! {
    #[test]
    fn matches_vec_bool_oracle(((w, h), seed) in (dims(), any::<u64>())) {
        // Random bits from a cheap generator so large grids stay fast.
        let mut s = seed | 1;
        let bits: Vec<bool> = (0..w * h).map(|_| {
            s ^= s << 13; s ^= s >> 7; s ^= s << 17; s % 3 == 0
        }).collect();
        let grid = oracle_grid(w, h, &bits);
        let t = grid.transposed();
        prop_assert_eq!(t.width(), h);
        prop_assert_eq!(t.transposed(), grid.clone());
        let mut blocked = 0;
        for y in 0..h {
            for x in 0..w {
                let b = bits[(y * w + x) as usize];
                blocked += usize::from(b);
                prop_assert_eq!(grid.is_blocked(Cell::new(x, y)), b);
                prop_assert_eq!(t.is_blocked(Cell::new(y, x)), b);
                // word_at: bit i is cell x + i, blocked past the east edge.
                let word = grid.word_at(x, y);
                let wword = grid.word_ending_at(x, y);
                for i in 0..64u32 {
                    let east = if x + i < w { bits[(y * w + x + i) as usize] } else { true };
                    prop_assert_eq!((word >> i) & 1 == 1, east);
                    let west = if x >= i { bits[(y * w + x - i) as usize] } else { true };
                    prop_assert_eq!((wword >> (63 - i)) & 1 == 1, west);
                }
            }
            prop_assert!(grid.is_blocked(Cell::new(w, y)));
        }
        prop_assert_eq!(grid.count_blocked(), blocked);
        prop_assert_eq!(grid.blocked_cells().count(), blocked);
        prop_assert!(grid.blocked_cells().all(|c| bits[(c.y * w + c.x) as usize]));
    }

    #[test]
    fn set_then_get((w, h) in dims(), ops in proptest::collection::vec((any::<u32>(), any::<u32>(), any::<bool>()), 0..64)) {
        let mut grid = BitGrid::new(w, h).unwrap();
        let mut oracle = vec![false; (w * h) as usize];
        for (x, y, b) in ops {
            let (x, y) = (x % (w + 1), y % (h + 1));
            let r = grid.set(Cell::new(x, y), b);
            if x < w && y < h {
                prop_assert!(r.is_ok());
                oracle[(y * w + x) as usize] = b;
            } else {
                prop_assert!(matches!(r, Err(GridError::OutOfBounds { .. })), "expected OutOfBounds");
            }
        }
        prop_assert_eq!(grid, oracle_grid(w, h, &oracle));
    }
}

#[test]
fn rejects_empty_and_huge() {
    assert!(matches!(
        BitGrid::new(0, 5),
        Err(GridError::EmptyGrid { .. })
    ));
    assert!(matches!(
        BitGrid::new(u32::MAX, u32::MAX),
        Err(GridError::TooLarge { .. })
    ));
    // One row past 2^32 cells: a planner's u32 cell index would wrap.
    assert!(matches!(
        BitGrid::new(1 << 16, (1 << 16) + 1),
        Err(GridError::TooLarge { max_cells, .. }) if max_cells == 1 << 32
    ));
}

#[test]
fn metric_transform_round_trips() {
    let geom = GridGeometry::try_new(Vector2::new(-3.0, 2.0), 0.1).unwrap();
    let grid = BitGrid::new(50, 40).unwrap().with_geometry(geom);
    let c = Cell::new(7, 13);
    let p = grid.cell_center(c);
    assert!((p - Vector2::new(-3.0 + 0.75, 2.0 + 1.35)).norm() < 1e-12);
    assert_eq!(grid.cell_at(p), Some(c));
    assert_eq!(grid.cell_at(Vector2::new(-3.01, 2.5)), None);
    assert!(GridGeometry::try_new(Vector2::zeros(), 0.0).is_err());
    assert!(GridGeometry::try_new(Vector2::zeros(), f64::NAN).is_err());
}
