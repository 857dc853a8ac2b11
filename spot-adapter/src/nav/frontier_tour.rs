//! `FrontierTour`: the order to walk to every frontier goal in, from the robot, as an open
//! asymmetric travelling-salesman path (FUEL, Zhou et al., RA-L 2021; TARE, Cao et al., RSS
//! 2021). Exact by Held-Karp dynamic programming up to [`EXACT_UP_TO`] goals; beyond, a
//! nearest-neighbour tour improved by 2-opt and or-opt moves until none shortens it.

/// Up to this many goals the tour is exact: Held-Karp keeps `2^n * n` partial tours, 49,152
/// at 12 (well under a millisecond); a building's map seldom has more frontiers than that.
pub const EXACT_UP_TO: usize = 12;

/// Longest run of consecutive goals an or-opt move carries elsewhere in the tour.
const OR_OPT_SEGMENT: usize = 3;

/// An open tour over `n` goals: the order to visit them in and its length.
#[derive(Clone, Debug, PartialEq)]
pub struct FrontierTour {
    /// Goal indices in walking order, each once.
    pub order: Vec<usize>,
    /// Metres from the robot through every goal in `order` (no walk back).
    pub length: f64,
}

/// Walking costs for a tour: from the robot to each goal, and between goals (row-major,
/// `between[i * n + j]` from goal `i` to goal `j`; need not be symmetric). Metres; infinite
/// where there is no walk.
#[derive(Clone, Debug)]
pub struct TourCosts {
    from_robot: Vec<f64>,
    between: Vec<f64>,
}

impl TourCosts {
    /// Costs over `from_robot.len()` goals with `between(i, j)` the walk from goal `i` to `j`.
    pub fn new(from_robot: Vec<f64>, between: impl Fn(usize, usize) -> f64) -> Self {
        let n = from_robot.len();
        let between = (0..n * n).map(|k| between(k / n, k % n)).collect();
        Self {
            from_robot,
            between,
        }
    }

    /// The number of goals.
    #[must_use]
    pub fn len(&self) -> usize {
        self.from_robot.len()
    }

    /// No goal at all.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.from_robot.is_empty()
    }

    fn between(&self, i: usize, j: usize) -> f64 {
        self.between[i * self.len() + j]
    }

    /// The length of walking `order` from the robot.
    #[must_use]
    pub fn length(&self, order: &[usize]) -> f64 {
        let Some(&first) = order.first() else {
            return 0.0;
        };
        self.from_robot[first]
            + order
                .windows(2)
                .map(|w| self.between(w[0], w[1]))
                .sum::<f64>()
    }
}

impl FrontierTour {
    /// The tour over every goal of `costs`: exact up to [`EXACT_UP_TO`] goals, improved
    /// nearest-neighbour beyond.
    #[must_use]
    pub fn plan(costs: &TourCosts) -> Self {
        if costs.len() <= EXACT_UP_TO {
            Self::held_karp(costs)
        } else {
            Self::improved_nearest_neighbour(costs)
        }
    }

    /// The shortest open tour (Held-Karp, 1962): `best[set][j]` is the shortest walk from the
    /// robot through the goals of `set` ending at `j`. `2^n * n` memory: callers keep `n` small.
    #[must_use]
    pub fn held_karp(costs: &TourCosts) -> Self {
        let n = costs.len();
        if costs.is_empty() {
            return Self {
                order: Vec::new(),
                length: 0.0,
            };
        }
        let full = (1usize << n) - 1;
        let mut best = vec![f64::INFINITY; (full + 1) * n];
        let mut came_from = vec![usize::MAX; (full + 1) * n];
        for j in 0..n {
            best[(1 << j) * n + j] = costs.from_robot[j];
        }
        for set in 1..=full {
            for j in (0..n).filter(|&j| set & (1 << j) != 0) {
                let here = best[set * n + j];
                if here.is_infinite() {
                    continue;
                }
                for k in (0..n).filter(|&k| set & (1 << k) == 0) {
                    let next = set | (1 << k);
                    let through = here + costs.between(j, k);
                    if through < best[next * n + k] {
                        best[next * n + k] = through;
                        came_from[next * n + k] = j;
                    }
                }
            }
        }
        // The first of equal ends: any is as short, and an unreachable goal still ends a tour.
        let mut end = 0;
        for j in 1..n {
            if best[full * n + j] < best[full * n + end] {
                end = j;
            }
        }
        let length = best[full * n + end];
        let mut order = Vec::with_capacity(n);
        let (mut set, mut j) = (full, end);
        while j != usize::MAX {
            order.push(j);
            let previous = came_from[set * n + j];
            set &= !(1 << j);
            j = previous;
        }
        if order.len() < n {
            // Some goal cannot be walked to or from: its order is arbitrary, the length infinite.
            order = (0..n).collect();
        } else {
            order.reverse();
        }
        Self { order, length }
    }

    /// The nearest-neighbour tour from the robot, then 2-opt (reverse a stretch) and or-opt
    /// (move a run of up to three goals elsewhere, as it is or reversed) while either
    /// shortens it. Each move is measured on the whole tour: the costs need not be symmetric.
    #[must_use]
    pub fn improved_nearest_neighbour(costs: &TourCosts) -> Self {
        let n = costs.len();
        let mut order = Vec::with_capacity(n);
        let mut left: Vec<usize> = (0..n).collect();
        let mut last: Option<usize> = None;
        while !left.is_empty() {
            let cost = |j: usize| last.map_or(costs.from_robot[j], |i| costs.between(i, j));
            let mut pick = 0;
            for k in 1..left.len() {
                if cost(left[k]) < cost(left[pick]) {
                    pick = k;
                }
            }
            let j = left.swap_remove(pick);
            order.push(j);
            last = Some(j);
        }
        let mut length = costs.length(&order);
        let mut candidate = order.clone();
        let mut improved = true;
        while improved {
            improved = false;
            for i in 0..n {
                for k in i + 1..n {
                    candidate.copy_from_slice(&order);
                    candidate[i..=k].reverse();
                    let l = costs.length(&candidate);
                    if l < length - 1e-9 {
                        (length, improved) = (l, true);
                        order.copy_from_slice(&candidate);
                    }
                }
            }
            for run in 1..=OR_OPT_SEGMENT.min(n.saturating_sub(1)) {
                for i in 0..=n - run {
                    for to in 0..=n - run {
                        if to == i {
                            continue;
                        }
                        for reversed in [false, true] {
                            let mut rest = order.clone();
                            let mut moved: Vec<usize> = rest.drain(i..i + run).collect();
                            if reversed {
                                moved.reverse();
                            }
                            rest.splice(to..to, moved);
                            let l = costs.length(&rest);
                            if l < length - 1e-9 {
                                (length, improved) = (l, true);
                                order = rest;
                            }
                        }
                    }
                }
            }
        }
        Self { order, length }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shortest tour by trying every order: the oracle.
    fn brute_force(costs: &TourCosts) -> f64 {
        fn permute(costs: &TourCosts, order: &mut Vec<usize>, k: usize, best: &mut f64) {
            if k == order.len() {
                *best = best.min(costs.length(order));
                return;
            }
            for i in k..order.len() {
                order.swap(k, i);
                permute(costs, order, k + 1, best);
                order.swap(k, i);
            }
        }
        let mut order: Vec<usize> = (0..costs.len()).collect();
        let mut best = f64::INFINITY;
        permute(costs, &mut order, 0, &mut best);
        if order.is_empty() { 0.0 } else { best }
    }

    fn random(seed: u64) -> impl FnMut() -> f64 {
        let mut state = seed;
        move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Goals scattered over a 20 m square and the robot at its middle, walks a little longer
    /// than straight lines and different each way (walks round furniture, say).
    fn scattered(n: usize, seed: u64) -> TourCosts {
        let mut next = random(seed);
        let points: Vec<(f64, f64)> = (0..=n).map(|_| (20.0 * next(), 20.0 * next())).collect();
        let distance = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).hypot(a.1 - b.1);
        let detours: Vec<f64> = (0..n * n).map(|_| 1.0 + 0.5 * next()).collect();
        TourCosts::new(
            (1..=n).map(|j| distance((10.0, 10.0), points[j])).collect(),
            |i, j| detours[i * n + j] * distance(points[i + 1], points[j + 1]),
        )
    }

    fn is_permutation(order: &[usize], n: usize) -> bool {
        let mut sorted = order.to_vec();
        sorted.sort_unstable();
        sorted == (0..n).collect::<Vec<_>>()
    }

    #[test]
    fn held_karp_finds_the_brute_force_optimum_up_to_seven_goals() {
        for n in 0..=7 {
            for seed in 0..20 {
                let costs = scattered(n, 100 * n as u64 + seed);
                let tour = FrontierTour::held_karp(&costs);
                assert!(is_permutation(&tour.order, n), "{tour:?}");
                assert!((tour.length - costs.length(&tour.order)).abs() < 1e-9);
                let optimum = brute_force(&costs);
                assert!(
                    (tour.length - optimum).abs() < 1e-9,
                    "{tour:?} vs {optimum}"
                );
            }
        }
    }

    /// The heuristic used beyond [`EXACT_UP_TO`] goals, checked where the optimum is known:
    /// never shorter (it would be a wrong length), at most 10 % longer, and most often optimal.
    #[test]
    fn the_improved_nearest_neighbour_tour_is_near_the_brute_force_optimum() {
        let mut optimal = 0;
        for n in 1..=7 {
            for seed in 0..20 {
                let costs = scattered(n, 7 + 100 * n as u64 + seed);
                let tour = FrontierTour::improved_nearest_neighbour(&costs);
                assert!(is_permutation(&tour.order, n), "{tour:?}");
                assert!((tour.length - costs.length(&tour.order)).abs() < 1e-9);
                let optimum = brute_force(&costs);
                assert!(tour.length >= optimum - 1e-9);
                assert!(tour.length <= 1.1 * optimum, "{} vs {optimum}", tour.length);
                if tour.length <= optimum + 1e-9 {
                    optimal += 1;
                }
            }
        }
        assert!(optimal >= 120, "optimal in {optimal} of 140");
    }

    #[test]
    fn the_heuristic_tour_is_no_longer_than_nearest_neighbour_on_many_goals() {
        let costs = scattered(30, 3);
        let tour = FrontierTour::plan(&costs);
        assert!(is_permutation(&tour.order, 30));
        // Without improvement moves the walk is the greedy explorer's order.
        let mut greedy = Vec::new();
        let mut last: Option<usize> = None;
        while greedy.len() < 30 {
            let next = (0..30)
                .filter(|j| !greedy.contains(j))
                .min_by(|&a, &b| {
                    let c = |j| last.map_or(costs.from_robot[j], |i| costs.between(i, j));
                    c(a).total_cmp(&c(b))
                })
                .unwrap();
            greedy.push(next);
            last = Some(next);
        }
        assert!(tour.length <= costs.length(&greedy) + 1e-9);
    }

    #[test]
    fn a_goal_with_no_walk_still_gets_a_place_and_an_infinite_length() {
        let costs = TourCosts::new(vec![1.0, f64::INFINITY], |i, j| {
            if i == j { 0.0 } else { f64::INFINITY }
        });
        let tour = FrontierTour::plan(&costs);
        assert!(is_permutation(&tour.order, 2));
        assert!(tour.length.is_infinite());
    }
}
