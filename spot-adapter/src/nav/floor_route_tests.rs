use super::*;
use nalgebra::Vector2;
use slam_core::GridGeometry;

/// A small LCG: the same cases every run.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> u32 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 33) as u32
    }
    fn below(&mut self, n: u32) -> u32 {
        self.next() % n
    }
}

/// A grid of `w` x `h` cells of 0.1 m with about a fifth of them blocked.
fn random_grid(rng: &mut Lcg, w: u32, h: u32) -> BitGrid {
    let geometry = GridGeometry::try_new(Vector2::zeros(), 0.1).unwrap();
    let mut grid = BitGrid::new(w, h).unwrap().with_geometry(geometry);
    for y in 0..h {
        for x in 0..w {
            if rng.below(5) == 0 {
                grid.set(Cell::new(x, y), true).unwrap();
            }
        }
    }
    grid
}

/// The depth-first search of [`brute_force`]: from `at`, the goal now or each unused link next.
#[allow(clippy::too_many_arguments)]
fn extend(
    graph: &FloorGraph<'_>,
    walk: &dyn Fn(FloorCell, FloorCell) -> Option<f64>,
    at: FloorCell,
    so_far: f64,
    used: &mut Vec<bool>,
    goal: FloorCell,
    best: &mut Option<f64>,
) {
    if let Some(w) = walk(at, goal) {
        let total = so_far + w;
        if best.is_none_or(|b| total < b) {
            *best = Some(total);
        }
    }
    for i in 0..graph.links.len() {
        if used[i] {
            continue;
        }
        let link = graph.links[i];
        for (from, to) in [(link.foot, link.top), (link.top, link.foot)] {
            if let Some(w) = walk(at, from) {
                used[i] = true;
                extend(graph, walk, to, so_far + w + link.length, used, goal, best);
                used[i] = false;
            }
        }
    }
}

/// The oracle: every order of distinct links, each taken either way, the walks between them by
/// one search per pair; the shortest total, or `None`.
fn brute_force(graph: &FloorGraph<'_>, start: FloorCell, goal: FloorCell) -> Option<f64> {
    let walk = |a: FloorCell, b: FloorCell| -> Option<f64> {
        if a.floor != b.floor {
            return None;
        }
        TravelCosts::between(graph.floors[a.floor], a.cell, &[b.cell])[0]
    };
    let mut best = None;
    let mut used = vec![false; graph.links.len()];
    extend(graph, &walk, start, 0.0, &mut used, goal, &mut best);
    best
}

#[test]
fn routes_over_floors_match_a_brute_force_search() {
    let mut rng = Lcg(0x9e37_79b9_7f4a_7c15);
    let mut found = 0;
    for case in 0..120 {
        let floors_n = 2 + rng.below(2) as usize;
        let (w, h) = (6 + rng.below(10), 6 + rng.below(10));
        let grids: Vec<BitGrid> = (0..floors_n).map(|_| random_grid(&mut rng, w, h)).collect();
        let cell = |rng: &mut Lcg, floor: usize| FloorCell {
            floor,
            cell: Cell::new(rng.below(w), rng.below(h)),
        };
        let links: Vec<StairsLink> = (0..rng.below(5))
            .map(|_| {
                let lower = rng.below(floors_n as u32 - 1) as usize;
                StairsLink {
                    foot: cell(&mut rng, lower),
                    top: cell(&mut rng, lower + 1),
                    length: f64::from(rng.below(40)) * 0.1,
                }
            })
            .collect();
        let graph = FloorGraph::new(grids.iter().collect(), links).unwrap();
        let start_floor = rng.below(floors_n as u32) as usize;
        let start = cell(&mut rng, start_floor);
        let goal_floor = rng.below(floors_n as u32) as usize;
        let goal = cell(&mut rng, goal_floor);
        let route = graph.route(start, goal).unwrap();
        let want = brute_force(&graph, start, goal);
        match (&route, want) {
            (Some(r), Some(b)) => {
                found += 1;
                assert!(
                    (r.length - b).abs() < 1e-9,
                    "case {case}: {r:?} against {b}"
                );
                // The legs chain from the start to the goal, and add up to the length.
                let mut at = start;
                let mut total = 0.0;
                for leg in &r.legs {
                    match *leg {
                        RouteLeg::Walk {
                            floor,
                            from,
                            to,
                            length,
                        } => {
                            assert_eq!((floor, from), (at.floor, at.cell), "case {case}");
                            at = FloorCell { floor, cell: to };
                            total += length;
                        }
                        RouteLeg::Stairs { link, up } => {
                            let l = graph.links()[link];
                            let (from, to) = if up { (l.foot, l.top) } else { (l.top, l.foot) };
                            assert_eq!(from, at, "case {case}");
                            at = to;
                            total += l.length;
                        }
                    }
                }
                assert_eq!(at, goal, "case {case}");
                assert!((total - r.length).abs() < 1e-9);
            }
            (None, None) => {}
            _ => panic!("case {case}: {route:?} against {want:?}"),
        }
    }
    assert!(found > 30, "only {found} cases had a route");
}

#[test]
fn a_floor_no_stairs_reach_has_no_route() {
    let geometry = GridGeometry::try_new(Vector2::zeros(), 0.1).unwrap();
    let grid = BitGrid::new(10, 10).unwrap().with_geometry(geometry);
    let at = |floor, x| FloorCell {
        floor,
        cell: Cell::new(x, 5),
    };
    let graph = FloorGraph::new(
        vec![&grid, &grid, &grid],
        vec![StairsLink {
            foot: at(0, 8),
            top: at(1, 8),
            length: 4.0,
        }],
    )
    .unwrap();
    assert_eq!(graph.route(at(0, 1), at(2, 1)).unwrap(), None);
    let up = graph.route(at(0, 1), at(1, 1)).unwrap().unwrap();
    assert!((up.length - (0.7 + 4.0 + 0.7)).abs() < 1e-9, "{up:?}");
    let here = graph.route(at(2, 1), at(2, 1)).unwrap().unwrap();
    assert!(here.length.abs() < 1e-12);
    assert_eq!(here.legs.len(), 1);
}

#[test]
fn bad_floors_cells_and_lengths_are_refused_by_name() {
    let geometry = GridGeometry::try_new(Vector2::zeros(), 0.1).unwrap();
    let grid = BitGrid::new(10, 10).unwrap().with_geometry(geometry);
    let at = |floor, x| FloorCell {
        floor,
        cell: Cell::new(x, 5),
    };
    let link = |foot, top, length| StairsLink { foot, top, length };
    match FloorGraph::new(vec![&grid, &grid], vec![link(at(0, 1), at(2, 1), 3.0)]) {
        Err(NavError::NoSuchFloor {
            what,
            floor,
            floors,
        }) => {
            assert_eq!((what, floor, floors), ("a stairs link's top", 2, 2));
        }
        other => panic!("{other:?}"),
    }
    match FloorGraph::new(vec![&grid, &grid], vec![link(at(0, 10), at(1, 1), 3.0)]) {
        Err(NavError::OffFloorGrid { what, floor, .. }) => {
            assert_eq!((what, floor), ("a stairs link's foot", 0));
        }
        other => panic!("{other:?}"),
    }
    for length in [f64::NAN, -1.0, f64::INFINITY] {
        match FloorGraph::new(vec![&grid, &grid], vec![link(at(0, 1), at(1, 1), length)]) {
            Err(NavError::InvalidConfig(e)) => assert_eq!(e.setting, "StairsLink::length"),
            other => panic!("{length}: {other:?}"),
        }
    }
    let graph = FloorGraph::new(vec![&grid, &grid], Vec::new()).unwrap();
    assert!(matches!(
        graph.route(at(5, 1), at(0, 1)),
        Err(NavError::NoSuchFloor {
            what: "the start",
            floor: 5,
            floors: 2
        })
    ));
    assert!(matches!(
        graph.route(at(0, 1), at(1, 12)),
        Err(NavError::OffFloorGrid {
            what: "the goal",
            floor: 1,
            ..
        })
    ));
}
