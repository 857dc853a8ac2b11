//! `with_pool_awake`: an alignment's loop run while one other worker of the thread pool keeps
//! looking for its work instead of going to sleep between iterations.
//!
//! Each ICP iteration searches its correspondences on all cores, then solves its update on
//! one. A solve of some tens of microseconds is longer than an idle rayon worker looks for work
//! before it sleeps, so the next search waits for that worker to be woken (a loop of 8
//! parallel chunks with a 60 us serial gap between them, on this project's 2-core machine: 214
//! us an iteration, against 163 us with a worker kept looking). Only the scheduling changes:
//! the same chunks, summed in the same order, so every result is the same to the bit.
//!
//! The price: that worker spins on its core for as long as the alignment runs, and while it
//! waits it may take up any work pending in the same pool (another caller's), which the
//! alignment then waits for before it returns.

use std::sync::atomic::{AtomicBool, Ordering};

/// `f` run on a worker of the current pool while another worker keeps executing whatever work
/// `f` forks (nothing sleeps between its parallel sections); `f`'s result. In a pool of one
/// thread `f` just runs.
pub(crate) fn with_pool_awake<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    if rayon::current_num_threads() < 2 {
        return f();
    }
    let done = AtomicBool::new(false);
    let (result, ()) = rayon::join(
        || {
            let result = f();
            done.store(true, Ordering::Release);
            result
        },
        || {
            // Whichever worker takes this runs `f`'s forked work until `f` returns; when nobody
            // took it before then, `f`'s own thread runs it afterwards and it returns at once.
            while !done.load(Ordering::Acquire) {
                if rayon::yield_now() != Some(rayon::Yield::Executed) {
                    std::hint::spin_loop();
                }
            }
        },
    );
    result
}

#[cfg(test)]
mod tests {
    use super::with_pool_awake;
    use rayon::prelude::*;

    #[test]
    fn forked_work_inside_is_done_and_the_result_returned() {
        let sums: Vec<u64> = with_pool_awake(|| {
            (0..50u64)
                .map(|k| (0..10_000u64).into_par_iter().map(|i| i * k).sum())
                .collect()
        });
        let expected: Vec<u64> = (0..50u64).map(|k| k * (10_000 * 9_999 / 2)).collect();
        assert_eq!(sums, expected);
    }

    #[test]
    fn in_a_pool_of_one_thread_it_runs_alone() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap_or_else(|e| panic!("{e}"));
        let sum = pool.install(|| with_pool_awake(|| (0..100u32).into_par_iter().sum::<u32>()));
        assert_eq!(sum, 4950);
    }
}
